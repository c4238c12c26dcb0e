// The records of one key-time solve's links (SolverLink, LinkRayPair), the values a key-time
// solve may take over from the key before instead of recomputing them (CachedLink and the
// closure's caches; paper §4.2), and the seeds of a link's shadow rays. Node indices are dense
// indices of the union PatchHierarchy, which every key time shares; seeds follow patch ids, so
// they are the same at every key time and in every time window.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/radiosity/pair_table.h"
#include "libcommon/scene/patch_hierarchy.h"

namespace rad {

// One link of a key-time solve. 64 bytes: a key holds millions of them at rad-global's peak,
// so the record is kept small. The oracle's F~ and spread, and the
// shooter's shape, are single precision: they steer refinement and weight the gather by
// factors whose own error is far above 6e-8; F and V stay double.
struct SolverLink {
  static constexpr uint32_t kNotKnown = ~uint32_t(0);
  int receiver = 0;  // dense node index (gathers)
  int shooter = 0;   // dense node index (shoots)
  // Its entry in KeySolveInput::reuse (the previous key's values: the accurate F when that key
  // computed one, and its ray pairs), else kNotKnown.
  uint32_t known = kNotKnown;
  // The shooter's radiosity as the receiver sees it over its mean (weightVisibility...): the
  // ray pairs' kernel-weighted mean of its leaves' B, divided by B_q; 1 for a leaf shooter.
  float shooterShape = 1.0f;
  double formFactor = 0;        // unoccluded F(receiver -> shooter); the estimate until `accurate`
  double visibility = 0;        // V in [0, 1] as gathered: rayVisibility weighted by the
                                // shooter's radiosity at the rays' ends (weightVisibility...)
  double rayVisibility = 0;     // V of the shadow rays, kernel-weighted (visibilityFrom)
  uint64_t openPairs = 0;       // which of those ray pairs were unoccluded (bit i: pair i < 64)
  float estimate = 0;           // F~ of the oracle
  float spreadArea = 0;         // max(A_p dF(p -> q), A_q dF(q -> p)) of the error oracle (m^2)
  bool refined = false;         // kept for the hierarchy, not gathered
  bool accurate = false;        // the accurate pass has seen it (an invisible link may keep F~)
  bool integrated = false;      // formFactor is the quadrature value
  bool reused = false;          // F and V taken from the previous key time (coherence)
  bool visibilityOnly = false;  // F taken over, V recomputed (the shaft met a moving object)
  double fv() const { return formFactor * visibility; }
};

// One ray pair of a link's radiosity-weighted visibility (weightVisibilityByShooterRadiosity):
// its kernel and the (u,v) of its end in the shooter. Geometry only: valid while both ends are
// static, like CachedLink's estimate. Single precision: 12 bytes instead of 24, as a key's
// pairs are held twice at rad-global's peak (the previous key's and this one's); a relative
// 6e-8 in a weight or in where a pair ends in the shooter
// moves no gathered value beyond the rays' own noise.
struct LinkRayPair {
  glm::vec2 uv{0.0f};
  float kernel = 0;
};
// A link's first ray pair is a 32-bit index: at most RadiosityOptions::maxLinks (4 M) times
// kMaxRecordedPairs (64) pairs.
constexpr uint32_t kNoRayPairs = ~uint32_t(0);

// Link values that a key-time solve may take over instead of recomputing (paper §4.2): keyed
// by (receiver, shooter) dense node index, which every key of the union hierarchy shares. Only
// values are taken over, never decisions: the solve refines and iterates exactly as without them,
// so a coherent key solve is bit-identical to an independent one whenever the cached values are
// what recomputing would give.
struct CachedLink {
  float estimate = 0, spreadArea = 0;  // geometry only: valid while both ends are static
  double formFactor = -1;              // accurate unoccluded F, or < 0 when never computed
  double visibility = 0;               // the shadow rays' V (SolverLink::rayVisibility)
  uint64_t openPairs = 0;              // and their unoccluded pairs
  uint32_t rayPairs = kNoRayPairs;     // its first LinkRayPair in the previous KeySolution
  bool visibilityValid = false;        // false: a moving object's swept bound met the link's shaft
};
using LinkCache = PairTable<CachedLink>;
// The closure's leaf-to-top form factors F(leaf -> top-level patch) a key-time solve may take
// over (both static): per dense node of the union hierarchy (whose numbering every key shares),
// its (top index, F) pairs. A previous key's KeySolution::leafTopFormFactor as it is: a dense
// index finds the values directly, where a hash map would be rebuilt at every key.
using LeafFormFactorCache = std::vector<std::vector<std::pair<uint32_t, double>>>;
// Whether a node of a static top-level patch is inside a closed room (its escape rays all meet
// the static geometry), keyed by node id: the same at every key time.
using ClosedNodeCache = std::unordered_map<uint64_t, bool>;

// Seed of the shadow rays of link (receiver <- shooter). It does not depend on the key time:
// a link whose ends and blockers did not move gets bit-identical visibility whether it is
// reused (coherent) or recomputed (--no-coherence), and its shadow does not shimmer in time.
uint64_t linkSeed(PatchId receiver, PatchId shooter);
// Seed of a receiver's shadow-ray start points (VisibilityScene::samplePoints): the same for
// all its links and its exposure, and at every key time.
uint64_t receiverSeed(PatchId receiver);

}  // namespace rad
