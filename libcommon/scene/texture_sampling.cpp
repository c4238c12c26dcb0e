// Texture sampling (texture_sampling.h).
#include "libcommon/scene/texture_sampling.h"

#include <cmath>

namespace rad {

glm::dvec3 sampleRepeat(const Texture& tex, glm::dvec2 uv) {
  int w = tex.width, h = tex.height;
  double x = uv.x * w - 0.5, y = uv.y * h - 0.5;
  double fx0 = std::floor(x), fy0 = std::floor(y);
  double fx = x - fx0, fy = y - fy0;
  auto wrap = [](double i, int n) {
    long long k = (long long)i % n;
    return int(k < 0 ? k + n : k);
  };
  int i0 = wrap(fx0, w), i1 = wrap(fx0 + 1, w), j0 = wrap(fy0, h), j1 = wrap(fy0 + 1, h);
  auto at = [&](int i, int j) {
    const float* p = tex.rgb.data() + (size_t(j) * w + i) * 3;
    return glm::dvec3(p[0], p[1], p[2]);
  };
  return (1 - fy) * ((1 - fx) * at(i0, j0) + fx * at(i1, j0)) +
         fy * ((1 - fx) * at(i0, j1) + fx * at(i1, j1));
}

bool hasPixels(const Texture& tex) {
  return tex.width > 0 && tex.height > 0 && tex.rgb.size() == size_t(tex.width) * tex.height * 3;
}

glm::dvec2 interpolateCorners(const std::array<glm::dvec2, 4>& c, int count, glm::dvec2 uv) {
  if (count == 3) return c[0] + uv.x * (c[1] - c[0]) + uv.y * (c[2] - c[0]);
  return (1 - uv.x) * (1 - uv.y) * c[0] + uv.x * (1 - uv.y) * c[1] + uv.x * uv.y * c[2] +
         (1 - uv.x) * uv.y * c[3];
}

}  // namespace rad
