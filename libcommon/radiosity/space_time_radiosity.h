// Space-time hierarchical radiosity (paper §3.1, §4.2; DESIGN.md §6 "rad-global"): one
// hierarchical solve per key time on a shared (union) patch hierarchy, with temporal
// coherence between consecutive key times, merged into a GlobalSolution.
//
// Coherence (§4.2): between key times t_{k-1} and t_k a link keeps its F and V when both its
// end patches are static over [t_{k-1}, t_k] and its shaft (Haines & Wallace 1994; see
// shaftMeetsBox) meets no swept bound of a node that moves in that interval. Such a link's
// shadow rays would hit exactly what they hit before (same seeds, same static blockers, no
// dynamic one inside the shaft), so the values taken over are the ones recomputing would give
// and, since the solve makes the same decisions from them, the coherent solution is
// bit-identical to independent per-key solves. Without coherence every key time is an
// independent solve (the baseline of the speed-up, and of the tests).
//
// Memory: each key time's links are folded into the links' activity intervals as soon as the
// key is solved (a run whose F·V does not change keeps one value), so the peak is one key's
// solve plus the compact result, not key times x links.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "libcommon/radiosity/global_solution.h"
#include "libcommon/radiosity/hierarchical_radiosity.h"
#include "libcommon/scene/scene.h"

namespace rad {

enum class BadLinkRule { kLights, kPartial, kAll, kNone };
BadLinkRule parseBadLinkRule(const std::string& s);  // lights|partial|all|none; usage Error
const char* badLinkRuleName(BadLinkRule r);

struct SpaceTimeOptions {
  RadiosityOptions radiosity;
  BadLinkRule badLinks = BadLinkRule::kLights;
  // partial: a pair is also bad when one of its gathered links has partialThreshold < V < 1.
  double partialThreshold = 0.0;
  bool coherence = true;
  std::function<void()> onKeySolved;  // called after each key time's solve (progress)
};

struct KeyTimeReport {
  double time = 0;
  size_t links = 0;           // all links of the key (refined ones included)
  size_t recomputed = 0;      // F / V computed at this key
  size_t reused = 0;          // F and V taken over from the previous key
  size_t visibilityOnly = 0;  // of recomputed: F taken over, only V computed
  size_t nodes = 0;           // nodes of this key's tree
  int iterations = 0;         // Gauss-Seidel sweeps
  int refineRounds = 0;
  bool linkCapReached = false;    // refinement stopped at the link bound (RadiosityOptions)
  size_t clusterLinks = 0;        // cluster links gathered (clustering)
  size_t clusterLinksReused = 0;  // of them: values taken over from the previous key
  double secondsLinks = 0, secondsSolve = 0, secondsCoherence = 0;

