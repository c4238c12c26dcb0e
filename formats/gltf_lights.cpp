// KHR_lights_punctual (contract in gltf_lights.h). The extension's text: Khronos,
// "KHR_lights_punctual" (glTF 2.0 extension registry); Blender's conversion: its exporter,
// io_scene_gltf2/blender/exp/gltf2_blender_gather_lights.py (Blender 3.4).
#include "formats/gltf_lights.h"

#include <tiny_gltf.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "libcommon/core/error.h"

namespace rad {

namespace {

constexpr double kHalfPi = 1.57079632679489661923;

bool finite(double x) {
  return std::isfinite(x);
}

std::string num(double x) {
  std::ostringstream os;
  os << x;
  return os.str();
}

PunctualLight readLight(const std::string& path, const tinygltf::Light& g, int index,
                        LightUnits units) {
  const std::string where = "light " + std::to_string(index);
  auto fail = [&](const std::string& what) { throw inputError(path, where + ": " + what); };
  PunctualLight l;
  l.name = g.name;
  if (g.type == "point")
    l.type = PunctualLightType::kPoint;
  else if (g.type == "spot")
    l.type = PunctualLightType::kSpot;
  else if (g.type == "directional")
    l.type = PunctualLightType::kDirectional;
  else
    fail("type '" + g.type.substr(0, 40) + "'; expected point, spot or directional");
  glm::dvec3 colour(1.0);
  if (!g.color.empty()) {
    if (g.color.size() != 3) fail("color has " + std::to_string(g.color.size()) + " values");
    for (int c = 0; c < 3; ++c) {
      if (!finite(g.color[size_t(c)]) || g.color[size_t(c)] < 0.0)
        fail("color " + num(g.color[size_t(c)]) + "; expected finite values >= 0");
      colour[c] = g.color[size_t(c)];
    }
  }
  if (!finite(g.intensity) || g.intensity < 0.0)
    fail("intensity " + num(g.intensity) + "; expected a finite value >= 0");
  const double scale = units == LightUnits::kBlender ? 1.0 / kBlenderLumensPerWatt : 1.0;
  l.intensity = colour * (g.intensity * scale);
  for (int c = 0; c < 3; ++c)
    if (!(l.intensity[c] <= kMaxEmission))
      fail("intensity " + num(l.intensity[c]) + " beyond " + num(kMaxEmission));
  if (!finite(g.range) || g.range < 0.0) fail("range " + num(g.range) + "; expected >= 0");
  l.range = g.range;
  if (l.type == PunctualLightType::kSpot) {
    l.innerConeAngle = g.spot.innerConeAngle;
    l.outerConeAngle = g.spot.outerConeAngle;
    if (!finite(l.innerConeAngle) || !finite(l.outerConeAngle) || l.innerConeAngle < 0.0 ||
        !(l.innerConeAngle < l.outerConeAngle) || !(l.outerConeAngle <= kHalfPi))
      fail("spot cones inner " + num(l.innerConeAngle) + ", outer " + num(l.outerConeAngle) +
           "; expected 0 <= inner < outer <= pi/2");
    l.profile = units == LightUnits::kBlender ? SpotProfile::kCycles : SpotProfile::kGltf;
  }
  return l;
}

}  // namespace

std::string lightUnitsName(LightUnits units) {
  switch (units) {
    case LightUnits::kAuto:
      return "auto";
    case LightUnits::kGltf:
      return "gltf";
    case LightUnits::kBlender:
      return "blender";
  }
  return "auto";
}

LightUnits parseLightUnits(const std::string& name) {
  for (LightUnits u : {LightUnits::kAuto, LightUnits::kGltf, LightUnits::kBlender})
    if (lightUnitsName(u) == name) return u;
  throw std::invalid_argument("light units '" + name + "'; expected auto, gltf or blender");
}

LightUnits resolveLightUnits(LightUnits units, const std::string& generator) {
  if (units != LightUnits::kAuto) return units;
  return generator.rfind("Khronos glTF Blender I/O", 0) == 0 ? LightUnits::kBlender
                                                             : LightUnits::kGltf;
}

void readPunctualLights(const std::string& path, const tinygltf::Model& model, LightUnits units,
                        Scene& scene) {
  const LightUnits resolved = resolveLightUnits(units, model.asset.generator);
  scene.lightUnits = lightUnitsName(resolved);
  scene.lights.clear();
  for (size_t i = 0; i < model.lights.size(); ++i)
    scene.lights.push_back(readLight(path, model.lights[i], int(i), resolved));
  for (size_t n = 0; n < model.nodes.size() && n < scene.nodes.size(); ++n) {
    const auto ext = model.nodes[n].extensions.find("KHR_lights_punctual");
    if (ext == model.nodes[n].extensions.end() || !ext->second.Has("light")) continue;
    const tinygltf::Value& v = ext->second.Get("light");
    const double index = v.IsInt()      ? double(v.Get<int>())
                         : v.IsNumber() ? v.GetNumberAsDouble()
                                        : -1.0;
    if (!(index >= 0.0 && index < double(scene.lights.size()) && index == std::floor(index)))
      throw inputError(path, "node " + std::to_string(n) + ": light " +
                                 (v.IsNumber() ? num(index) : std::string("(not a number)")) +
                                 " out of range (" + std::to_string(scene.lights.size()) +
                                 " lights)");
    scene.nodes[n].light = int(index);
  }
}

}  // namespace rad
