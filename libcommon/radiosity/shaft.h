// Shaft culling (Haines & Wallace 1994, "Shaft culling for efficient ray-cast radiosity"):
// may an axis-aligned box meet the convex hull of two polygons? Used to decide which links a
// moving object may shadow between two key times (space_time_radiosity.h) and which blockers
// lie between a receiver and a light (rad-movies). Conservative: `false` is exact, `true` may
// be wrong. Pure geometry: deterministic, thread-safe.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "libcommon/scene/geometry.h"

namespace rad {

// Shaft culling (Haines & Wallace 1994, "Shaft culling for efficient ray-cast radiosity"):
// true when the axis-aligned box [lo, hi] may meet the convex hull of the two polygons. The
// shaft used is the hull's bounding box intersected with the prisms over the hull's three
// axis-aligned projections (a 2D convex hull each), which contains the hull: a `false` is
// exact, a `true` may be conservative.
bool shaftMeetsBox(const Polygon& a, const Polygon& b, const glm::dvec3& lo, const glm::dvec3& hi);

// The same shaft built once, for testing many boxes against one pair of polygons (rad-movies'
// blockers of one receiver and one light).
class Shaft {
 public:
  Shaft(const Polygon& a, const Polygon& b);
  bool meets(const glm::dvec3& lo, const glm::dvec3& hi) const;

 private:
  struct Edge {
    int axis;            // the projection drops this axis
    glm::dvec2 p0, out;  // a hull edge's start and outward unit normal
  };
  glm::dvec3 lo_{0.0}, hi_{0.0};
  double scale_ = 0;
  std::vector<Edge> edges_;
};

}  // namespace rad
