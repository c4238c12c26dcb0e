#include "libcommon/scene/scene_digest.h"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <set>

#include "libcommon/core/error.h"

namespace rad {

namespace {

// FNV-1a 64 over canonical little-endian bytes (formats/checksum.h holds the same hash for
// files; libcommon does not depend on formats/).
class Digest {
 public:
  void bytes(const void* data, size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < size; ++i) h_ = (h_ ^ p[i]) * 0x100000001b3ull;
  }
  void integer(int64_t v) {
    unsigned char b[8];
    for (int i = 0; i < 8; ++i) b[i] = static_cast<unsigned char>(uint64_t(v) >> (8 * i));
    bytes(b, 8);
  }
  void number(double v) {
    uint64_t bits;
    std::memcpy(&bits, &v, 8);
    integer(int64_t(bits));
  }
  void vec(const glm::dvec2& v) { number(v.x), number(v.y); }
  void vec(const glm::dvec3& v) { number(v.x), number(v.y), number(v.z); }
  void text(const std::string& s) {
    integer(int64_t(s.size()));
    bytes(s.data(), s.size());
  }
  std::string hex() const {
    char out[32];
    std::snprintf(out, sizeof out, "fnv1a64:%016llx", static_cast<unsigned long long>(h_));
    return out;
  }

 private:
  uint64_t h_ = 0xcbf29ce484222325ull;
};

void addGeometry(const Scene& scene, Digest& d) {
  const std::vector<InputPolygon> polygons = scene.inputPolygons();
  d.integer(int64_t(polygons.size()));
  for (const InputPolygon& p : polygons) {
    d.integer(p.local.count);
    for (int i = 0; i < p.local.count; ++i) {
      d.vec(p.local.v[size_t(i)]);
      d.vec(p.uv[size_t(i)]);
      d.vec(p.normal[size_t(i)]);
    }
    d.integer(p.node), d.integer(p.material), d.integer(p.backFace);
  }
}

void addMaterials(const Scene& scene, Digest& d) {
  d.integer(int64_t(scene.materials.size()));
  for (const Material& m : scene.materials) {
    d.vec(m.reflectance);
    d.integer(m.doubleSided);
    const bool textured =
        m.baseColorTexture >= 0 && size_t(m.baseColorTexture) < scene.textures.size();
    d.integer(textured);
    if (textured) d.vec(scene.textures[size_t(m.baseColorTexture)].mean);
  }
}

// `nodes` and their ancestors, ascending.
std::set<int> withAncestors(const Scene& scene, const std::vector<int>& nodes) {
  std::set<int> out;
  for (int n : nodes)
    for (int k = n; k >= 0 && size_t(k) < scene.nodes.size() && out.insert(k).second;)
      k = scene.nodes[size_t(k)].parent;
  return out;
}

// Rest pose and channels of `nodes`.
void addMotion(const Scene& scene, const std::set<int>& nodes, Digest& d) {
  d.integer(int64_t(nodes.size()));
  for (int n : nodes) {
    const Node& node = scene.nodes[size_t(n)];
    d.integer(n), d.integer(node.parent);
    d.vec(node.translation);
    d.number(node.rotation.w), d.number(node.rotation.x);
    d.number(node.rotation.y), d.number(node.rotation.z);
    d.vec(node.scale);
  }
  for (const AnimationChannel& c : scene.channels) {
    if (!nodes.count(c.node)) continue;
    d.integer(c.node), d.integer(int64_t(c.path)), d.integer(int64_t(c.interpolation));
    d.integer(int64_t(c.times.size()));
    for (double t : c.times) d.number(t);
    d.integer(int64_t(c.values.size()));
    for (double v : c.values) d.number(v);
  }
}

// Emission, and the lamps with their motion (a moving lamp changes the light, not the geometry).
void addLights(const Scene& scene, Digest& d) {
  d.integer(int64_t(scene.materials.size()));
  for (const Material& m : scene.materials) {
    d.vec(m.emission);
    // An emissive texture's mean (the first pass's B_e); nothing added without one, so the
    // digests of scenes without them are unchanged.
    if (m.emissiveTexture >= 0 && size_t(m.emissiveTexture) < scene.textures.size())
      d.vec(scene.textures[size_t(m.emissiveTexture)].mean);
  }
  const std::vector<int> lamps = scene.lightNodes();
  if (lamps.empty()) return;  // a scene without lamps digests as before lamps were read
  d.integer(int64_t(lamps.size()));
  for (int n : lamps) {
    const PunctualLight& l = scene.lights[size_t(scene.nodes[size_t(n)].light)];
    d.integer(n), d.integer(int64_t(l.type)), d.integer(int64_t(l.profile));
    d.vec(l.intensity), d.number(l.range), d.number(l.innerConeAngle), d.number(l.outerConeAngle);
  }
  addMotion(scene, withAncestors(scene, lamps), d);
}

void addCamera(const Scene& scene, Digest& d) {
  const std::vector<int> cameraNodes = scene.cameraNodes();
  d.integer(int64_t(cameraNodes.size()));
  for (int n : cameraNodes) {
    const Node& node = scene.nodes[size_t(n)];
    d.integer(n), d.text(node.name);
    if (node.camera < 0 || size_t(node.camera) >= scene.cameras.size()) continue;
    const Camera& c = scene.cameras[size_t(node.camera)];
    d.text(c.name), d.integer(c.perspective), d.number(c.yfov), d.number(c.aspectRatio);
    d.number(c.xmag), d.number(c.ymag), d.number(c.znear), d.number(c.zfar);
  }
  addMotion(scene, withAncestors(scene, cameraNodes), d);
}

}  // namespace

