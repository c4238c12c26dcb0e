// Closed solids (contract in closed_solid.h).
#include "libcommon/scene/closed_solid.h"

#include <array>
#include <map>
#include <utility>

namespace rad {
namespace {

using Point = std::array<double, 3>;

Point pointOf(const glm::dvec3& p) {
  return {p.x, p.y, p.z};
}

}  // namespace

bool isClosedSolid(const std::vector<MeshTriangle>& triangles) {
  if (triangles.size() < 4) return false;
  // Each directed edge a -> b counts +1 on the key (min, max) when a < b and -1 otherwise; a
  // consistently wound watertight mesh uses every edge once each way: two uses, sum 0.
  std::map<std::pair<Point, Point>, std::array<int, 2>> uses;  // {uses, signed sum}
  double volume6 = 0.0;  // six times the signed volume (divergence theorem)
  for (const MeshTriangle& t : triangles) {
    volume6 += glm::dot(t.p[0], glm::cross(t.p[1], t.p[2]));
    for (size_t k = 0; k < 3; ++k) {
      const Point a = pointOf(t.p[k]), b = pointOf(t.p[(k + 1) % 3]);
      if (a == b) return false;
      std::array<int, 2>& u = uses[a < b ? std::make_pair(a, b) : std::make_pair(b, a)];
      u[0] += 1;
      u[1] += a < b ? 1 : -1;
    }
  }
  for (const auto& e : uses)
    if (e.second[0] != 2 || e.second[1] != 0) return false;
  return volume6 > 0.0;
}

}  // namespace rad
