// glTF 2.0 §3.7.2 primitive topology to triangles (spec: formats/gltf_scene.md).
#include "formats/gltf_triangles.h"

#include <algorithm>

namespace rad {

namespace {
constexpr int kModeTriangles = 4;  // glTF §3.7.2.1 primitive.mode
constexpr int kModeTriangleStrip = 5;
}  // namespace

std::vector<std::array<uint32_t, 3>> unrollTriangles(int mode, const std::vector<uint32_t>& idx,
                                                     const std::string& where,
                                                     std::vector<std::string>& warnings) {
  std::vector<std::array<uint32_t, 3>> tris;
  if (mode == kModeTriangles) {
    if (idx.size() % 3 != 0)
      warnings.push_back(where + ": " + std::to_string(idx.size() % 3) +
                         " trailing indices ignored");
    for (size_t i = 0; i + 2 < idx.size(); i += 3) tris.push_back({idx[i], idx[i + 1], idx[i + 2]});
  } else if (mode == kModeTriangleStrip) {
    for (size_t i = 0; i + 2 < idx.size(); ++i)
      tris.push_back({idx[i], idx[i + 1 + i % 2], idx[i + 2 - i % 2]});
  } else {
    for (size_t i = 0; i + 2 < idx.size(); ++i) tris.push_back({idx[i + 1], idx[i + 2], idx[0]});
  }
  return tris;
}

size_t appendTriangles(const std::vector<std::array<uint32_t, 3>>& tris,
                       const PrimitiveVertices& vertices, int material, Mesh& mesh) {
  const std::vector<double>& p = vertices.positions;
  const std::vector<double>& uv = vertices.uv;
  const std::vector<double>& normals = vertices.normals;
  size_t dropped = 0;
  for (const auto& t : tris) {
    MeshTriangle mt;
    mt.material = material;
    for (size_t k = 0; k < 3; ++k) {
      const size_t v = t[k];
      mt.p[k] = {p[3 * v], p[3 * v + 1], p[3 * v + 2]};
      if (!uv.empty()) mt.uv[k] = {uv[2 * v], uv[2 * v + 1]};
      if (!normals.empty()) {
        const glm::dvec3 n(normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]);
        const double len = glm::length(n);
        mt.normal[k] = len > 1e-12 ? n / len : glm::dvec3(0.0);
      }
    }
    // A triangle with a zero normal at a vertex, or whose normals all equal its flat
    // normal (a flat-shaded export), stays flat.
    bool smooth = !normals.empty(), flat = true;
    const glm::dvec3 faceNormal = glm::normalize(glm::cross(mt.p[1] - mt.p[0], mt.p[2] - mt.p[0]));
    for (size_t k = 0; k < 3 && smooth; ++k) {
      smooth = mt.normal[k] != glm::dvec3(0.0);
      flat = flat && glm::dot(mt.normal[k], faceNormal) > 1.0 - 1e-9;
    }
    if (!smooth || flat) mt.normal = {};
    // Zero area (relative to the longest edge, so needles of collinear points count too).
    const double twiceArea = glm::length(glm::cross(mt.p[1] - mt.p[0], mt.p[2] - mt.p[0]));
    double edge = 0.0;
    for (size_t k = 0; k < 3; ++k) edge = std::max(edge, glm::length(mt.p[(k + 1) % 3] - mt.p[k]));
    if (!(twiceArea > 1e-12 * edge * edge)) {
      ++dropped;
      continue;
    }
    mesh.triangles.push_back(mt);
  }
  return dropped;
}

}  // namespace rad