  // The --report JSON of one key (keys "time", "links", "recomputed", ...; global_stage.h),
  // also how a key window file carries its keys' figures to the merge.
  nlohmann::json toJson() const;
  static KeyTimeReport fromJson(const nlohmann::json& j);  // missing keys stay 0
};

struct SpaceTimeReport {
  std::vector<KeyTimeReport> keys;
  double secondsSetup = 0, secondsMerge = 0;
  size_t topPatches = 0, unionNodes = 0, linkRows = 0, badPairs = 0;
};

// Link values of `previous` (solved at t0 on `hierarchy`) that stay valid until t1: F, its
// estimate and spread while both ends are static; V too unless the shaft meets a swept bound.
LinkCache reusableLinks(const KeySolution& previous, const PatchHierarchy& hierarchy,
                        const Scene& scene, double t0, double t1);

// The closure's leaf-to-top form factors of `previous`, all valid at the next key time: the
// closure integrates only pairs of patches that never move.
LeafFormFactorCache reusableLeafFormFactors(const KeySolution& previous,
                                            const PatchHierarchy& hierarchy);

// The whole first pass: key times must be strictly increasing. Two passes: the key-time pass
// (per key: the visibility scene at t, the links coherence keeps from the previous key,
// solveKeyTime, its links folded into activity intervals and bad pairs), then the merge into
// the union hierarchy (node radiosity per key, bad pairs, link rows with their F·V samples,
// good-link irradiance at the leaves' vertices).
GlobalSolution solveSpaceTime(const Scene& scene, const std::vector<double>& keyTimes,
                              const SpaceTimeOptions& options, SpaceTimeReport* report = nullptr);

// A time window of the key-time pass (rad-global --window; issue 17 "Render farm"): the keys
// firstKey .. firstKey + K - 1 of a run's key times, solved on a union hierarchy of their own,
// with all the final merge of solveSpaceTime needs of them, at the precision it uses them (the
// per-key records are float there too). Windows that together hold every key merge
// (mergeKeyWindows) into the very GlobalSolution solveSpaceTime computes over all the keys.
//
// Why a window needs nothing of the keys before it: a key's solve depends on its own time only
// (coherence takes over values, never decisions, and the values are the ones recomputing gives;
// the solve works on node ids and the tree's structure, not on the union's dense indices), and
// everything that depends on the whole animation (the static/moving split of the visibility
// scene and of the closure, the cluster tree, the minimum area) is built from the run's first
// and last key times, which a window is given with the rest of the run's keys.
struct KeyWindow {
  uint32_t firstKey = 0;         // index of its first key in the run's key times
  std::vector<double> keyTimes;  // K >= 1: the run's keyTimes[firstKey .. firstKey + K - 1]
  PatchHierarchy hierarchy;      // the window's union hierarchy, in its own subdivision order
  // Per key k: the union's node count after k's solve. The nodes key k made are
  // [nodeCount[k - 1], nodeCount[k]) (from topCount for k = 0), in the order its solve first
  // split their parents: the merge replays them key by key to rebuild the run's node order.
  std::vector<uint32_t> nodeCount;
  // Per node i and key k at i * K + k, the per-key records of the final merge: B (a node
  // outside the key's tree has its nearest ancestor's in it), exposure (1 outside the tree),
  // the good closure factor of the key-tree leaf at or above it (1 above the leaves).
  std::vector<glm::vec3> radiosity;
  std::vector<float> exposure, goodClosure;
  // Per top t and key k at t * K + k: the irradiance gathered through cluster links; empty when
  // the run has no cluster links (--no-clustering).
  std::vector<glm::vec3> clusterIrradiance;
  // The links' activity intervals within the window (keys from 0 = firstKey; flags:
  // kLinkRefined only). A row's (F·V, V) values at sampleOffset: one when every key of the row
  // has the first one's bits, else one per key (so the merge re-adds every key's exact bits).
  std::vector<GlobalLink> links;
  std::vector<float> linkValues, linkVisibility;
  std::vector<std::pair<uint32_t, uint32_t>> badPairs;  // (receiver top, shooter top), sorted
  std::vector<KeyTimeReport> reports;                   // per key (not checked, for --report)

  size_t keyCount() const { return keyTimes.size(); }
  // Throws rad::inputError(where, ...) when sizes, indices or values are inconsistent (what
  // the merge indexes with is in range; key times increase; exposures in [0, 1]).
  void validate(const std::string& where) const;
};

// The key-time pass on keys firstKey..lastKey (inclusive) of `keyTimes`, all of the run's key
// times (they fix what depends on the whole animation).
KeyWindow solveKeyWindow(const Scene& scene, const std::vector<double>& keyTimes, size_t firstKey,
                         size_t lastKey, const SpaceTimeOptions& options,
                         SpaceTimeReport* report = nullptr);

// solveSpaceTime's result from windows of the same run (`keyTimes` all of its key times;
// `names[i]` names windows[i] in errors): each key is taken from the first window, by first
// key, that holds it; the subdivisions are replayed key by key, the per-key records and the
// links' values re-added in key order, and the same final merge runs. One-line
// rad::inputError naming a window when a key is in no window, when windows that share a key
// disagree there, or when a window's key times are not the run's.
GlobalSolution mergeKeyWindows(const Scene& scene, const std::vector<double>& keyTimes,
                               std::vector<KeyWindow> windows,
                               const std::vector<std::string>& names,
                               SpaceTimeReport* report = nullptr);

}  // namespace rad
