// Reference renderer: an independent Monte Carlo path tracer for the same scenes (issue 7), used
// to measure the radiosity pipeline's error (docs/design.md §8 "error vs converged reference").
//
// It shares only the scene model (Scene: worldTransform, inputPolygons, materials) and the
// camera (camera_projection.h primaryRay) with the pipeline; ray casting is its own Embree 3
// scene (one world-space triangle BVH rebuilt per frame time), not VisibilityScene.
//
// Light transport (Kajiya 1986, "The rendering equation"; Pharr, Jakob, Humphreys, PBRT 3rd
// ed. §14.5): every surface is Lambertian with reflectance rho (BRDF rho / pi) — where the
// material has a baseColorTexture, rho = baseColorFactor x the texel under the hit (bilinear,
// REPEAT), not the texture's mean the radiosity pass uses; emitters have constant exitant
// radiance L_e. Conventions are those of form_factor.h: polygons are one-sided
// (CCW about the front normal), the back of a single-sided polygon is black and absorbing, an
// emitter emits from its front only; a doubleSided material reflects and emits on both sides
// (Scene::inputPolygons adds its reversed copy).
//
// Estimator (Veach & Guibas 1995, multiple importance sampling): at every path vertex one
// emitter point by next-event estimation (emitter chosen in proportion to area x sum(L_e),
// area-uniform on it) and one cosine-distributed continuation (throughput x= rho); emission
// reached by the continuation counts too, the two combined with the power heuristic. This
// keeps the variance bounded where NEE alone has a 1/r^2 tail (points near an emitter's edge,
// enclosure corners). Emission seen directly counts in full. Unbiased up to --max-depth
// reflections; Russian roulette from the third reflection on with survival probability
// min(0.95, max rho).
//
// Randomness is counter-based (splitMix64 / uniformOpen01): sample s of pixel (x, y) depends
// only on (seed, pixel, s) — and the frame number only with decorrelateFrames — so images are
// bit-identical whatever the thread count, and by default a part of the image whose paths see
// nothing that moves is bit-identical from frame to frame (no reference flicker, which keeps
// rad-diff's static-pixel mask meaningful).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/core/float_image.h"
#include "libcommon/scene/camera_projection.h"
#include "libcommon/scene/pixel_filter.h"
#include "libcommon/scene/scene.h"

namespace rad {

struct PathTracerOptions {
  int samplesPerPixel = 64;
  // Maximum number of reflections along a path (0: emitters only, 1: direct lighting).
  int maxDepth = 64;
  // Russian roulette starts after this many reflections.
  int rouletteDepth = 3;
  std::uint64_t seed = 0;
  // Mix the frame number into every pixel's seed (independent noise per frame).
  bool decorrelateFrames = false;
  // The pixel filter (pixel_filter.h), as Cycles samples it: each sample's offset from the pixel
  // centre drawn from the filter per axis (the sample's stratum mapped through the filter's
  // inverse distribution), every sample weighted 1. Filter none: every sample through the
  // centre (point sampling, as rad-compose --pixel-filter none).
  PixelFilter filter;
};

// Mean and spread of a Monte Carlo estimate.
struct RadianceEstimate {
  glm::dvec3 mean{0.0};
  glm::dvec3 standardError{0.0};  // sample standard deviation / sqrt(samples)
  long long samples = 0;
};

class PathTracer {
 public:
  // Takes the scene's world-space geometry at time t. Throws rad::Error(kEnvironment) if
  // Embree fails. The scene must outlive the tracer.
  PathTracer(const Scene& scene, double t);
  ~PathTracer();
  PathTracer(const PathTracer&) = delete;
  PathTracer& operator=(const PathTracer&) = delete;

  // Moves every node to time t (rebuilds the BVH). Not thread-safe with queries.
  void setTime(double t);
  double time() const { return time_; }

  // One path sample of the radiance arriving along the ray (towards its origin) from
  // [tNear, tFar]. `seed` fixes every random decision.
  glm::dvec3 radianceSample(const Ray& ray, std::uint64_t seed,
                            const PathTracerOptions& options) const;
  // n independent samples of the same ray (seeds derived from `seed`), with their spread.
  RadianceEstimate estimateRadiance(const Ray& ray, long long n, std::uint64_t seed,
                                    const PathTracerOptions& options) const;

  // Renders the view: RGB linear radiance, row 0 at the top, samplesPerPixel stratified
  // samples per pixel. Parallel over rows (TBB); deterministic. `frame` only matters with
  // options.decorrelateFrames.
  FloatImage render(const CameraView& view, ImageSize size, const PathTracerOptions& options,
                    int frame = 0) const;

  int polygonCount() const;
  int emitterCount() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  const Scene& scene_;
  double time_ = 0.0;
};

}  // namespace rad
