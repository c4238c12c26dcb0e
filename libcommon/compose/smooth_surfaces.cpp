// Coplanar patches of one material as one surface for the pixel filter. Contract and reasons in
// smooth_surfaces.h.
#include "libcommon/compose/smooth_surfaces.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

namespace rad {

SmoothSurfaces smoothSurfaces(const std::vector<Polygon>& world,
                              const std::vector<glm::dvec3>& normals,
                              const std::vector<int>& material, const std::vector<size_t>& object,
                              const std::vector<char>& fullItem) {
  const size_t n = world.size();
  // The scene's extent, for the plane offsets' tolerance.
  double extent = 0.0;
  for (size_t t = 0; t < n; ++t)
    for (int k = 0; k < world[t].count; ++k)
      for (int a = 0; a < 3; ++a) extent = std::max(extent, std::abs(world[t].v[size_t(k)][a]));
  const double offsetStep = 1e-5 * std::max(extent, 1e-30), normalStep = 1e-5;
  using Key = std::array<long long, 6>;  // material, object, normal x y z, offset: rounded
  std::map<Key, uint32_t> byPlane;
  SmoothSurfaces s;
  s.surfaceOf.assign(n + 1, 0);
  s.fullSurface.assign(1, 0);
  for (size_t t = 0; t < n; ++t) {
    const bool full = t + 1 >= fullItem.size() || fullItem[t + 1];
    const glm::dvec3& nrm = normals[t];
    if (world[t].count < 3 || full || !std::isfinite(glm::dot(nrm, nrm))) {
      s.surfaceOf[t + 1] = uint32_t(s.fullSurface.size());
      s.fullSurface.push_back(full ? 1 : 0);
      continue;
    }
    const double offset = glm::dot(nrm, world[t].v[0]);
    const Key key{material[t],
                  (long long)object[t],
                  std::llround(nrm.x / normalStep),
                  std::llround(nrm.y / normalStep),
                  std::llround(nrm.z / normalStep),
                  std::llround(offset / offsetStep)};
    auto it = byPlane.find(key);
    if (it == byPlane.end()) {
      it = byPlane.emplace(key, uint32_t(s.fullSurface.size())).first;
      s.fullSurface.push_back(0);
    }
    s.surfaceOf[t + 1] = it->second;
  }
  return s;
}

}  // namespace rad
