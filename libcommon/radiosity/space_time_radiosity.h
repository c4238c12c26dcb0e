// Space-time hierarchical radiosity (paper §3.1, §4.2; docs/design.md §6.1 "rad-global"): one
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
#include "libcommon/radiosity/key_solve_inputs.h"
#include "libcommon/radiosity/key_window.h"
#include "libcommon/scene/scene.h"

namespace rad {

enum class BadLinkRule { kLights, kPartial, kAll, kNone };
const char* badLinkRuleName(BadLinkRule r);

struct SpaceTimeOptions {
  RadiosityOptions radiosity;
  BadLinkRule badLinks = BadLinkRule::kLights;
  // partial: a pair is also bad when one of its gathered links has partialThreshold < V < 1.
  double partialThreshold = 0.0;
  // partial: a pair whose shooter does not emit only when the shadow of its partly visible
  // links, sum B_q F (1 - V) A_p, is at least this share of the power the top-level patches
  // carry (sum A B) at some key time; 0: every such pair.
  double partialPowerShare = 0.0;
  bool coherence = true;
  std::function<void()> onKeySolved;  // called after each key time's solve (progress)
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

// The whole first pass: key times must be strictly increasing. Two passes: the key-time pass
// (per key: the visibility scene at t, the links coherence keeps from the previous key,
// solveKeyTime, its links folded into activity intervals and bad pairs), then the merge into
// the union hierarchy (node radiosity per key, bad pairs, link rows with their F·V samples,
// good-link irradiance at the leaves' vertices).
GlobalSolution solveSpaceTime(const Scene& scene, const std::vector<double>& keyTimes,
                              const SpaceTimeOptions& options, SpaceTimeReport* report = nullptr);

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
