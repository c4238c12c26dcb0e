// The geometry of one link; see link_form_factor.h.
// The figures behind the reasons given here: docs/results.md, "Figures moved out of the radiosity
// code's comments (issue 55)".
#include "libcommon/radiosity/link_form_factor.h"

#include <algorithm>

namespace rad {

namespace {

// Some vertex of `p` lies strictly in front of the plane of `q`.
bool someVertexInFront(const Polygon& p, const FacingPlane& pPlane, const FacingPlane& qPlane) {
  if (qPlane.normal == glm::dvec3(0.0)) return false;
  const double tol = 1e-12 * std::max(pPlane.size, qPlane.size);
  for (int i = 0; i < p.count; ++i)
    if (glm::dot(qPlane.normal, p.v[i] - qPlane.centroid) > tol) return true;
  return false;
}

}  // namespace

double linkFormFactor(const Polygon& p, const Polygon& q, int order, double relTol) {
  if (order != kAutoOrder) return polygonToPolygonFormFactor(p, q, order);
  return linkFormFactorFrom(p, q, linkFormFactorIntegral(p, q, relTol));
}

double linkFormFactorIntegral(const Polygon& p, const Polygon& q, double relTol) {
  // Integrate over the smaller patch and use reciprocity: a Gauss rule on the larger one misses
  // the log-singular strip along a shared edge (README of the reference: perp_common_edge_*).
  const bool swap = p.area() > q.area();
  const Polygon& from = swap ? q : p;
  const Polygon& to = swap ? p : q;
  // How near is measured against the patch integrated over (areaAverageFormFactor's rule, with the
  // adaptive rule up to a ratio of 1 so that shared edges stay adaptive): F(x -> to) varies over
  // `from` on the scale of x's distance to `to`, whatever `to`'s size. The larger patch's size
  // would make every pair with a giant patch adaptive (issue 18: a mutated vertex 1e10 m away).
  return areaAverageFormFactor(from, to, relTol, 1.0);
}

double linkFormFactorFrom(const Polygon& p, const Polygon& q, double fromSmaller) {
  const double ap = p.area(), aq = q.area();
  return ap > aq ? std::min(1.0, fromSmaller * aq / ap) : fromSmaller;
}

FacingPlane facingPlane(const Polygon& p) {
  return {p.normal(), p.centroid(), polygonSize(p)};
}

bool mutuallyFacing(const Polygon& p, const FacingPlane& pPlane, const Polygon& q,
                    const FacingPlane& qPlane) {
  return someVertexInFront(p, pPlane, qPlane) && someVertexInFront(q, qPlane, pPlane);
}

}  // namespace rad
