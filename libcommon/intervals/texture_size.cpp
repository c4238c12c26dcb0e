// The texture size rule of rad-intervals (texture_intervals_builder.h: "texture size", "size
// hysteresis", TextureShape).
#include <algorithm>
#include <cmath>

#include "libcommon/intervals/texture_intervals_builder.h"

namespace rad {
namespace {

// The ladder's side for n texels along one axis, kept at `current` (> 0) while n stays within
// a factor (1 + tol) of the interval (current / r, current] it was rounded from.
int ladderSideFor(double n, int current, const TextureIntervalsOptions& o) {
  if (current > 0) {
    double tol = 1.0 + o.resizeTolerance;
    if (n > current / (o.sizeRatio * tol) && n <= current * tol) return current;
  }
  // The first side of the ladder round(r^k), k = 0, 1, ... that holds n texels.
  long side = 1;
  for (int k = 1; side < n && side < (1L << 20); ++k)
    side = std::lround(std::pow(o.sizeRatio, double(k)));
  side = std::clamp<long>(side, o.minSize, o.maxSize);
  return int(side);
}

// n of the size rule: at least one texel per covered pixel, n^2 = area x density.
double texelsPerSide(double projectedPixels, const TextureIntervalsOptions& o) {
  return std::sqrt(std::max(0.0, projectedPixels) * o.texelDensity);
}

}  // namespace

int textureSideFor(double projectedPixels, int current, const TextureIntervalsOptions& o) {
  return ladderSideFor(texelsPerSide(projectedPixels, o), current, o);
}

TextureShape textureShapeOf(const Polygon& p) {
  glm::dvec3 eu, ev;
  if (p.count == 3) {
    eu = p.v[1] - p.v[0];
    ev = p.v[2] - p.v[0];
  } else {
    eu = 0.5 * ((p.v[1] - p.v[0]) + (p.v[2] - p.v[3]));
    ev = 0.5 * ((p.v[3] - p.v[0]) + (p.v[2] - p.v[1]));
  }
  const double lu = glm::length(eu), lv = glm::length(ev);
  if (!(lu > 0.0) || !(lv > 0.0)) return {};
  // sin of the angle between the axes; a sliver's large 1 / sin is bounded by the side clamp.
  const double sine = glm::length(glm::cross(eu, ev)) / (lu * lv);
  if (!(sine > 1e-9) || !std::isfinite(sine)) return {};
  return {std::sqrt(lu / lv / sine), std::sqrt(lv / lu / sine)};
}

TextureSize textureSizeFor(double projectedPixels, TextureShape shape, TextureSize current,
                           const TextureIntervalsOptions& o) {
  const double n = texelsPerSide(projectedPixels, o);
  return {ladderSideFor(n * shape.u, current.width, o),
          ladderSideFor(n * shape.v, current.height, o)};
}

}  // namespace rad
