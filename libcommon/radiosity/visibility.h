// Shadow-ray visibility between patches with Embree 3 (Wald et al. 2014, "Embree: a kernel
// framework for efficient CPU ray tracing"); stratified pair estimator as in Hanrahan,
// Salzman, Aupperle 1991 (visibility of a link from k jittered ray pairs).
//
// Scene layout: all static triangles (world space) live in one child scene whose BVH is built
// once (high quality) and instanced with the identity transform; each dynamic object is
// its own child scene (built once, in its local frame) instanced with a transform that the
// caller sets per key time. Only the small top-level BVH over the instances is rebuilt by
// commit(). Embree works in single precision: blockers closer than ~1e-6 of the scene's
// coordinate magnitude to a ray end are below its resolution.
//
// End polygons are never blockers. Two mechanisms, both always on:
//  * every triangle carries a caller-defined `surface` id (e.g. the top-level patch it belongs
//    to); a query may name the surfaces of its two end polygons, and hits on triangles with
//    those ids are ignored (an Embree occlusion filter). This is the robust way: it also
//    ignores the sub-patch's parent surface and is immune to float self-intersection;
//  * each ray is the open segment between its two sample points, shortened at both ends by
//    kSegmentEpsilon of its length (tnear / tfar), so surfaces touching an end polygon along
//    an edge (a wall meeting the floor) do not block rays that start next to that edge.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/scene/geometry.h"

struct RTCRay;  // embree3/rtcore_ray.h

namespace rad {

struct VisibilityTriangle {
  glm::dvec3 v[3];
  std::uint32_t surface = 0;  // caller's patch id; queries name the ids of their end patches
};

struct VisibilityQuery {
  Polygon a, b;
  std::uint64_t seed = 0;  // derive from the link (e.g. hash of both patch ids, key time)
  std::uint32_t ignoreA = 0xffffffffu;  // surface id of a (kNoSurface: none)
  std::uint32_t ignoreB = 0xffffffffu;  // surface id of b
};

class VisibilityScene {
 public:
  static constexpr std::uint32_t kNoSurface = 0xffffffffu;
  // Relative shortening of every shadow segment at both ends.
  static constexpr double kSegmentEpsilon = 1e-4;

  // Creates the Embree device and the static BVH (built here, once). Throws
  // rad::Error(ExitCode::kEnvironment) if Embree fails.
  explicit VisibilityScene(const std::vector<VisibilityTriangle>& staticTriangles);
  ~VisibilityScene();
  VisibilityScene(const VisibilityScene&) = delete;
  VisibilityScene& operator=(const VisibilityScene&) = delete;
  VisibilityScene(VisibilityScene&&) noexcept;
  VisibilityScene& operator=(VisibilityScene&&) noexcept;

  // Adds a dynamic object (triangles in its local frame, placed by an affine transform); returns
  // its instance id (0, 1, ...). Its BVH is built here, once. Call commit() before the next query.
  int addInstance(const std::vector<VisibilityTriangle>& localTriangles,
                  const glm::dmat4& objectToWorld = glm::dmat4(1.0));
  // Sets an instance's local-to-world transform (affine). Call commit() before the next query.
  void setInstanceTransform(int id, const glm::dmat4& objectToWorld);
  // Rebuilds the top-level BVH over the instances. Not thread-safe with queries.
  void commit();

  // True if the open segment from -> to (shortened by kSegmentEpsilon at both ends) hits a
  // triangle whose surface is neither ignoreA nor ignoreB.
  bool occluded(const glm::dvec3& from, const glm::dvec3& to, std::uint32_t ignoreA = kNoSurface,
                std::uint32_t ignoreB = kNoSurface) const;

