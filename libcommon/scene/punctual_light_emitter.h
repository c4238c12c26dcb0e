// Punctual lights (KHR_lights_punctual: point, spot, directional) as Emitters (emitter.h): delta
// lights with no area, placed by their node (docs/design.md §4 "Lights"). They are no patch and
// make no links; the stages add their direct irradiance with a shadow test of their own
// (shadowTarget).
#pragma once

#include <array>

#include "libcommon/scene/emitter.h"
#include "libcommon/scene/scene.h"

namespace rad {

// The world-space bounds {min, max} of every mesh node over the whole animation
// (Scene::sweptBounds over [startTime, endTime]); a zero box at the origin for an empty scene.
// What bounds a sun's parallel shadow rays and its power.
std::array<glm::dvec3, 2> animationBounds(const Scene& scene);

// A punctual light placed at one time.
class PlacedPunctualLight final : public PlacedEmitter {
 public:
  // `position`: the node's world origin; `direction`: the unit world direction the light
  // shines in (the node's -Z); `sceneBounds`: animationBounds, for a sun's reach and power.
  PlacedPunctualLight(const PunctualLight& light, const glm::dvec3& position,
                      const glm::dvec3& direction, const std::array<glm::dvec3, 2>& sceneBounds);

  // Point: $4 \pi I$; spot: $2 \pi I \int_{\cos outer}^1 f(c)\,dc$ (f the profile, Simpson's
  // rule); sun: E times the area of the disc around the scene's bounds.
  glm::dvec3 power() const override;
  double samplingWeight() const override;
  double area() const override { return 0.0; }
  // Radiant intensity W/sr toward unit direction `w` (point, spot); a sun's E for any w.
  glm::dvec3 emittedRadiance(const glm::dvec3& y, const glm::dvec3& w) const override;
  glm::dvec3 radianceToward(const glm::dvec3& y, const glm::dvec3& x) const override;
  // Point, spot: $I(w) \cos\theta / d^2$ times the range window
  // $\mathrm{clamp}(1 - (d / range)^4, 0, 1)^2$ (the extension's recommendation); sun:
  // $E \max(0, \cos\theta)$.
  glm::dvec3 irradiance(const glm::dvec3& x, const glm::dvec3& n) const override;
  // The position (a sun: the scene's centre moved against its direction), pdfArea 0.
  EmitterSample sample(const glm::dvec2& u) const override;
  glm::dvec3 shadowTarget(const glm::dvec3& x) const override;

  // The spot profile at cosine `c` from the axis (1 for point and sun): scene.h SpotProfile.
  double profile(double c) const;
  const PunctualLight& light() const { return light_; }
  const glm::dvec3& position() const { return position_; }
  const glm::dvec3& direction() const { return direction_; }
  bool directional() const { return light_.type == PunctualLightType::kDirectional; }

 private:
  PunctualLight light_;
  glm::dvec3 position_{0.0};
  glm::dvec3 direction_{0.0, 0.0, -1.0};
  glm::dvec3 centre_{0.0};  // of the scene's bounds
  double reach_ = 1.0;      // the bounds' diagonal, at least 1e-6 m
  double cosOuter_ = 0.0, cosInner_ = 1.0;
};

class PunctualLightEmitter final : public Emitter {
 public:
  // `node` carries a light of `scene` (Node::light); `scene` must outlive the emitter.
  PunctualLightEmitter(const Scene& scene, int node, const std::array<glm::dvec3, 2>& sceneBounds);

  int node() const override { return node_; }
  int top() const override { return -1; }
  bool moves(double t0, double t1) const override;
  // A point or spot: its position at the node's sample times, padded by the largest step (as
  // EmissivePolygonEmitter::bounds); a sun: the scene's bounds (its shadows reach everywhere).
  std::array<glm::dvec3, 2> bounds(double t0, double t1) const override;
  glm::dvec3 power(double t) const override;
  std::unique_ptr<PlacedEmitter> at(double t) const override;
  std::string toString() const override;

  const PunctualLight& light() const { return scene_.lights[size_t(light_)]; }

 private:
  const Scene& scene_;
  int node_ = -1;
  int light_ = -1;
  std::array<glm::dvec3, 2> sceneBounds_{};
};

}  // namespace rad
