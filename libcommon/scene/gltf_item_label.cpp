// Labels of glTF items in messages (gltf_item_label.h).
#include "libcommon/scene/gltf_item_label.h"

namespace rad {
namespace {

// Bytes of a name kept in a message, as the glTF reader cuts quoted input.
constexpr size_t kMaxLabelName = 120;

std::string oneLineName(const std::string& name) {
  std::string out;
  for (char c : name) out += (static_cast<unsigned char>(c) < 0x20) ? ' ' : c;
  if (out.size() <= kMaxLabelName) return out;
  size_t end = kMaxLabelName;  // at a UTF-8 character boundary
  while (end > 0 && (static_cast<unsigned char>(out[end]) & 0xC0) == 0x80) --end;
  return out.substr(0, end) + "…";
}

}  // namespace

std::string gltfItemLabel(const std::string& kind, int index, const std::string& name) {
  if (name.empty()) return kind + " " + std::to_string(index);
  return kind + " \"" + oneLineName(name) + "\" (" + std::to_string(index) + ")";
}

std::string nodeLabel(const Scene& scene, int node) {
  const bool known = node >= 0 && size_t(node) < scene.nodes.size();
  return gltfItemLabel("node", node, known ? scene.nodes[size_t(node)].name : "");
}

std::string meshLabel(const Scene& scene, int mesh) {
  const bool known = mesh >= 0 && size_t(mesh) < scene.meshes.size();
  return gltfItemLabel("mesh", mesh, known ? scene.meshes[size_t(mesh)].name : "");
}

std::string materialLabel(const Scene& scene, int material) {
  if (material < 0 || size_t(material) >= scene.materials.size()) return "the default material";
  const Material& m = scene.materials[size_t(material)];
  return gltfItemLabel("material", m.gltfIndex >= 0 ? m.gltfIndex : material, m.name);
}

}  // namespace rad
