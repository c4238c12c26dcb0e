// Small glTF scenes written by tests (no binary files in git): meshes from triangle lists, with
// optional TEXCOORD_0, in one embedded (data URI) buffer; materials, nodes, cameras and the rest
// as JSON the test writes itself.
#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace rad::test {

inline std::string base64Encoded(const std::string& bytes) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    unsigned v = (unsigned char)bytes[i] << 16;
    if (i + 1 < bytes.size()) v |= (unsigned char)bytes[i + 1] << 8;
    if (i + 2 < bytes.size()) v |= (unsigned char)bytes[i + 2];
    out += k[(v >> 18) & 63];
    out += k[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? k[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? k[v & 63] : '=';
  }
  return out;
}

class GltfBuilder {
 public:
  GltfBuilder() {
    doc_["asset"] = {{"version", "2.0"}};
    doc_["scene"] = 0;
    doc_["scenes"] = {{{"nodes", nlohmann::json::array()}}};
  }
  nlohmann::json& doc() { return doc_; }

  int addMaterial(const nlohmann::json& material) { return push("materials", material); }

  // A mesh of one primitive: float VEC3 positions (and VEC2 uvs when given), uint32 indices.
  int addMesh(const std::string& name, const std::vector<glm::vec3>& positions,
              const std::vector<uint32_t>& indices, int material,
              const std::vector<glm::vec2>& uvs = {}) {
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const glm::vec3& p : positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
    nlohmann::json attributes;
    attributes["POSITION"] = accessor(bytesOf(positions), "VEC3", positions.size(), 5126,
                                      {{"min", {lo.x, lo.y, lo.z}}, {"max", {hi.x, hi.y, hi.z}}});
    if (!uvs.empty()) attributes["TEXCOORD_0"] = accessor(bytesOf(uvs), "VEC2", uvs.size(), 5126);
    nlohmann::json primitive = {
        {"attributes", attributes},
        {"indices", accessor(bytesOf(indices), "SCALAR", indices.size(), 5125)}};
    if (material >= 0) primitive["material"] = material;
    return push("meshes", {{"name", name}, {"primitives", {primitive}}});
  }

  // A LINEAR animation of `path` ("translation", "rotation", "scale") of `node`: key `times`
  // (seconds) and their values (3 or 4 floats a key).
  int addAnimation(int node, const std::string& path, const std::vector<float>& times,
                   const std::vector<float>& values) {
    const int input = accessor(bytesOf(times), "SCALAR", times.size(), 5126,
                               {{"min", {times.front()}}, {"max", {times.back()}}});
    const int output =
        accessor(bytesOf(values), path == "rotation" ? "VEC4" : "VEC3", times.size(), 5126);
    return push("animations",
                {{"samplers", {{{"input", input}, {"output", output}}}},
                 {"channels", {{{"sampler", 0}, {"target", {{"node", node}, {"path", path}}}}}}});
  }

  // A node of the displayed scene (a root).
  int addNode(const nlohmann::json& node) {
    const int i = push("nodes", node);
    doc_["scenes"][0]["nodes"].push_back(i);
    return i;
  }

  // A perspective camera node at `translation` looking down -Z (rotation optional).
  int addCamera(const nlohmann::json& perspective, const nlohmann::json& node) {
    const int c = push("cameras", {{"type", "perspective"}, {"perspective", perspective}});
    nlohmann::json n = node;
    n["camera"] = c;
    return addNode(n);
  }

  std::string write(const std::string& path) {
    doc_["buffers"] = {{{"uri", "data:application/octet-stream;base64," + base64Encoded(bin_)},
                        {"byteLength", bin_.size()}}};
    std::ofstream(path) << doc_.dump(1);
    return path;
  }

 private:
  template <class T>
  static std::string bytesOf(const std::vector<T>& v) {
    return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  int push(const std::string& array, const nlohmann::json& item) {
    if (!doc_.contains(array)) doc_[array] = nlohmann::json::array();
    doc_[array].push_back(item);
    return int(doc_[array].size()) - 1;
  }
  int accessor(const std::string& bytes, const std::string& type, size_t count, int componentType,
               const nlohmann::json& extra = nlohmann::json::object()) {
    while (bin_.size() % 4) bin_ += '\0';
    const int view = push(
        "bufferViews", {{"buffer", 0}, {"byteOffset", bin_.size()}, {"byteLength", bytes.size()}});
    bin_ += bytes;
    nlohmann::json a = {
        {"bufferView", view}, {"componentType", componentType}, {"count", count}, {"type", type}};
    a.update(extra);
    return push("accessors", a);
  }

  nlohmann::json doc_;
  std::string bin_;
};

// An axis-aligned box [lo, hi] as 12 triangles facing out (CCW seen from outside), corners
// shared, so its edges close.
inline void boxTriangles(glm::vec3 lo, glm::vec3 hi, std::vector<glm::vec3>& positions,
                         std::vector<uint32_t>& indices) {
  const uint32_t base = uint32_t(positions.size());
  for (int i = 0; i < 8; ++i)
    positions.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
  const uint32_t faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces)
    for (uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u}) indices.push_back(base + f[k]);
}

}  // namespace rad::test
