// A glTF primitive's vertices and indices made into the scene's triangles (spec:
// formats/gltf_scene.md; glTF 2.0 §3.7.2 "Meshes"): the topology (list, strip, fan) unrolled,
// the shading normals kept or dropped, zero-area triangles dropped. Pure: no file, no model; the
// reader (gltf_scene.cpp) checks the accessors before it calls these.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "libcommon/scene/scene.h"

namespace rad {

// Triangle list per glTF §3.7.2 for mode TRIANGLES (4), TRIANGLE_STRIP (5) or TRIANGLE_FAN (6)
// (strip: p_i = {v_i, v_{i+1+i%2}, v_{i+2-i%2}}; fan: p_i = {v_{i+1}, v_{i+2}, v_0}). A list whose
// index count is not a multiple of 3 adds one warning "WHERE: N trailing indices ignored".
std::vector<std::array<uint32_t, 3>> unrollTriangles(int mode, const std::vector<uint32_t>& idx,
                                                     const std::string& where,
                                                     std::vector<std::string>& warnings);

// The vertex data of one primitive, all already checked: positions 3 per vertex (finite),
// uv 2 per vertex or empty, normals 3 per vertex or empty; every index < vertex count.
struct PrimitiveVertices {
  const std::vector<double>& positions;
  const std::vector<double>& uv;
  const std::vector<double>& normals;
};

// Appends to `mesh` one MeshTriangle of material `material` per triangle, in order. A triangle
// with a zero normal at a vertex, or whose normals all equal its flat normal, stays flat (no
// normals). Returns how many triangles were dropped for zero area (relative to the longest
// edge, so needles of collinear points count too).
size_t appendTriangles(const std::vector<std::array<uint32_t, 3>>& tris,
                       const PrimitiveVertices& vertices, int material, Mesh& mesh);

}  // namespace rad