  // Fraction in [0, 1] of k ray pairs that are unoccluded. Sample points: stratified on a and
  // on b (jittered m x m grid if k = m^2, otherwise Latin hypercube with k strata per axis),
  // area-uniform on each polygon, the b strata randomly permuted against the a strata. All
  // randomness is counter-based from `seed` (splitmix64), so the result depends only on the
  // arguments and the scene: not on threads or call order. Thread-safe after commit().
  // Estimator: E = V (unbiased); the standard deviation is at most 1/(2 sqrt(k)).
  double visibility(const Polygon& a, const Polygon& b, int k, std::uint64_t seed,
                    std::uint32_t ignoreA = kNoSurface, std::uint32_t ignoreB = kNoSurface) const;
  // Visibility of a link from a's k sample points (samplePoints(a, k, seedA), so that every
  // link of a receiver shoots from the same points, the ones its exposure is measured at) to
  // k stratified points on b: the kernel-weighted fraction of unoccluded pairs,
  //   $V = \sum_i K_i v_i / \sum_i K_i$, $K_i = \cos\theta_a \cos\theta_b / r^2$ (0 behind),
  // the ratio estimator of F_occluded / F_unoccluded (Cohen & Wallace ch. 4). An area-uniform
  // count lets pairs that exchange no energy (behind either plane) decide the link's
  // visibility. When no sample pair has K > 0, the area-uniform fraction.
  // `openPairs`, when given, receives bit i set for each unoccluded pair i < kMaxRecordedPairs.
  // The pairs i < kMaxRecordedPairs whose bit is set in `blockedPairs` count as occluded and cast
  // no ray (a's covered points: rad-global's exposure).
  double visibilityFrom(const std::vector<glm::dvec3>& aPoints, const glm::dvec3& aNormal,
                        const Polygon& b, std::uint64_t seed, std::uint32_t ignoreA = kNoSurface,
                        std::uint32_t ignoreB = kNoSurface, std::uint64_t* openPairs = nullptr,
                        std::uint64_t blockedPairs = 0) const;
  // visibilityFrom with each pair's kernel also weighted by weightAtB(its point on b):
  //   $V_w = \sum_i K_i w(y_i) v_i / \sum_i K_i w(y_i)$.
  // With w = the shooter's radiosity this is the share of the power leaving b towards a that
  // arrives (a shooter bright where it is hidden, the ceiling above a lamp, is not averaged
  // with its visible part). The pairs are visibilityFrom's; `knownOpenPairs` (its openPairs of
  // the same arguments) spares the rays when k <= kMaxRecordedPairs. A null weightAtB: w = 1.
  // kernelMeanWeight, when given, receives $\sum_i K_i w(y_i) / \sum_i K_i$ over all pairs, open
  // or not (the shooter's radiosity as the receiver sees it; -1 when no pair carries energy).
  // `blockedPairs` as visibilityFrom's.
  double weightedVisibilityFrom(const std::vector<glm::dvec3>& aPoints, const glm::dvec3& aNormal,
                                const Polygon& b, std::uint64_t seed, std::uint32_t ignoreA,
                                std::uint32_t ignoreB, const std::uint64_t* knownOpenPairs,
                                const std::function<double(const glm::dvec3&)>& weightAtB,
                                std::uint64_t* openPairs = nullptr,
                                double* kernelMeanWeight = nullptr,
                                std::uint64_t blockedPairs = 0) const;
  static constexpr int kMaxRecordedPairs = 64;
  // The pairs weightedVisibilityFrom makes from the same arguments: b's points (bPoints[i]
  // paired with aPoints[i]) and each pair's kernel K_i. For a caller that weights the same
  // pairs again with other weights (rad-global at each refinement round, whose geometry, rays
  // and pairs stay while the shooter's B changes).
  static void pairsFrom(const std::vector<glm::dvec3>& aPoints, const glm::dvec3& aNormal,
                        const Polygon& b, std::uint64_t seed, std::vector<glm::dvec3>& bPoints,
                        std::vector<double>& kernel);
  // weightedVisibilityFrom's value from its pairs' kernels, their open bits `known` (k <=
  // kMaxRecordedPairs) and weights w(y_i): the same arithmetic in the same order, so the same
  // bits.
  static double weightedVisibilityOfPairs(int k, const double* kernel, std::uint64_t known,
                                          const double* weightAtB, std::uint64_t* openPairs,
                                          double* kernelMeanWeight);
  // Which of the segments from x to bPoints[i] (i < kMaxRecordedPairs) are unoccluded: bit i,
  // tested only where `candidates` has it (the others stay 0). Thread-safe after commit().
  std::uint64_t openFrom(const glm::dvec3& x, const std::vector<glm::dvec3>& bPoints,
                         std::uint32_t ignoreA = kNoSurface, std::uint32_t ignoreB = kNoSurface,
                         std::uint64_t candidates = ~std::uint64_t(0)) const;
  // The same for the k (at most kMaxRecordedPairs) segments from from[i * fromStep] to to[i]
  // (fromStep 0: one shared origin), each as occluded() tests it. Thread-safe after commit().
  std::uint64_t openSegments(const glm::dvec3* from, size_t fromStep, const glm::dvec3* to, int k,
                             std::uint32_t ignoreA, std::uint32_t ignoreB,
                             std::uint64_t candidates = ~std::uint64_t(0)) const;
  // k stratified, area-uniform points on p (the strata of visibility()), from `seed`.
  static std::vector<glm::dvec3> samplePoints(const Polygon& p, int k, std::uint64_t seed);
  // samplePoints over the part of p in front of the plane through `at` with normal n (the same
  // points as samplePoints where no vertex of p is behind it, or where nothing of p is in
  // front): a receiver's rays to the part of a shooter behind its plane carry nothing.
  static std::vector<glm::dvec3> samplePointsInFront(const Polygon& p, const glm::dvec3& at,
                                                     const glm::dvec3& n, int k,
                                                     std::uint64_t seed);
  // The surface id of the first triangle that the ray origin + t direction, t in
  // [kSegmentEpsilon, inf), hits, ignoring the triangles of surface `ignore`; kNoSurface when
  // it hits nothing. Thread-safe after commit().
  std::uint32_t firstHit(const glm::dvec3& origin, const glm::dvec3& direction,
                         std::uint32_t ignore = kNoSurface) const;
  // firstHit with where it hits (t in units of |direction|), a second surface to ignore, and
  // the ray's extent t in [tnear, tfar].
  struct Hit {
    std::uint32_t surface = kNoSurface;
    double t = 0.0;
  };
  Hit nearestHit(const glm::dvec3& origin, const glm::dvec3& direction,
                 std::uint32_t ignoreA = kNoSurface, std::uint32_t ignoreB = kNoSurface,
                 double tnear = kSegmentEpsilon,
                 double tfar = std::numeric_limits<double>::infinity()) const;
  // firstHit against the static geometry alone, without the dynamic objects: the same at every
  // time (rad-global's closed-room test, which moving objects inside a room cannot open).
  std::uint32_t firstStaticHit(const glm::dvec3& origin, const glm::dvec3& direction,
                               std::uint32_t ignore = kNoSurface) const;

