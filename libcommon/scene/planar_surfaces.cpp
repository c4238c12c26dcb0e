// Planar surfaces of top-level patches. Contracts in planar_surfaces.h.
#include "libcommon/scene/planar_surfaces.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

namespace rad {

std::vector<uint32_t> planarSurfaceOfTops(const std::vector<InputPolygon>& tops) {
  double size = 0.0;
  for (const InputPolygon& t : tops)
    for (int k = 1; k < t.local.count; ++k)
      size = std::max(size, glm::length(t.local.v[size_t(k)] - t.local.v[0]));
  const double q = size > 0.0 ? 1e-9 * size : 1.0;
  std::map<std::array<long long, 6>, uint32_t> first;  // plane key -> its lowest top
  std::vector<uint32_t> surface(tops.size());
  for (size_t i = 0; i < tops.size(); ++i) {
    const InputPolygon& t = tops[i];
    const glm::dvec3 n = t.local.normal();
    const double d = glm::dot(n, t.local.v[0]);
    const std::array<long long, 6> key = {(long long)t.node * 2 + (t.backFace ? 1 : 0),
                                          t.material,
                                          std::llround(n.x * 1e6),
                                          std::llround(n.y * 1e6),
                                          std::llround(n.z * 1e6),
                                          std::llround(d / q)};
    surface[i] = first.emplace(key, uint32_t(i)).first->second;
  }
  return surface;
}

}  // namespace rad
