// Emissive polygons, the first Emitter (emitter.h): a top-level patch whose material has an
// exitant radiance L_e > 0, one-sided by winding, Lambertian (constant radiance over its front
// half-space). A doubleSided emitter's reversed copy is a second emitter, its back side.
#pragma once

#include "libcommon/scene/emitter.h"
#include "libcommon/scene/geometry.h"
#include "libcommon/scene/scene.h"

namespace rad {

// The polygon placed at one time: its world polygon, front normal and area as computed from
// `world` (Polygon::normal, Polygon::area), so every consumer sees the same bits.
class PlacedEmissivePolygon final : public PlacedEmitter {
 public:
  // `world` must not be degenerate (non-zero normal); `radiance` is L_e per channel, >= 0.
  PlacedEmissivePolygon(const Polygon& world, const glm::dvec3& radiance);

  glm::dvec3 power() const override;
  double samplingWeight() const override;
  double area() const override { return area_; }
  glm::dvec3 emittedRadiance(const glm::dvec3& y, const glm::dvec3& w) const override;
  glm::dvec3 radianceToward(const glm::dvec3& y, const glm::dvec3& x) const override;
  glm::dvec3 irradiance(const glm::dvec3& x, const glm::dvec3& n) const override;
  // Area-uniform (pointOnPolygon), pdfArea = 1 / area.
  EmitterSample sample(const glm::dvec2& u) const override;

  const Polygon& world() const { return world_; }
  const glm::dvec3& normal() const { return normal_; }
  const glm::dvec3& radiance() const { return radiance_; }

 private:
  Polygon world_;
  glm::dvec3 normal_{0.0};
  glm::dvec3 radiance_{0.0};
  double area_ = 0.0;
};

class EmissivePolygonEmitter final : public Emitter {
 public:
  // `polygon` is Scene::inputPolygons()[topIndex]; `scene` must outlive the emitter.
  EmissivePolygonEmitter(const Scene& scene, const InputPolygon& polygon, int topIndex,
                         const glm::dvec3& radiance);

  int node() const override { return polygon_.node; }
  int top() const override { return top_; }
  bool moves(double t0, double t1) const override;
  // The polygon's own vertices at the node's sample times (Scene::sampleTimes), padded as
  // Scene::sweptBounds pads its node's box; exact for a static light.
  std::array<glm::dvec3, 2> bounds(double t0, double t1) const override;
  glm::dvec3 power(double t) const override;
  std::unique_ptr<PlacedEmitter> at(double t) const override;
  std::string toString() const override;

  const InputPolygon& polygon() const { return polygon_; }
  const glm::dvec3& radiance() const { return radiance_; }
  // The polygon in the world at time t (its node's world transform applied to it).
  Polygon worldAt(double t) const;

 private:
  const Scene& scene_;
  InputPolygon polygon_;
  int top_ = -1;
  glm::dvec3 radiance_{0.0};
};

}  // namespace rad
