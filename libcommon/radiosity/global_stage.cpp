// rad-global as a stage: options, key times, min-area default, report (see the header).
#include "libcommon/radiosity/global_stage.h"

#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <sstream>

#include "libcommon/core/error.h"

namespace rad {

nlohmann::json GlobalOptions::toJson() const {
  const RadiosityOptions& r = spaceTime.radiosity;
  return {{"frames", frames},
          {"fps", fps},
          {"key-step", keyStep},
          {"eps", r.eps},
          {"oracle", refinementOracleName(r.oracle)},
          {"min-area", r.minArea},
          {"rays", r.rays},
          {"tol", r.tol},
          {"bad-links", badLinkRuleName(spaceTime.badLinks)},
          {"partial-threshold", spaceTime.partialThreshold},
          {"partial-power-share", spaceTime.partialPowerShare},
          {"max-links", r.maxLinks},
          {"no-closure", !r.closure},
          {"no-closed-rooms", !r.closedRooms},
          {"no-clustering", !r.clustering},
          {"cluster-separation", r.clusterSeparation},
          {"light-cluster-share", r.lightClusterShare},
          {"cluster-member-rays", r.clusterMemberRays},
          {"isotropic-clusters", r.isotropicClusters},
          {"no-shooter-shape", !r.shooterShape},
          {"no-coherence", !spaceTime.coherence}};
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
  return {{"key_times", keys},
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
      << " link rows, " << solve.badPairs << " bad pairs\n"
      << "  seconds: links " << t.secondsLinks << ", solve " << t.secondsSolve << ", merge "
      << solve.secondsMerge << ", write " << secondsWrite << ", total " << secondsTotal
      << "; peak memory " << std::setprecision(1) << peakMemoryMb << " MB\n";
  return out.str();
}

}  // namespace rad
