// Emissive textures (glTF 2.0 §3.9.3 `emissiveTexture`; issue 57): a material's exitant
// radiance varies over its surface, $L_e(x) = L_e \cdot \mathrm{tex}(uv(x))$ with L_e the
// material's emissiveFactor x strength (Material::emission). The second pass shows it per pixel
// (rad-compose); the first pass and the light a patch casts take its mean over each top-level
// patch's texture footprint, so a patch emits the power $\pi A \overline{L_e}$ (paper §3.1: the
// global pass is coarse, the gather is per pixel). Without a texture both are
// Material::emission, bit for bit.
#pragma once

#include <glm/glm.hpp>

#include "libcommon/scene/scene.h"

namespace rad {

// Whether the material has an emissive texture with pixels (and emits).
bool hasEmissiveTexture(const Scene& scene, const Material& mat);

// L_e at texture coordinates `texUv` (the polygon's TEXCOORD interpolated), bilinear with
// glTF's default sampler; Material::emission without an emissive texture.
glm::dvec3 emissionAt(const Scene& scene, const Material& mat, glm::dvec2 texUv);

// The mean of L_e over a top-level patch: its (u,v) domain sampled at the centres of n x n equal
// cells (a quad, parallelogram: equal areas) or n^2 equal sub-triangles (a triangle), n from the
// texels its footprint covers (4 to 64); Material::emission without an emissive texture, zero
// without a material. Deterministic.
glm::dvec3 meanEmissionOver(const Scene& scene, const InputPolygon& top);

}  // namespace rad
