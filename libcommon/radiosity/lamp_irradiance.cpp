// A lamp's irradiance on a radiosity element (contract in lamp_irradiance.h).
#include "libcommon/radiosity/lamp_irradiance.h"

#include <algorithm>
#include <cmath>

namespace rad {

double frontSolidAngle(const Polygon& p, const glm::dvec3& x) {
  const glm::dvec3 n = p.normal();
  if (!(glm::dot(n, x - p.v[0]) > 0.0)) return 0.0;
  double sum = 0.0;
  for (int k = 1; k + 1 < p.count; ++k) {
    const glm::dvec3 a = p.v[0] - x, b = p.v[size_t(k)] - x, c = p.v[size_t(k + 1)] - x;
    const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
    const double num = std::abs(glm::dot(a, glm::cross(b, c)));
    const double den =
        la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
    double half = std::atan2(num, den);  // in [0, pi]: a triangle seen past 90 degrees
    sum += 2.0 * half;
  }
  return sum;
}

LampValue lampIrradiance(const PlacedPunctualLight& lamp, const Polygon& world,
                         const glm::dvec3& normal, const VisibilityScene* visibility,
                         std::uint32_t surface) {
  LampValue out;
  const double area = world.area();
  if (!(area > 0.0)) return out;
  constexpr int m = kLampSamplesPerSide;
  double kernelSum = 0.0, weighted = 0.0, seen = 0.0;
  double lo = INFINITY, hi = -INFINITY;
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      const glm::dvec3 x = pointOnPolygon(world, (i + 0.5) / m, (j + 0.5) / m);
      const glm::dvec3 E = lamp.irradiance(x, normal);
      bool open = std::max(E.x, std::max(E.y, E.z)) > 0.0;
      if (open && visibility)
        open = !visibility->occluded(x, lamp.shadowTarget(x), surface, VisibilityScene::kNoSurface);
      const double e = open ? std::max(E.x, std::max(E.y, E.z)) : 0.0;
      lo = std::min(lo, e);
      hi = std::max(hi, e);
      if (lamp.directional()) {
        seen += open ? 1.0 : 0.0;
        continue;
      }
      const glm::dvec3 d = x - lamp.position();
      const double d2 = glm::dot(d, d);
      const double cosX = d2 > 0.0 ? -glm::dot(normal, d) / std::sqrt(d2) : 0.0;
      if (!(cosX > 0.0)) continue;
      const double K = cosX / d2;
      kernelSum += K;
      // f_k: the lamp's irradiance relative to the isotropic unoccluded I cos / d^2.
      const double peak = std::max(lamp.light().intensity.x,
                                   std::max(lamp.light().intensity.y, lamp.light().intensity.z));
      if (open && peak > 0.0) weighted += K * (e / (peak * K));
    }
  out.spread = hi > lo ? hi - lo : 0.0;
  if (lamp.directional()) {
    out.mean = lamp.irradiance(world.centroid(), normal) * (seen / (m * m));
    return out;
  }
  if (!(kernelSum > 0.0)) return out;
  const double omega = frontSolidAngle(world, lamp.position());
  out.mean = lamp.light().intensity * (omega / area * weighted / kernelSum);
  return out;
}

}  // namespace rad
