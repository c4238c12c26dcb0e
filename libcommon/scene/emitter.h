// The light seam (docs/design.md §4 "Lights"): what a light emits toward a point, how to sample
// it, where it is over time, whether it moves, and its power. The stages ask "which things
// emit, where, how much" of the scene's list of Emitters, made in one place (scene_emitters.h);
// what still reads a material's emission directly is a patch's own B_e (below).
//
// Two levels:
//  * Emitter: a light of the scene over time (its node's animation included). Holds a reference
//    to its Scene, which must outlive it.
//  * PlacedEmitter: one light placed in the world at one time (Emitter::at): the per-point
//    queries of a gather or a path tracer, with no animation to evaluate per query.
//
// Emissive polygons are the first implementation (emissive_polygon_emitter.h): one emitter per
// emitting top-level patch (a doubleSided emitter's reversed copy is its own emitter, the back
// side). A polygon light IS a patch: rad-global's hierarchy and links treat it as a patch with
// B_e = pi L_e, and nothing here replaces that.
//
// How a lamp that is not a polygon plugs in (point, spot, sun: KHR_lights_punctual, issue 57):
//  * a new Emitter subclass beside emissive_polygon_emitter.h, made by makeSceneEmitters from
//    the scene's lights, with top() == -1 and a PlacedEmitter whose area() is 0 (a delta light:
//    no ray can hit it; sample() gives its position, or for a sun a point far along -direction,
//    with pdfArea 0 meaning "the only point");
//  * it has no patch and makes no links: the radiosity solve gets its light as a direct
//    irradiance term per receiver, E = irradiance(x, n) times a visibility of its own (a
//    first-pass E added to B = B_e + rho (E + H)), and rad-movies adds a per-texel direct term
//    with its own shadow test (shadow map or rays from sample().point);
//  * rad-reference adds it to next-event estimation without MIS (a continuation ray cannot find
//    a delta light): for area() == 0, emittedRadiance(y, w) is the radiant intensity W/sr
//    toward w, and the estimate is I cos / d^2 over the light's choice probability.
#pragma once

#include <array>
#include <memory>
#include <string>

#include <glm/glm.hpp>

namespace rad {

// A point on a placed light, drawn by PlacedEmitter::sample.
struct EmitterSample {
  glm::dvec3 point{0.0};   // world, metres
  glm::dvec3 normal{0.0};  // the light's unit front normal at `point` (zero: a point light)
  // Density of `point` per unit area of the light (a polygon: 1 / area, uniform); 0 for a
  // delta light, whose one point is certain.
  double pdfArea = 0.0;
};

// One light placed in the world at one time. Queries are const and thread-safe.
class PlacedEmitter {
 public:
  virtual ~PlacedEmitter() = default;
  // Emitted power per channel, watts (a Lambertian polygon: pi L_e A).
  virtual glm::dvec3 power() const = 0;
  // The weight with which next-event estimation chooses this light among others: proportional to
  // the power summed over the channels (a polygon: A (L_r + L_g + L_b), i.e. that sum / pi).
  virtual double samplingWeight() const = 0;
  // Area of the emitting surface, m^2; 0 for a delta light (point, spot, sun).
  virtual double area() const = 0;
  // Exitant radiance W/(m^2 sr) leaving `y` (a point on the light) in unit direction `w`, where
  // the caller has already found `w` on the light's emitting side (a ray hit its front, or the
  // cosine at the light is positive). Constant for a Lambertian polygon.
  virtual glm::dvec3 emittedRadiance(const glm::dvec3& y, const glm::dvec3& w) const = 0;
  // The same toward a receiver point `x`, tested: zero when x is on or behind the emitting
  // side (a polygon light is one-sided by winding).
  virtual glm::dvec3 radianceToward(const glm::dvec3& y, const glm::dvec3& x) const = 0;
  // Irradiance W/m^2 at `x` on a surface with unit normal `n` from the whole light, with no
  // occluder: for a polygon $E = L_e \pi F(dA_x \to P)$ (Lambert's contour formula, the light
  // clipped to the receiver's front half-space), for a point light $I \cos\theta / d^2$.
  virtual glm::dvec3 irradiance(const glm::dvec3& x, const glm::dvec3& n) const = 0;
  // A point on the light from two numbers in [0, 1); deterministic in `u`.
  virtual EmitterSample sample(const glm::dvec2& u) const = 0;
  // A delta light's (area() == 0) shadow test from receiver `x`: the segment from x to this
  // point must be clear for x to be lit. The lamp's position for a point or spot; for a sun, x
  // moved against the light's direction past the scene's bounds (parallel shadows). Unused for
  // a light with area (its default is sample's point at the centre of [0, 1)^2).
  virtual glm::dvec3 shadowTarget(const glm::dvec3& x) const {
    (void)x;
    return sample(glm::dvec2(0.5)).point;
  }
};

// A light of the scene over time.
class Emitter {
 public:
  virtual ~Emitter() = default;
  // The scene node whose world transform places the light (-1: fixed in the world).
  virtual int node() const = 0;
  // The top-level patch it is (index into Scene::inputPolygons()), or -1 for a light that is
  // not a patch.
  virtual int top() const = 0;
  // Whether the light's placement changes somewhere in [t0, t1].
  virtual bool moves(double t0, double t1) const = 0;
  // World-space axis-aligned bounds of the light swept over [t0, t1]: {min, max}, conservative.
  virtual std::array<glm::dvec3, 2> bounds(double t0, double t1) const = 0;
  // Emitted power per channel at time t, watts.
  virtual glm::dvec3 power(double t) const = 0;
  // The light placed at time t; null when it degenerates there (a zero scale).
  virtual std::unique_ptr<PlacedEmitter> at(double t) const = 0;
  virtual std::string toString() const = 0;
};

}  // namespace rad
