// Transmittance textures by projective shadows (Martín, Pueyo, Tost, "Frame-to-frame coherent
// animation with two-pass radiosity", §3.1 "Transmittance Texture Computation" and §5; the
// projective texture transform after Segal, Korobkin, van Widenfelt, Foran, Haeberli 1992,
// "Fast shadows and lighting effects using texture mapping", and Herf & Heckbert 1997,
// "Simulating soft shadows with graphics hardware"; stratified sample points by correlated
// multi-jittered sampling, Kensler 2013, "Correlated Multi-Jittered Sampling").
//
// For N sample points s on a shooter polygon, the blockers are rendered with eye at s and the
// receiver's plane as the image plane, the image plane mapped onto the receiver's texture
// (u,v) square. A texel is covered by a blocker exactly when the segment from s to the texel
// centre's point on the receiver plane crosses the blocker between s and the plane. Instead of
// counting covered samples (the paper increments a counter) each sample writes its own bit
// into an integer render target with glLogicOp(GL_OR): one 64-bit mask per texel. Occlusion
// masks of disjoint blocker sets then merge exactly by OR (docs/design.md §6.3 "rad-movies"), so
// the coherent result (static blockers once per movie, dynamic ones per key) equals rendering all
// blockers at every key bit for bit.
//
// Texture map of the receiver: texel (i, j) has its centre at (u,v) = ((i+.5)/w, (j+.5)/h) and
// the (u,v) map of patch_hierarchy.h (triangles: affine; quads: bilinear). The render maps
// the plane to (u,v) by a plane homography fixed by the polygon's corners (Heckbert 1989,
// "Fundamentals of texture mapping", square-to-quad): exact for triangles and parallelograms;
// for a quad whose bilinear map is not affine the homography and the bilinear map agree at the
// corners and edges' ends only, and the shadow is taken at the homography's point for that
// (u,v) (a displacement of second order in the quad's departure from a parallelogram).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/movies/occlusion_mask_renderer.h"
#include "libcommon/scene/geometry.h"

