// rad-global as a stage: options, key times, min-area default, report (see the header).
#include "libcommon/radiosity/global_stage.h"

#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <sstream>

#include "libcommon/core/error.h"
#include "libcommon/core/shared_parameters.h"

namespace rad {

namespace {

using Group = ParameterGroup;
using Check = ParameterCheck;

RadiosityOptions& radiosity(GlobalOptions& g) {
  return g.spaceTime.radiosity;
}

// The key times, refinement and solver.
void addSolveParameters(ParameterTable<GlobalOptions>& t) {
  addFramesParameter(t, &GlobalOptions::frames, "the scene's animation, docs/design.md §1");
  addFpsParameter(t, &GlobalOptions::fps);
  t.add("key-step", &GlobalOptions::keyStep,
        "frames between key times (the last frame is always one)", Check::positive(),
        Group::kQuality);
  t.add(
      "eps", [](GlobalOptions& g) -> double& { return radiosity(g).eps; },
      "refinement threshold: refine while B_q F_pq V A_p > eps x the largest power emitted "
      "or, once it is larger, carried (sum of A B over the patches)",
      Check::nonNegative(), Group::kQuality);
  t.add(
      "shadow-eps-share", [](GlobalOptions& g) -> double& { return radiosity(g).shadowEpsShare; },
      "also refine a partly visible link while B_q F_pq min(V, 1 - V) A_p > this x eps x the "
      "power: the receiver's one radiosity blends both sides of a shadow boundary (0: off)",
      Check::nonNegative());
  t.add(
      "rays", [](GlobalOptions& g) -> int& { return radiosity(g).rays; },
      "shadow-ray pairs per link", Check::positive(), Group::kQuality);
  t.addEnum(
      "oracle", [](GlobalOptions& g) -> RefinementOracle& { return radiosity(g).oracle; },
      EnumNames<RefinementOracle>::of(
          {RefinementOracle::kPower, RefinementOracle::kError, RefinementOracle::kBoth},
          refinementOracleName),
      "what --eps bounds: power (B_q F_pq V A_p, HSA'91), error (B_q V times the spread "
      "of the point form factor over either patch, x its area), both");
  t.add(
      "min-area", [](GlobalOptions& g) -> double& { return radiosity(g).minArea; },
      "do not subdivide patches of this area (m^2) or less; 0: 1e-4 of the largest "
      "top-level patch",
      Check::nonNegative());
  t.add(
      "tol", [](GlobalOptions& g) -> double& { return radiosity(g).tol; },
      "solver stop: relative change < tol x (1 - max reflectance)", Check::positive());
  t.add(
      "max-links", [](GlobalOptions& g) -> size_t& { return radiosity(g).maxLinks; },
      "memory bound: a key time stops refining at this many links (~160 bytes each) and "
      "warns; at most 2^31",
      Check::range(1, double(kMaxLinkBound)));
}

// The bad links the second pass takes, and the clusters.
void addLinkParameters(ParameterTable<GlobalOptions>& t) {
  t.addEnum(
      "bad-links", [](GlobalOptions& g) -> BadLinkRule& { return g.spaceTime.badLinks; },
      EnumNames<BadLinkRule>::of(
          {BadLinkRule::kLights, BadLinkRule::kPartial, BadLinkRule::kAll, BadLinkRule::kNone},
          badLinkRuleName),
      "which (receiver, shooter) pairs the second pass computes per texel: lights "
      "(emitting shooters), partial (also partly visible links), all, none");
  t.add(
      "partial-threshold", [](GlobalOptions& g) -> double& { return g.spaceTime.partialThreshold; },
      "partial: a link is partly visible when threshold < V < 1", Check::range(0.0, 1.0));
  t.add(
      "partial-power-share",
      [](GlobalOptions& g) -> double& { return g.spaceTime.partialPowerShare; },
      "partial: a pair whose shooter does not emit only when its partly visible links' "
      "shadow, sum B F (1 - V) A, is at least this share of the power the surfaces carry "
      "(sum A B); 0: every such pair",
      Check::range(0.0, 1.0));
  t.add(
      "cluster-separation",
      [](GlobalOptions& g) -> double& { return radiosity(g).clusterSeparation; },
      "keep a cluster link only while its ends' centres are at least this many times the sum "
      "of their bounding radii apart; larger is more accurate and slower",
      Check::range(1.0, 1e6));
  t.add(
      "weak-near-ambient-share",
      [](GlobalOptions& g) -> double& { return radiosity(g).weakNearAmbientShare; },
      "before the first solve, judge which near cluster links are too weak to refine by this "
      "share of the ambient radiosity (the emitted power over the area's absorption) instead "
      "of by the lights' alone",
      Check::range(0.0, 1e6));
  t.add(
      "light-cluster-share",
      [](GlobalOptions& g) -> double& { return radiosity(g).lightClusterShare; },
      "a link from a light stays a cluster link (smooth light, no per-texel shadows) while "
      "its power bound is under this share of eps times the power; 0 refines every light's "
      "links to patch pairs",
      Check::range(0.0, 1e6));
  t.add(
      "cluster-member-rays",
      [](GlobalOptions& g) -> int& { return radiosity(g).clusterMemberRays; },
      "shadow-ray pairs per member top of a cluster link's receiver, for that top's own "
      "visibility; 0: each member takes its facing group's visibility",
      Check::range(0, 64));
  t.add(
      "near-block-rays", [](GlobalOptions& g) -> int& { return radiosity(g).nearBlockRays; },
      "rays of the blocked test of a near cluster link between large ends: dropped when all "
      "are blocked (rooms behind a wall), else refined; 0: such links are refined untested",
      Check::range(0, 1024));
}

// The switches that exist to compare against a baseline.
void addBaselineParameters(ParameterTable<GlobalOptions>& t) {
  t.addFlag(
      "no-closure", [](GlobalOptions& g) -> bool& { return radiosity(g).closure; }, false,
      "gather without the closure factor (each leaf's row sum its own; exact energy "
      "balance in closed rooms): the plain hierarchical gather, for comparison",
      Group::kBaseline);
  t.addFlag(
      "no-closed-rooms", [](GlobalOptions& g) -> bool& { return radiosity(g).closedRooms; }, false,
      "do not scale the row sums of leaves inside a closed room (no escaping ray) to "
      "exactly 1; only the unoccluded tops' share is corrected, as in open scenes",
      Group::kBaseline);
  t.addFlag(
      "no-clustering", [](GlobalOptions& g) -> bool& { return radiosity(g).clustering; }, false,
      "link every pair of top-level patches (the baseline) instead of starting from the "
      "root cluster's self-link of a cluster hierarchy over them",
      Group::kBaseline);
  t.addFlag(
      "refine-weak-near-links",
      [](GlobalOptions& g) -> bool& { return radiosity(g).keepWeakNearLinks; }, false,
      "refine every near cluster link without a light down to its member pairs, also one "
      "that cannot carry eps times the power (its bound with form factor 1), instead of "
      "keeping it: packed small objects then fill the link bound",
      Group::kBaseline);
  t.addFlag(
      "isotropic-clusters",
      [](GlobalOptions& g) -> bool& { return radiosity(g).isotropicClusters; }, true,
      "take each cluster as emitting and receiving alike in every direction (area / 4) "
      "instead of by its members' facing groups",
      Group::kBaseline);
  t.addFlag(
      "no-shooter-shape", [](GlobalOptions& g) -> bool& { return radiosity(g).shooterShape; },
      false,
      "gather each link's shooter at its mean radiosity, not as the receiver's ray pairs "
      "see its leaves' radiosity",
      Group::kBaseline);
  t.addFlag(
      "no-coherence", [](GlobalOptions& g) -> bool& { return g.spaceTime.coherence; }, false,
      "recompute every link at every key time (the baseline of the speed-up)", Group::kBaseline);
}

}  // namespace

const ParameterTable<GlobalOptions>& globalParameters() {
  static const ParameterTable<GlobalOptions> table = [] {
    ParameterTable<GlobalOptions> t;
    addSolveParameters(t);
    addLinkParameters(t);
    addBaselineParameters(t);
    return t;
  }();
  return table;
}

const std::vector<Preset>& globalPresets() {
  static const std::vector<Preset> presets{
      {"draft", {{"eps", "0.02"}}},
      {"final", {{"eps", "1e-5"}, {"key-step", "4"}, {"rays", "64"}}},
  };
  return presets;
}

nlohmann::json GlobalOptions::toJson() const {
  return globalParameters().toJson(*this);
}

std::vector<double> keyTimesOf(const FrameRange& frames, int keyStep, double fps) {
  std::vector<double> times;
  for (int f : keyFrames(frames.first, frames.last, keyStep)) times.push_back(f / fps);
  return times;
}

KeyIndexRange windowKeys(const FrameRange& frames, int keyStep, const std::string& window) {
  int first = 0, last = 0;
  char dash = 0, rest = 0;
  if (std::sscanf(window.c_str(), "%d %c %d %c", &first, &dash, &last, &rest) != 3 || dash != '-' ||
      first < 0 || last < first)
    throw Error(ExitCode::kUsage, "", "--window " + window + ": expected FIRST-LAST");
  const FrameRange w{first, last};
  if (!frames.covers(w))
    throw Error(ExitCode::kUsage, "",
                "--window " + window + " is not within the run's frames " + frames.toString());
  const std::vector<int> keys = keyFrames(frames.first, frames.last, keyStep);
  KeyIndexRange r{keys.size(), 0};
  for (size_t k = 0; k < keys.size(); ++k)
    if (keys[k] >= first && keys[k] <= last) r.first = std::min(r.first, k), r.last = k;
  if (r.first == keys.size())
    throw Error(ExitCode::kUsage, "",
                "--window " + window + " holds no key frame of frames " + frames.toString() +
                    " at --key-step " + std::to_string(keyStep));
  return r;
}

std::vector<FrameRange> keyWindows(const FrameRange& frames, int keyStep, int count) {
  const std::vector<int> keys = keyFrames(frames.first, frames.last, keyStep);
  const size_t K = keys.size(), n = std::min(K, size_t(std::max(count, 1)));
  std::vector<FrameRange> out;
  for (size_t i = 0; i < n; ++i) {
    const size_t firstKey = K * i / n, nextKey = K * (i + 1) / n;
    out.push_back(
        {i == 0 ? frames.first : keys[firstKey], i + 1 == n ? frames.last : keys[nextKey] - 1});
  }
  return out;
}

std::vector<std::string> argumentsWithoutMerge(int argc, const char* const* argv,
                                               const std::vector<std::string>& merged) {
  std::vector<std::string> out;
  size_t next = 0;  // merged[next] is the next value a "--merge" took (it may come again)
  for (int i = 0; i < argc; ++i) {
    const std::string word = argv[i];
    if (word.rfind("--merge=", 0) == 0) {
      next += next < merged.size() && word.substr(8) == merged[next];
      continue;
    }
    if (word == "--merge") {  // and the values CLI11 gave it, as many as follow in order
      while (i + 1 < argc && next < merged.size() && argv[i + 1] == merged[next]) ++i, ++next;
      continue;
    }
    out.push_back(word);
  }
  return out;
}

double resolveMinArea(const Scene& scene, double minArea, double t) {
  if (minArea > 0.0) return minArea;
  double largest = 0;
  for (const InputPolygon& p : scene.inputPolygons()) {
    glm::dmat4 m = p.node >= 0 ? scene.worldTransform(p.node, t) : glm::dmat4(1);
    largest = std::max(largest, p.local.transformed(m).area());
  }
  return 1e-4 * largest;
}

namespace {

// Sums of the per-key figures.
struct KeyTotals {
  size_t recomputed = 0, reused = 0, links = 0, visibilityOnly = 0, clusterLinks = 0;
  size_t lampValues = 0, lampValuesReused = 0;
  double secondsLinks = 0, secondsSolve = 0, secondsCoherence = 0;
  long iterations = 0;
};

KeyTotals totalsOf(const std::vector<KeyTimeReport>& keys) {
  KeyTotals t;
  for (const KeyTimeReport& r : keys) {
    t.recomputed += r.recomputed;
    t.reused += r.reused;
    t.visibilityOnly += r.visibilityOnly;
    t.links += r.links;
    t.clusterLinks += r.clusterLinks;
    t.lampValues += r.lampValues;
    t.lampValuesReused += r.lampValuesReused;
    t.secondsLinks += r.secondsLinks;
    t.secondsSolve += r.secondsSolve;
    t.secondsCoherence += r.secondsCoherence;
    t.iterations += r.iterations;
  }
  return t;
}

}  // namespace

nlohmann::json GlobalReport::toJson() const {
  nlohmann::json keys = nlohmann::json::array();
  for (size_t k = 0; k < solve.keys.size(); ++k) {
    nlohmann::json key = solve.keys[k].toJson();
    key["key"] = k;
    keys.push_back(std::move(key));
  }
  const KeyTotals t = totalsOf(solve.keys);
  nlohmann::json report = {{"key_times", keys},
                           {"totals",
                            {{"links", t.links},
                             {"cluster_links", t.clusterLinks},
                             {"recomputed", t.recomputed},
                             {"reused", t.reused},
                             {"visibility_only", t.visibilityOnly},
                             {"iterations", t.iterations},
                             {"union_nodes", solve.unionNodes},
                             {"link_rows", solve.linkRows},
                             {"bad_pairs", solve.badPairs},
                             {"keys_at_link_cap", keysAtLinkCap()}}},
                           {"seconds",
                            {{"read", secondsRead},
                             {"setup", solve.secondsSetup},
                             {"links", t.secondsLinks},
                             {"solve", t.secondsSolve},
                             {"coherence", t.secondsCoherence},
                             {"merge", solve.secondsMerge},
                             {"write", secondsWrite},
                             {"total", secondsTotal}}},
                           {"peak_memory_mb", peakMemoryMb},
                           {"coherence", coherence}};
  if (t.lampValues > 0) {  // a scene with lamps only
    report["totals"]["lamp_values"] = t.lampValues;
    report["totals"]["lamp_values_reused"] = t.lampValuesReused;
  }
  return report;
}

size_t GlobalReport::keysAtLinkCap() const {
  size_t n = 0;
  for (const KeyTimeReport& r : solve.keys) n += r.linkCapReached;
  return n;
}

std::string GlobalReport::linkCapWarning(const std::string& tool, size_t maxLinks) const {
  const size_t n = keysAtLinkCap();
  if (n == 0) return "";
  return tool + ": warning: " + std::to_string(n) + " of " + std::to_string(solve.keys.size()) +
         " key times stopped refining at the link bound (" + std::to_string(maxLinks) +
         " links); the solution is coarser than the refinement threshold asks\n";
}

std::string GlobalReport::table(const std::string& tool) const {
  std::ostringstream out;
  out << tool << ": " << solve.keys.size() << " key times, " << solve.topPatches
      << " top-level patches\n";
  out << "  key   time(s)    links  recomputed    reused  nodes  sweeps  links(s) solve(s)\n";
  auto row = [&](size_t k) {
    const KeyTimeReport& r = solve.keys[k];
    out << std::setw(5) << k << std::setw(10) << std::fixed << std::setprecision(3) << r.time
        << std::setw(9) << r.links << std::setw(12) << r.recomputed << std::setw(10) << r.reused
        << std::setw(7) << r.nodes << std::setw(8) << r.iterations << std::setw(10)
        << r.secondsLinks << std::setw(9) << r.secondsSolve << "\n";
  };
  const size_t K = solve.keys.size();
  const size_t head = K > kTableKeys ? kTableKeys / 2 : K;
  for (size_t k = 0; k < head; ++k) row(k);
  if (K > kTableKeys)
    out << "  ... " << K - kTableKeys << " more key times (every one in --report's key_times)\n";
  for (size_t k = std::max(head, K - kTableKeys / 2); k < K; ++k) row(k);
  const KeyTotals t = totalsOf(solve.keys);
  out << "  total: " << t.links << " links (and " << t.clusterLinks << " cluster links), "
      << t.recomputed << " recomputed (" << t.visibilityOnly << " of them visibility only), "
      << t.reused << " reused; " << solve.unionNodes << " union nodes, " << solve.linkRows
      << " link rows, " << solve.badPairs << " bad pairs\n";
  if (t.lampValues > 0)
    out << "  lamps: " << t.lampValues << " direct irradiance values, " << t.lampValuesReused
        << " of them reused\n";
  out << "  seconds: links " << t.secondsLinks << ", solve " << t.secondsSolve << ", merge "
      << solve.secondsMerge << ", write " << secondsWrite << ", total " << secondsTotal
      << "; peak memory " << std::setprecision(1) << peakMemoryMb << " MB\n";
  return out.str();
}

}  // namespace rad
