// Touching solids by rays (contract in solid_contact.h).
#include "libcommon/movies/solid_contact.h"

#include <cmath>

namespace rad {

RayStart coveredBySolid(const VisibilityScene& blockers, const Scene& scene,
                        const PatchHierarchy& h, uint32_t top, const glm::dvec3& p,
                        const glm::dvec3& d, double t) {
  return rayStart(blockers, p, d, top, [&](uint32_t hit) {
    if (hit >= uint32_t(h.topCount())) return false;
    const InputPolygon& surface = h.top(int(hit));
    const int m = surface.material;
    const bool doubleSided =
        m >= 0 && m < int(scene.materials.size()) && scene.materials[size_t(m)].doubleSided;
    if (doubleSided && !surface.closedSolid) return false;
    // The solid's outside: a closed solid's reversed copy faces in (closed_solid.h).
    const glm::dvec3 n = surface.local.transformed(scene.worldTransform(surface.node, t)).normal();
    const double outward = doubleSided && surface.backFace ? -1.0 : 1.0;
    return outward * glm::dot(n, d) > 0.0;
  });
}

bool insideSolid(const VisibilityScene& blockers, const Scene& scene, const PatchHierarchy& h,
                 uint32_t top, const glm::dvec3& p, const glm::dvec3& n, double size, double t) {
  glm::dvec3 u = std::abs(n.x) > 0.5 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
  u = glm::normalize(glm::cross(u, n));
  const glm::dvec3 v = glm::cross(n, u);
  const double c = std::cos(88.0 * M_PI / 180.0), sn = std::sin(88.0 * M_PI / 180.0);
  const glm::dvec3 dirs[4] = {c * n + sn * u, c * n - sn * u, c * n + sn * v, c * n - sn * v};
  // Every ray inside or undecided (rayStart), one at least inside: a ray into a sheet of two
  // back-to-back patches is undecided, and the sheet's other side is outside.
  bool inside = false;
  for (const glm::dvec3& d : dirs) {
    const RayStart r = coveredBySolid(blockers, scene, h, top, p, d * size, t);
    if (r == RayStart::kOutside) return false;
    inside = inside || r == RayStart::kInside;
  }
  return inside;
}

}  // namespace rad
