// Punctual lights as emitters (contract in punctual_light_emitter.h). Spot falloff and range
// window: Khronos, "KHR_lights_punctual" (its recommended implementation); Cycles' spot:
// Blender 3.4, intern/cycles/kernel/light/light.h, spot_light_attenuation.
#include "libcommon/scene/punctual_light_emitter.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

namespace rad {

namespace {

constexpr double kPi = 3.14159265358979323846;

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

}  // namespace

std::array<glm::dvec3, 2> animationBounds(const Scene& scene) {
  const double inf = std::numeric_limits<double>::infinity();
  std::array<glm::dvec3, 2> box{glm::dvec3(inf), glm::dvec3(-inf)};
  for (int n : scene.meshNodes()) {
    const std::array<glm::dvec3, 2> b = scene.sweptBounds(n, scene.startTime(), scene.endTime());
    box[0] = glm::min(box[0], b[0]);
    box[1] = glm::max(box[1], b[1]);
  }
  if (!(box[0].x <= box[1].x)) box = {glm::dvec3(0.0), glm::dvec3(0.0)};
  return box;
}

PlacedPunctualLight::PlacedPunctualLight(const PunctualLight& light, const glm::dvec3& position,
                                         const glm::dvec3& direction,
                                         const std::array<glm::dvec3, 2>& sceneBounds)
    : light_(light),
      position_(position),
      direction_(direction),
      centre_(0.5 * (sceneBounds[0] + sceneBounds[1])),
      reach_(std::max(glm::length(sceneBounds[1] - sceneBounds[0]), 1e-6)),
      cosOuter_(std::cos(light.outerConeAngle)),
      cosInner_(std::cos(light.innerConeAngle)) {}

double PlacedPunctualLight::profile(double c) const {
  if (light_.type != PunctualLightType::kSpot) return 1.0;
  if (!(c > cosOuter_)) return 0.0;
  if (light_.profile == SpotProfile::kCycles) {
    const double blend = 1.0 - light_.innerConeAngle / light_.outerConeAngle;
    const double smooth = (1.0 - cosOuter_) * blend;
    const double t = c - cosOuter_;
    return smooth > 0.0 && t < smooth ? c * smoothstep(t / smooth) : c;
  }
  const double scale = 1.0 / std::max(0.001, cosInner_ - cosOuter_);
  const double t = std::clamp((c - cosOuter_) * scale, 0.0, 1.0);
  return t * t;
}

glm::dvec3 PlacedPunctualLight::power() const {
  switch (light_.type) {
    case PunctualLightType::kPoint:
      return 4.0 * kPi * light_.intensity;
    case PunctualLightType::kSpot: {
      // Simpson's rule over c in [cos outer, 1]; the profile is smooth between its kinks at
      // the cones, so a fine even grid is accurate to far below a sampling weight's needs.
      constexpr int kSteps = 256;
      const double h = (1.0 - cosOuter_) / kSteps;
      double sum = 0.0;
      for (int i = 0; i <= kSteps; ++i) {
        const double w = i == 0 || i == kSteps ? 1.0 : (i % 2 ? 4.0 : 2.0);
        sum += w * profile(cosOuter_ + i * h);
      }
      return 2.0 * kPi * (sum * h / 3.0) * light_.intensity;
    }
    case PunctualLightType::kDirectional:
      return light_.intensity * (kPi * 0.25 * reach_ * reach_);
  }
  return glm::dvec3(0.0);
}

double PlacedPunctualLight::samplingWeight() const {
  const glm::dvec3 p = power();
  return p.x + p.y + p.z;
}

glm::dvec3 PlacedPunctualLight::emittedRadiance(const glm::dvec3&, const glm::dvec3& w) const {
  if (directional()) return light_.intensity;
  return light_.intensity * profile(glm::dot(w, direction_));
}

glm::dvec3 PlacedPunctualLight::radianceToward(const glm::dvec3& y, const glm::dvec3& x) const {
  const glm::dvec3 d = x - y;
  const double len = glm::length(d);
  if (!(len > 0.0)) return glm::dvec3(0.0);
  return emittedRadiance(y, d / len);
}

glm::dvec3 PlacedPunctualLight::irradiance(const glm::dvec3& x, const glm::dvec3& n) const {
  if (directional()) return light_.intensity * std::max(0.0, -glm::dot(n, direction_));
  const glm::dvec3 d = x - position_;
  const double dist2 = glm::dot(d, d);
  if (!(dist2 > 0.0)) return glm::dvec3(0.0);
  const double dist = std::sqrt(dist2);
  const glm::dvec3 w = d / dist;
  const double cosX = -glm::dot(n, w);
  if (!(cosX > 0.0)) return glm::dvec3(0.0);
  double window = 1.0;
  if (light_.range > 0.0) {
    const double r = dist / light_.range;
    window = std::clamp(1.0 - r * r * r * r, 0.0, 1.0);
    window *= window;
  }
  return light_.intensity * (profile(glm::dot(w, direction_)) * window * cosX / dist2);
}

EmitterSample PlacedPunctualLight::sample(const glm::dvec2&) const {
  EmitterSample s;
  s.point = directional() ? centre_ - direction_ * reach_ : position_;
  s.pdfArea = 0.0;
  return s;
}

glm::dvec3 PlacedPunctualLight::shadowTarget(const glm::dvec3& x) const {
  return directional() ? x - direction_ * reach_ : position_;
}

PunctualLightEmitter::PunctualLightEmitter(const Scene& scene, int node,
                                           const std::array<glm::dvec3, 2>& sceneBounds)
    : scene_(scene),
      node_(node),
      light_(scene.nodes[size_t(node)].light),
      sceneBounds_(sceneBounds) {}

bool PunctualLightEmitter::moves(double t0, double t1) const {
  return scene_.isDynamic(node_, t0, t1);
}

std::array<glm::dvec3, 2> PunctualLightEmitter::bounds(double t0, double t1) const {
  if (light().type == PunctualLightType::kDirectional) return sceneBounds_;
  const double inf = std::numeric_limits<double>::infinity();
  std::array<glm::dvec3, 2> box{glm::dvec3(inf), glm::dvec3(-inf)};
  const std::vector<double> ts =
      moves(t0, t1) ? scene_.sampleTimes(node_, t0, t1, 32) : std::vector<double>{t0};
  glm::dvec3 prev(0.0);
  double pad = 0.0;
  for (std::size_t i = 0; i < ts.size(); ++i) {
    const glm::dvec3 p(scene_.worldTransform(node_, ts[i])[3]);
    box[0] = glm::min(box[0], p);
    box[1] = glm::max(box[1], p);
    if (i > 0) pad = std::max(pad, glm::length(p - prev));
    prev = p;
  }
  box[0] -= glm::dvec3(pad);
  box[1] += glm::dvec3(pad);
  return box;
}

glm::dvec3 PunctualLightEmitter::power(double t) const {
  const std::unique_ptr<PlacedEmitter> placed = at(t);
  return placed ? placed->power() : glm::dvec3(0.0);
}

std::unique_ptr<PlacedEmitter> PunctualLightEmitter::at(double t) const {
  const glm::dmat4 m = scene_.worldTransform(node_, t);
  const glm::dvec3 forward(m * glm::dvec4(0.0, 0.0, -1.0, 0.0));
  const double len = glm::length(forward);
  if (!(len > 0.0)) return nullptr;  // a zero scale: no direction
  return std::make_unique<PlacedPunctualLight>(light(), glm::dvec3(m[3]), forward / len,
                                               sceneBounds_);
}

std::string PunctualLightEmitter::toString() const {
  static const char* kTypes[] = {"point", "spot", "directional"};
  const PunctualLight& l = light();
  std::ostringstream os;
  os << kTypes[int(l.type)] << " light '" << l.name << "' (node " << node_ << ", light " << light_
     << ", " << (l.type == PunctualLightType::kDirectional ? "E " : "I ") << l.intensity.x << " "
     << l.intensity.y << " " << l.intensity.z << ")";
  return os.str();
}

}  // namespace rad
