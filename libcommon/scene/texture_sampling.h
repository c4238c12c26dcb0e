// Sampling of a glTF texture as the toolchain reads them (decoded to linear RGB, Texture).
#pragma once

#include <array>

#include <glm/glm.hpp>

#include "libcommon/scene/scene.h"

namespace rad {

// Bilinear sample with glTF's default sampler (LINEAR, REPEAT). glTF's (u,v) = (0,0) is the
// first texel of the first row of the image (Texture::rgb row 0).
glm::dvec3 sampleRepeat(const Texture& tex, glm::dvec2 uv);

// Whether the texture has pixels to sample.
bool hasPixels(const Texture& tex);

// The attribute map of a polygon's (u,v) parameterisation applied to per-vertex values
// (patch_hierarchy.h: quads bilinear over v0..v3, triangles affine over v0..v2).
glm::dvec2 interpolateCorners(const std::array<glm::dvec2, 4>& c, int count, glm::dvec2 uv);

}  // namespace rad
