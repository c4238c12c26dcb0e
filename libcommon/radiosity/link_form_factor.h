// The geometry of one link between two patches: whether the two can exchange energy at all
// (mutuallyFacing, the test of every link made), and the unoccluded form factor of a leaf link
// (linkFormFactor: which rule of form_factor.h, integrated over which patch). Pure functions of
// the two polygons: deterministic, thread-safe.
#pragma once

#include <glm/glm.hpp>

#include "libcommon/radiosity/form_factor.h"
#include "libcommon/scene/geometry.h"

namespace rad {

// Unoccluded F(p -> q) of a leaf link. kAutoOrder: integrated over the smaller of the two
// with reciprocity (A_p F_pq = A_q F_qp), adaptively (to relative tolerance relTol) when the
// smaller one's centroid is nearer the other than the smaller one's size, else with a fixed
// Gauss rule whose order falls with that distance ratio; any other order:
// polygonToPolygonFormFactor(p, q, order) (one rule per receiver: exact row sums).
double linkFormFactor(const Polygon& p, const Polygon& q, int order, double relTol = 1e-5);
// kAutoOrder's two steps: the integral over the smaller patch, F(smaller -> other) (the same
// for p, q and q, p unless their areas are equal: a link and its reverse share it), and
// F(p -> q) from it by reciprocity.
double linkFormFactorIntegral(const Polygon& p, const Polygon& q, double relTol);
double linkFormFactorFrom(const Polygon& p, const Polygon& q, double fromSmaller);

// True when the top-level patches p and q can exchange energy at all: some vertex of each lies
// strictly in front of the other's plane. Each polygon's plane is made once (facingPlane), as
// one polygon meets many (the cluster refinement's patch pairs, millions a key on a large
// scene), and recomputing both normals and centroids for each pair is wasted work.
struct FacingPlane {
  glm::dvec3 normal, centroid;
  double size = 0.0;  // polygonSize: the tolerance's scale
};
FacingPlane facingPlane(const Polygon& p);
bool mutuallyFacing(const Polygon& p, const FacingPlane& pPlane, const Polygon& q,
                    const FacingPlane& qPlane);

}  // namespace rad