  // Many queries in parallel (TBB); results in input order, identical to calling visibility()
  // on each query in turn.
  std::vector<double> visibilityBatch(const std::vector<VisibilityQuery>& queries, int k) const;

  int instanceCount() const;

 private:
  bool segmentMayHit(const glm::dvec3& a, const glm::dvec3& b) const;
  // The segment from a to b as the occlusion ray occluded() traces; false when it cannot hit
  // anything (outside the scene's bounds, or no direction in single precision).
  bool segmentRay(const glm::dvec3& a, const glm::dvec3& b, RTCRay& ray) const;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Where the ray origin + t direction from a point of surface `ignore` starts: outside (its
// first surface is a front, or none), inside a solid (the back of a one-sided patch,
// `isBack(surface)`), or undecided: a front and such a back at the same distance (1e-5
// relative), where Embree returns either. That is a partition's top flush with the ceiling (a
// floor point under the partition is inside it; the cubic scene's walls, issue 15), but also a
// thin sheet made of two back-to-back patches (the table scene's car fins), which a point
// outside meets: the caller decides from its other rays.
enum class RayStart { kOutside, kInside, kUndecided };
RayStart rayStart(const VisibilityScene& v, const glm::dvec3& origin, const glm::dvec3& direction,
                  std::uint32_t ignore, const std::function<bool(std::uint32_t)>& isBack);

// The visibility of b's points bPoints from the point x (normal n) through the unoccluded ones
// (openFrom's bits), each weighted by the kernel cos cos / r^2 (0 behind either plane) and by
// weight[i] (a shooter's radiosity at its point; null: 1):
//   $V = \sum_i K_i w_i o_i / \sum_i K_i w_i$,
// the unweighted share of open bits when no point carries energy. No rays: pure arithmetic.
double pointVisibility(const glm::dvec3& x, const glm::dvec3& n,
                       const std::vector<glm::dvec3>& bPoints, const glm::dvec3& bNormal,
                       std::uint64_t open, const double* weight = nullptr);
// The open bits of all of k rays (k <= kMaxRecordedPairs).
std::uint64_t allRaysOpen(int k);
// pointVisibility's kernels K_i of x's first k points (k <= kMaxRecordedPairs) into `kernel`,
// and the same V from them: a texel's kernels do not change from key to key, only the weights.
void pointKernels(const glm::dvec3& x, const glm::dvec3& n, const std::vector<glm::dvec3>& bPoints,
                  const glm::dvec3& bNormal, int k, double* kernel);
double pointVisibilityOfKernels(const double* kernel, int k, std::uint64_t open,
                                const double* weight = nullptr);

// Counter-based random numbers (Steele, Lea, Flood 2014, splitmix64 finaliser).
std::uint64_t splitMix64(std::uint64_t x);
// Uniform double in the open interval (0, 1) from (seed, counter).
double uniformOpen01(std::uint64_t seed, std::uint64_t counter);
// Uniformly random permutation of 0..k-1 (Fisher-Yates, counter-based, from (seed, i)).
std::vector<int> permutation(int k, std::uint64_t seed);

}  // namespace rad