const std::vector<ScenePart>& allSceneParts() {
  static const std::vector<ScenePart> parts = {ScenePart::kGeometry, ScenePart::kMaterials,
                                               ScenePart::kLights, ScenePart::kAnimation,
                                               ScenePart::kCamera};
  return parts;
}

const char* scenePartName(ScenePart part) {
  switch (part) {
    case ScenePart::kGeometry:
      return "geometry";
    case ScenePart::kMaterials:
      return "materials";
    case ScenePart::kLights:
      return "lights";
    case ScenePart::kAnimation:
      return "animation";
    case ScenePart::kCamera:
      return "camera";
  }
  return "unknown";
}

std::string sceneDigest(const Scene& scene, ScenePart part) {
  Digest d;
  d.text(scenePartName(part));  // equal bytes of two parts still digest differently
  switch (part) {
    case ScenePart::kGeometry:
      addGeometry(scene, d);
      break;
    case ScenePart::kMaterials:
      addMaterials(scene, d);
      break;
    case ScenePart::kLights:
      addLights(scene, d);
      break;
    case ScenePart::kAnimation:
      addMotion(scene, withAncestors(scene, scene.meshNodes()), d);
      break;
    case ScenePart::kCamera:
      addCamera(scene, d);
      break;
  }
  return d.hex();
}

nlohmann::json sceneDigests(const Scene& scene, const std::vector<ScenePart>& parts) {
  nlohmann::json out = nlohmann::json::object();
  for (ScenePart p : parts) out[scenePartName(p)] = sceneDigest(scene, p);
  return out;
}

std::string sceneDigestMismatch(const nlohmann::json& recorded, const Scene& scene,
                                const std::string& producer) {
  if (!recorded.is_object()) return "";
  for (ScenePart part : allSceneParts()) {
    const std::string name = scenePartName(part);
    const auto it = recorded.find(name);
    if (it == recorded.end()) continue;
    const std::string here = sceneDigest(scene, part);
    const std::string there = it->is_string() ? it->get<std::string>() : it->dump();
    if (there == here) continue;
    const bool plural = part == ScenePart::kMaterials || part == ScenePart::kLights;
    return "made from a scene whose " + name + (plural ? " differ" : " differs") + " (" + name +
           " digest " + there.substr(0, 40) + " there, " + here + " here); re-run " +
           (producer.empty() ? std::string("the stage that wrote it") : producer);
  }
  return "";
}

void requireSceneDigests(const nlohmann::json& parameters, const std::string& where,
                         const std::string& producer, const Scene& scene) {
  if (!parameters.is_object()) return;
  const auto it = parameters.find(kSceneDigestsKey);
  if (it == parameters.end()) return;
  const std::string mismatch = sceneDigestMismatch(*it, scene, producer);
  if (!mismatch.empty()) throw inputError(where, mismatch);
}

}  // namespace rad
