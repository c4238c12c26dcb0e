#include "libcommon/scene/scene_summary.h"

#include <map>
#include <sstream>

#include "libcommon/scene/emission_texture.h"
#include "libcommon/scene/punctual_light_emitter.h"

namespace rad {

namespace {
nlohmann::json vec3(const glm::dvec3& v) {
  return {v.x, v.y, v.z};
}
}  // namespace

glm::dvec3 emittedPower(const Scene& scene, const InputPolygon& polygon, double t) {
  if (polygon.material < 0) return glm::dvec3(0.0);
  double area = polygon.local.transformed(scene.worldTransform(polygon.node, t)).area();
  return glm::pi<double>() * meanEmissionOver(scene, polygon) * area;
}

namespace {
// The KHR_lights_punctual lights on nodes of the scene, as the stages read them.
nlohmann::json summarizeLights(const Scene& scene, double t0, double t1) {
  static const char* kTypes[] = {"point", "spot", "directional"};
  nlohmann::json lights = nlohmann::json::array();
  const std::vector<int> nodes = scene.lightNodes();
  if (nodes.empty()) return lights;
  const std::array<glm::dvec3, 2> bounds = animationBounds(scene);
  for (int n : nodes) {
    const PunctualLightEmitter emitter(scene, n, bounds);
    const PunctualLight& l = emitter.light();
    const std::unique_ptr<PlacedEmitter> placed = emitter.at(t0);
    const auto* p = dynamic_cast<const PlacedPunctualLight*>(placed.get());
    nlohmann::json j = {
        {"node", n},
        {"name", l.name},
        {"light", scene.nodes[size_t(n)].light},
        {"type", kTypes[int(l.type)]},
        {"units", scene.lightUnits},
        {l.type == PunctualLightType::kDirectional ? "irradiance_w_m2" : "intensity_w_sr",
         vec3(l.intensity)},
        {"range", l.range},
        {"dynamic", emitter.moves(t0, t1)}};
    if (p) {
      j["position_at_start"] = vec3(p->position());
      j["direction_at_start"] = vec3(p->direction());
      j["power_w"] = vec3(p->power());
    }
    if (l.type == PunctualLightType::kSpot) {
      j["inner_cone"] = l.innerConeAngle;
      j["outer_cone"] = l.outerConeAngle;
      j["profile"] = l.profile == SpotProfile::kCycles ? "cycles" : "gltf";
    }
    lights.push_back(j);
  }
  return lights;
}
}  // namespace

nlohmann::json summarizeScene(const Scene& scene) {
  nlohmann::json s;
  double t0 = scene.startTime(), t1 = scene.endTime();
  std::vector<InputPolygon> polygons = scene.inputPolygons();
  size_t triangles = 0;
  for (int n : scene.meshNodes()) triangles += scene.meshes[scene.nodes[n].mesh].triangles.size();
  s["path"] = scene.path;
  s["time_range"] = {t0, t1};
  s["mesh_nodes"] = scene.meshNodes().size();
  s["triangles"] = triangles;
  s["patches"] = polygons.size();
  // One pass over the polygons (in node order), each node's transform made once: a floor of
  // thousands of mesh nodes made the per-node scans of every polygon quadratic (issue 58).
  size_t quads = 0;
  double area = 0.0;
  std::map<int, std::pair<glm::dvec3, size_t>> emitted;  // node -> (power, patches)
  int placedNode = -1;
  glm::dmat4 worldFromLocal(1.0);
  for (const InputPolygon& p : polygons) {
    if (p.node != placedNode) worldFromLocal = scene.worldTransform(placedNode = p.node, t0);
    quads += p.local.count == 4;
    area += p.local.transformed(worldFromLocal).area();
    if (p.material < 0 || !scene.materials[p.material].isEmitter()) continue;
    std::pair<glm::dvec3, size_t>& e =
        emitted.try_emplace(p.node, glm::dvec3(0.0), 0).first->second;
    e.first += emittedPower(scene, p, t0);
    ++e.second;
  }
  s["quads"] = quads;
  s["total_area_m2"] = area;

  // Emitters grouped by mesh node.
  nlohmann::json emitters = nlohmann::json::array();
  for (int n : scene.meshNodes()) {
    const auto it = emitted.find(n);
    if (it == emitted.end()) continue;
    const glm::dvec3 power = it->second.first;
    const size_t count = it->second.second;
    emitters.push_back({{"node", n},
                        {"name", scene.nodes[n].name},
                        {"patches", count},
                        {"power_w", vec3(power)},
                        {"dynamic", scene.isDynamic(n, t0, t1)}});
  }
  s["emitters"] = emitters;
  s["lights"] = summarizeLights(scene, t0, t1);

  nlohmann::json dynamic = nlohmann::json::array();
  for (int n : scene.meshNodes()) {
    if (!scene.isDynamic(n, t0, t1)) continue;
    auto b = scene.sweptBounds(n, t0, t1);
    dynamic.push_back(
        {{"node", n}, {"name", scene.nodes[n].name}, {"swept_bounds", {vec3(b[0]), vec3(b[1])}}});
  }
  s["dynamic_nodes"] = dynamic;

  nlohmann::json cameras = nlohmann::json::array();
  for (int n : scene.cameraNodes()) {
    const Camera& c = scene.cameras[scene.nodes[n].camera];
    CameraView v0 = scene.cameraAt(n, t0);
    cameras.push_back({{"node", n},
                       {"name", scene.nodes[n].name},
                       {"type", c.perspective ? "perspective" : "orthographic"},
                       {"yfov", c.yfov},
                       {"eye_at_start", vec3(v0.eye())},
                       {"animated", scene.isDynamic(n, t0, t1)}});
  }
  s["cameras"] = cameras;

  nlohmann::json warnings = scene.warnings;
  if (cameras.empty()) warnings.push_back("no camera: rad-intervals and rad-compose need one");
  if (emitters.empty() && s["lights"].empty())
    warnings.push_back(missingEmitterMessage(scene) + " (rad-global and rad-reference refuse it)");
  s["warnings"] = warnings;
  return s;
}

std::string sceneSummaryText(const nlohmann::json& s) {
  std::ostringstream os;
  os << s["path"].get<std::string>() << ": glTF scene\n";
  os << "  time range     " << s["time_range"][0] << " .. " << s["time_range"][1] << " s\n";
  os << "  patches        " << s["patches"] << " (" << s["quads"] << " quads) from "
     << s["triangles"] << " triangles in " << s["mesh_nodes"] << " mesh nodes, "
     << s["total_area_m2"] << " m^2\n";
  for (const auto& e : s["emitters"]) {
    os << "  emitter        " << e["name"].get<std::string>() << " (node " << e["node"] << "), "
       << e["patches"] << " patches, power " << e["power_w"].dump() << " W"
       << (e["dynamic"].get<bool>() ? ", moving" : "") << "\n";
  }
  for (const auto& l : s["lights"]) {
    os << "  light          " << l["name"].get<std::string>() << " (node " << l["node"] << "), "
       << l["type"].get<std::string>() << ", "
       << (l.contains("irradiance_w_m2") ? "E " + l["irradiance_w_m2"].dump() + " W/m^2"
                                         : "I " + l["intensity_w_sr"].dump() + " W/sr")
       << " (" << l["units"].get<std::string>() << " units)";
    if (l.contains("outer_cone"))
      os << ", cones " << l["inner_cone"] << " " << l["outer_cone"] << " rad ("
         << l["profile"].get<std::string>() << ")";
    os << (l["dynamic"].get<bool>() ? ", moving" : "") << "\n";
  }
  for (const auto& d : s["dynamic_nodes"]) {
    os << "  dynamic        " << d["name"].get<std::string>() << " (node " << d["node"]
       << "), swept bounds " << d["swept_bounds"].dump() << "\n";
  }
  for (const auto& c : s["cameras"]) {
    os << "  camera         " << c["name"].get<std::string>() << " (node " << c["node"] << "), "
       << c["type"].get<std::string>() << ", yfov " << c["yfov"]
       << (c["animated"].get<bool>() ? ", animated" : ", static") << "\n";
  }
  for (const auto& w : s["warnings"]) os << "  warning        " << w.get<std::string>() << "\n";
  return os.str();
}

}  // namespace rad
