// rad-global as a stage: options, key times, min-area default, report (see the header).
#include "libcommon/radiosity/global_stage.h"

#include <algorithm>
#include <iomanip>
#include <sstream>

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
          {"max-links", r.maxLinks},
          {"no-closure", !r.closure},
          {"no-closed-rooms", !r.closedRooms},
          {"no-clustering", !r.clustering},
          {"cluster-separation", r.clusterSeparation},
          {"no-shooter-shape", !r.shooterShape},
          {"no-coherence", !spaceTime.coherence}};
}

std::vector<double> keyTimesOf(const FrameRange& frames, int keyStep, double fps) {
  std::vector<double> times;
  for (int f : keyFrames(frames.first, frames.last, keyStep)) times.push_back(f / fps);
  return times;
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
    const KeyTimeReport& r = solve.keys[k];
    keys.push_back({{"key", k},
                    {"time", r.time},
                    {"links", r.links},
                    {"recomputed", r.recomputed},
                    {"reused", r.reused},
                    {"visibility_only", r.visibilityOnly},
                    {"nodes", r.nodes},
                    {"iterations", r.iterations},
                    {"refine_rounds", r.refineRounds},
                    {"link_cap_reached", r.linkCapReached},
                    {"cluster_links", r.clusterLinks},
                    {"cluster_links_reused", r.clusterLinksReused},
                    {"seconds_links", r.secondsLinks},
                    {"seconds_solve", r.secondsSolve},
                    {"seconds_coherence", r.secondsCoherence}});
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
  for (size_t k = 0; k < solve.keys.size(); ++k) {
    const KeyTimeReport& r = solve.keys[k];
    out << std::setw(5) << k << std::setw(10) << std::fixed << std::setprecision(3) << r.time
        << std::setw(9) << r.links << std::setw(12) << r.recomputed << std::setw(10) << r.reused
        << std::setw(7) << r.nodes << std::setw(8) << r.iterations << std::setw(10)
        << r.secondsLinks << std::setw(9) << r.secondsSolve << "\n";
  }
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
