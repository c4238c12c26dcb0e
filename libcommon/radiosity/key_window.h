// The records a key-time solve hands on (issue 17 "Render farm"): one key time's figures
// (KeyTimeReport) and a time window's solve (KeyWindow), which rad-global --window writes as a
// key window file (formats/key_window.md) and --merge reads. Apart from the solver, so that the
// file's reader links without it (the fuzz build, tests/fuzz).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "libcommon/radiosity/global_solution.h"
#include "libcommon/scene/patch_hierarchy.h"

namespace rad {

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
  size_t lampValues = 0;          // (node, lamp) direct irradiance values of the key's leaves
  size_t lampValuesReused = 0;    // of them: taken over from the previous key
  double secondsLinks = 0, secondsSolve = 0, secondsCoherence = 0;
  // The key's links by kind at the end of its refinement (LinkCensus::toJson; null: not
  // counted, as in a key window file written before it).
  nlohmann::json linkCensus;

  // The --report JSON of one key (keys "time", "links", "recomputed", ...; global_stage.h),
  // also how a key window file carries its keys' figures to the merge.
  nlohmann::json toJson() const;
  static KeyTimeReport fromJson(const nlohmann::json& j);  // missing keys stay 0
};

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

}  // namespace rad
