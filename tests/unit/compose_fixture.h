// A tiny scene for rad-compose tests, written as real glTF (so the tool reads it too): a camera
// at the origin looking down -Z at a grey wall (reflectance 0.5, 2x2 m at z = -5) and a small
// lamp (L_e = (4, 2, 1), reflectance 0.5) beside it; plus builders for the global solution,
// intervals and movies the tool reads.
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "formats/gltf_scene.h"
#include "libcommon/radiosity/global_solution.h"
#include "libcommon/scene/scene.h"

namespace rad::test {

constexpr int kWallTop = 0;  // mesh node order: wall first, then lamp
constexpr int kLampTop = 1;
const glm::dvec3 kLampEmission(4.0, 2.0, 1.0);

inline void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

// Writes dir/compose.gltf (+ compose.bin) and returns the .gltf path.
inline std::string writeComposeScene(const std::string& dir) {
  std::filesystem::create_directories(dir);
  const float pos[8][3] = {{-1, -1, -5},     {1, -1, -5},      {1, 1, -5},       {-1, 1, -5},
                           {1.3f, 0.3f, -5}, {1.9f, 0.3f, -5}, {1.9f, 0.9f, -5}, {1.3f, 0.9f, -5}};
  const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
  std::string bin(reinterpret_cast<const char*>(pos), sizeof pos);
  bin += std::string(reinterpret_cast<const char*>(idx), sizeof idx);
  writeBytes(dir + "/compose.bin", bin);
  const std::string gltf = R"({
  "asset": {"version": "2.0"},
  "extensionsUsed": ["KHR_materials_emissive_strength"],
  "scene": 0,
  "scenes": [{"nodes": [0, 1, 2]}],
  "nodes": [
    {"name": "cam", "camera": 0},
    {"name": "wall", "mesh": 0},
    {"name": "lamp", "mesh": 1}
  ],
  "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
  "materials": [
    {"name": "grey", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}},
    {"name": "light", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]},
     "emissiveFactor": [1.0, 0.5, 0.25],
     "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}}
  ],
  "meshes": [
    {"name": "wall", "primitives": [{"attributes": {"POSITION": 0}, "indices": 2, "material": 0}]},
    {"name": "lamp", "primitives": [{"attributes": {"POSITION": 1}, "indices": 2, "material": 1}]}
  ],
  "buffers": [{"uri": "compose.bin", "byteLength": 108}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 48},
    {"buffer": 0, "byteOffset": 48, "byteLength": 48},
    {"buffer": 0, "byteOffset": 96, "byteLength": 12}
  ],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
     "min": [-1, -1, -5], "max": [1, 1, -5]},
    {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3",
     "min": [1.3, 0.3, -5], "max": [1.9, 0.9, -5]},
    {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}
  ]
})";
  writeBytes(dir + "/compose.gltf", gltf);
  return dir + "/compose.gltf";
}

// A global solution over the scene's top-level patches with key times `keys`; radiosity of
// node i at key k is radiosity(i, k). `splitWall` subdivides the wall once first (nodes 2..5).
template <class F>
GlobalSolution makeSolution(const Scene& scene, const std::vector<double>& keys, bool splitWall,
                            F radiosity) {
  GlobalSolution g;
  g.keyTimes = keys;
  g.hierarchy = PatchHierarchy(scene.inputPolygons());
  if (splitWall) g.hierarchy.subdivide(kWallTop);
  const int N = g.hierarchy.size(), K = int(keys.size());
  int leaves = 0;
  for (int i = 0; i < N; ++i) {
    g.leafRow.push_back(g.hierarchy.isLeaf(i) ? leaves++ : -1);
    for (int k = 0; k < K; ++k) g.nodeRadiosity.push_back(glm::vec3(radiosity(i, k)));
  }
  g.leafVertexGoodIrradiance.assign(size_t(leaves) * K * 4, glm::vec3(0.0f));
  g.validate("test solution");
  return g;
}

}  // namespace rad::test