namespace rad {

// Number of shooter samples for a bad link (paper §3.1: "proportional to the maximum form
// factor between the shooter and the texels"): ceil(samplesPerFormFactor * maxFormFactor)
// clamped to [minSamples, maxSamples], then rounded to the square m*m of a stratified grid
// (m = ceil(sqrt(n)), lowered while m*m > maxSamples). maxSamples <= 64.
int transmittanceSampleCount(double maxFormFactor, double samplesPerFormFactor, int minSamples,
                             int maxSamples);

// n = m*m correlated multi-jittered points in [0,1)^2 (one per cell of an m x m grid and one
// per column of an n x 1 and a 1 x n grid, so an edge parallel to either axis is resolved to
// 1/n). Deterministic in (n, seed).
std::vector<glm::dvec2> multiJitteredPoints(int n, uint32_t seed);

// Maps unit-square points onto a polygon's (u,v) domain and then into the polygon: quads by
// their bilinear map, triangles by the area-preserving square-to-triangle warp
// (u, v) -> (1 - sqrt(a), b sqrt(a)).
glm::dvec3 samplePointOnPolygon(const Polygon& p, glm::dvec2 unitSquare);

// Bit s set when samples[s] lies strictly in front of the receiver's plane (only those can
// light it; a texel's transmittance counts only these).
SampleMask frontSampleMask(const Polygon& receiver, const std::vector<glm::dvec3>& samples);

// Visible fraction of the valid samples: popcount(valid & ~occluded) / popcount(valid); 1 when
// no sample is valid.
double transmittanceFromMask(SampleMask occluded, SampleMask valid);

// The transmittance as the texel receives it: each valid sample s weighted by the kernel
// cos(theta_x) cos(theta_s) / r^2 of the point-to-area form factor (the texel at x, normal n;
// the shooter's normal taken either way, as a planar shooter lies wholly on one side of x):
//   T(x) = sum_{s open} K(x, s) / sum_s K(x, s),
// the quadrature of F(x -> S, visible) / F(x -> S) by the samples, where the popcount fraction
// weights every part of the shooter alike. A large light near a receiver varies K over itself
// (a lamp seen from the foot of a side wall), and there a penumbra weighted alike is wrong.
// Fully open or fully occluded: exactly 1 or 0 whatever the weights;
// no weight at any valid sample: the popcount fraction.
double kernelWeightedTransmittance(const glm::dvec3& x, const glm::dvec3& n,
                                   const std::vector<glm::dvec3>& samples,
                                   const glm::dvec3& shooterNormal, SampleMask occluded,
                                   SampleMask valid);

// The same quadrature for a shooter whose radiosity is not uniform (a subdivided patch that does
// not emit, a bad pair of --bad-links partial): each sample s also weighted by the shape
// beta_s = B(y_s) / B_S, the radiosity of the leaf under it over the shooter's mean,
//   T_B(x) = sum_{s open} K(x, s) beta_s / sum_s K(x, s),
// so that B_S F(x -> S) T_B(x) estimates the irradiance $\int_S B(y) V K dy$ of the shooter's
// leaves, not of its mean (a wall's mean radiosity puts too little light on a ceiling whose near
// parts see the wall's brighter upper half). Not 1 where every sample
// is open: the kernel still weights the shooter's parts.
// Per channel (beta_s for R, G, B).
glm::dvec3 shapedTransmittance(const glm::dvec3& x, const glm::dvec3& n,
                               const std::vector<glm::dvec3>& samples,
                               const glm::dvec3& shooterNormal, SampleMask occluded,
                               SampleMask valid, const std::vector<glm::vec3>& shape);

// Approximate merge operators for transmittances of two disjoint blocker sets (paper §5,
// Figure 7): occlusions a = 1 - Ts and b = 1 - Td merge to max(a, b) (blockers overlap),
// min(1, a + b) (disjoint) or 1 - (1 - a)(1 - b) (independent). kExact ORs the sample masks.
enum class MergeMode { kExact, kMax, kSum, kIndependent };
const char* mergeModeName(MergeMode m);  // parsing: mergeModeNames() (movies_options.h)
double mergeTransmittance(MergeMode mode, double staticT, double dynamicT);

// The 4x4 clip-from-world transform of one sample (before the origin shift): a point y maps to
// clip (2U - C, 2V - C, 0, C) where (U/C, V/C) is the receiver-texture (u,v) of the point
// where the ray from `sample` through y meets the receiver's plane. Exposed for tests.
glm::dmat4 projectiveShadowMatrix(const Polygon& receiver, const glm::dvec3& sample);
// (u,v) of a point of the receiver's plane under the render's homography.
glm::dvec2 receiverPlaneUv(const Polygon& receiver, const glm::dvec3& pointOnPlane);
// How far in front of the receiver's plane a blocker must be to cast (1e-6 of the receiver's
// radius about its centroid), in both mask methods: touching geometry such as the receiver's
// coplanar neighbours does not shadow it.
double receiverFrontOffset(const Polygon& receiver);

// The render's map between the receiver's plane and its texture (u,v) (the homography above),
// both ways: what receiverPlaneUv computes, made once per receiver.
class ReceiverTextureMap {
 public:
  explicit ReceiverTextureMap(const Polygon& receiver);
  // Homogeneous (U, V, C) of a point of the receiver's plane; C > 0 inside the polygon.
  glm::dvec3 uvHomogeneous(const glm::dvec3& pointOnPlane) const;
  // The point of the plane that maps to uv.
  glm::dvec3 planePoint(glm::dvec2 uv) const;

 private:
  glm::dvec3 origin_, e1_, e2_;
  glm::dmat3 uvFromPlane_, planeFromUv_;
};

// OSMesa renderer of occlusion masks (projective shadows, see above): the baker's default
// OcclusionMaskRenderer. Owns its GL context (gl_context.h threading rules: one renderer per
// thread).
class TransmittanceRenderer final : public OcclusionMaskRenderer {
 public:
  // Throws rad::Error(kEnvironment) when no GL context can be made.
  TransmittanceRenderer();
  ~TransmittanceRenderer() override;
  TransmittanceRenderer(const TransmittanceRenderer&) = delete;
  TransmittanceRenderer& operator=(const TransmittanceRenderer&) = delete;

  // OcclusionMaskRenderer::render; an empty blocker list (or no sample in front of the
  // receiver) gives all-zero masks without rendering.
  void render(const Polygon& receiver, int width, int height,
              const std::vector<glm::dvec3>& samples, const std::vector<BlockerTriangle>& blockers,
              std::vector<SampleMask>& out) override;

  // Render passes so far (one per render() call that drew) and sample-passes (passes x
  // samples): the cost figures of the report.
  long passes() const override;
  long samplePasses() const override;
  long trianglesDrawn() const;                // blocker triangles x samples
  std::string rendererName() const override;  // GL_RENDERER

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rad
