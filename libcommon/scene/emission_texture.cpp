// Emissive textures (emission_texture.h).
#include "libcommon/scene/emission_texture.h"

#include <algorithm>
#include <cmath>

#include "libcommon/scene/texture_sampling.h"

namespace rad {
namespace {

// Subdivisions per side of a patch's (u,v) domain: about two samples per texel along each side
// of the footprint, bounded so a patch costs at most 64^2 samples.
int samplesPerSide(const Texture& tex, const InputPolygon& top) {
  const int n = top.local.count;
  double area = 0.0;  // of the footprint in texels (shoelace over the corners' uvs)
  for (int k = 0; k < n; ++k) {
    const glm::dvec2 a = top.uv[size_t(k)] * glm::dvec2(tex.width, tex.height);
    const glm::dvec2 b = top.uv[size_t((k + 1) % n)] * glm::dvec2(tex.width, tex.height);
    area += a.x * b.y - a.y * b.x;
  }
  const double side = std::sqrt(std::abs(0.5 * area));
  return std::clamp(int(std::ceil(2.0 * side)), 4, 64);
}

}  // namespace

bool hasEmissiveTexture(const Scene& scene, const Material& mat) {
  return mat.isEmitter() && mat.emissiveTexture >= 0 &&
         size_t(mat.emissiveTexture) < scene.textures.size() &&
         hasPixels(scene.textures[size_t(mat.emissiveTexture)]);
}

glm::dvec3 emissionAt(const Scene& scene, const Material& mat, glm::dvec2 texUv) {
  if (!hasEmissiveTexture(scene, mat)) return mat.emission;
  return mat.emission * sampleRepeat(scene.textures[size_t(mat.emissiveTexture)], texUv);
}

glm::dvec3 meanEmissionOver(const Scene& scene, const InputPolygon& top) {
  if (top.material < 0 || size_t(top.material) >= scene.materials.size()) return glm::dvec3(0.0);
  const Material& mat = scene.materials[size_t(top.material)];
  if (!hasEmissiveTexture(scene, mat)) return mat.emission;
  const Texture& tex = scene.textures[size_t(mat.emissiveTexture)];
  const int n = samplesPerSide(tex, top), count = top.local.count;
  glm::dvec3 sum(0.0);
  int samples = 0;
  const auto add = [&](double u, double v) {
    sum += sampleRepeat(tex, interpolateCorners(top.uv, count, glm::dvec2(u, v)));
    ++samples;
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      if (count != 3) {
        add((i + 0.5) / n, (j + 0.5) / n);
      } else if (i + j < n) {  // the sub-triangle at (i, j) and, below the diagonal, its mirror
        add((i + 1.0 / 3.0) / n, (j + 1.0 / 3.0) / n);
        if (i + j < n - 1) add((i + 2.0 / 3.0) / n, (j + 2.0 / 3.0) / n);
      }
    }
  return mat.emission * (sum / double(std::max(samples, 1)));
}

}  // namespace rad
