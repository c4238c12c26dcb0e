// rad-global: the first pass (paper §3.1, §4.2; DESIGN.md §6 "rad-global"): space-time
// hierarchical radiosity over the key times of a frame range, written as global.rlh.

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <iostream>

#include "formats/atomic_file.h"
#include "formats/gltf_scene.h"
#include "formats/link_hierarchy.h"
#include "formats/provenance.h"
#include "libcommon/radiosity/space_time_radiosity.h"
#include "tools/common/tool_main.h"

namespace {

constexpr const char* kTool = "rad-global";

struct Options {
  std::string scene;
  std::string output;
  std::string frames = "0-0";
  double fps = 24.0;
  // 8, not 4: on four scenes (the bundled one, 8 cubes, the table with moving lights, static
  // and following camera; 48 frames, tradeoff.py) 8 gave the same error against the path-traced
  // reference to 0.03 % and 17-28 % less CPU time; the good links' indirect light between
  // keys is smooth, and the lights' (bad) links are re-evaluated per movie key anyway.
  int keyStep = 8;
  double eps = 1e-3;
  std::string oracle = "power";
  double minArea = 0.0;
  int rays = 16;
  double tol = 1e-4;
  std::string badLinks = "lights";
  double partialThreshold = 0.0;
  bool noCoherence = false;
  std::string report;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Space-time hierarchical radiosity (first pass): solves the scene at key times of a frame "
      "range with temporal coherence and writes the link hierarchy global.rlh."};
  Options o;
  rad::setUpApp(app, kTool,
                "rad-global scene.gltf -o global.rlh --frames 0-95 --fps 24 --key-step 8");
  app.add_option("SCENE", o.scene, "glTF scene")->required();
  app.add_option("-o,--output", o.output, "output link hierarchy (.rlh)")->required();
  app.add_option("--frames", o.frames, "frame range a-b (time = frame / fps)")
      ->capture_default_str();
  app.add_option("--fps", o.fps, "frames per second")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--key-step", o.keyStep, "frames between key times (the last frame is always one)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--eps", o.eps,
                 "refinement threshold: refine while B_q F_pq V A_p > eps x largest emitted power")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--oracle", o.oracle,
                 "what --eps bounds: power (B_q F_pq V A_p, HSA'91), error (B_q V times the "
                 "spread of the point form factor over either patch, x its area), both")
      ->capture_default_str()
      ->check(CLI::IsMember({"power", "error", "both"}));
  app.add_option("--min-area", o.minArea,
                 "do not subdivide patches of this area (m^2) or less; 0: 1e-4 of the largest "
                 "top-level patch")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--rays", o.rays, "shadow-ray pairs per link")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--tol", o.tol, "solver stop: relative change < tol x (1 - max reflectance)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--bad-links", o.badLinks,
                 "which (receiver, shooter) pairs the second pass computes per texel: lights "
                 "(emitting shooters), partial (also partly visible links), all, none")
      ->capture_default_str()
      ->check(CLI::IsMember({"lights", "partial", "all", "none"}));
  app.add_option("--partial-threshold", o.partialThreshold,
                 "partial: a link is partly visible when threshold < V < 1")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  app.add_flag("--no-coherence", o.noCoherence,
               "recompute every link at every key time (the baseline of the speed-up)");
  app.add_option("--report", o.report, "also write the run report as JSON to this file");
  if (int rc = rad::parseCommandLine(app, kTool, argc, argv); rc >= 0) return rc;

  return rad::runTool(kTool, [&]() {
    auto tStart = std::chrono::steady_clock::now();
    std::vector<int> frames = rad::parseFrameRange(o.frames);
    if (frames.empty()) throw rad::Error(rad::ExitCode::kUsage, "--frames", "names no frame");
    int first = *std::min_element(frames.begin(), frames.end());
    int last = *std::max_element(frames.begin(), frames.end());
    std::vector<double> keyTimes;
    for (int f = first; f < last; f += o.keyStep) keyTimes.push_back(f / o.fps);
    keyTimes.push_back(last / o.fps);

    auto tRead = std::chrono::steady_clock::now();
    rad::Scene scene = rad::readGltfScene(o.scene);
    double secondsRead =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - tRead).count();

    rad::SpaceTimeOptions st;
    st.radiosity.eps = o.eps;
    st.radiosity.oracle = o.oracle == "error"  ? rad::RefinementOracle::kError
                          : o.oracle == "both" ? rad::RefinementOracle::kBoth
                                               : rad::RefinementOracle::kPower;
    st.radiosity.rays = o.rays;
    st.radiosity.tol = o.tol;
    st.radiosity.minArea = o.minArea;
    if (o.minArea <= 0.0) {
      double largest = 0;
      for (const rad::InputPolygon& p : scene.inputPolygons()) {
        glm::dmat4 m = p.node >= 0 ? scene.worldTransform(p.node, keyTimes.front()) : glm::dmat4(1);
        largest = std::max(largest, p.local.transformed(m).area());
      }
      st.radiosity.minArea = 1e-4 * largest;
    }
    st.badLinks = rad::parseBadLinkRule(o.badLinks);
    st.partialThreshold = o.partialThreshold;
    st.coherence = !o.noCoherence;

    rad::Progress progress(kTool, long(keyTimes.size()));
    st.onKeySolved = [&]() { progress.advance(); };
    rad::SpaceTimeReport rep;
    rad::GlobalSolution g = rad::solveSpaceTime(scene, keyTimes, st, &rep);
    progress.done();

    nlohmann::json params = {{"frames", o.frames},
                             {"fps", o.fps},
                             {"key-step", o.keyStep},
                             {"eps", o.eps},
                             {"oracle", o.oracle},
                             {"min-area", st.radiosity.minArea},
                             {"rays", o.rays},
                             {"tol", o.tol},
                             {"bad-links", o.badLinks},
                             {"partial-threshold", o.partialThreshold},
                             {"no-coherence", o.noCoherence}};
    rad::Provenance prov = rad::makeProvenance(kTool, argc, argv, params);
    rad::addInput(prov, o.scene);
    auto tWrite = std::chrono::steady_clock::now();
    rad::writeLinkHierarchy(o.output, g, prov,
                            {{"parameters", params},
                             {"first_frame", first},
                             {"last_frame", last},
                             {"coherence", !o.noCoherence}});
    double secondsWrite =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - tWrite).count();

    // Report: per key time and totals, on stderr and optionally as JSON.
    nlohmann::json keys = nlohmann::json::array();
    size_t recomputed = 0, reused = 0, total = 0, visibilityOnly = 0;
    double secondsLinks = 0, secondsSolve = 0, secondsCoherence = 0;
    long iterations = 0;
    std::cerr << kTool << ": " << keyTimes.size() << " key times, " << scene.inputPolygons().size()
              << " top-level patches\n";
    std::cerr << "  key   time(s)    links  recomputed    reused  nodes  sweeps  links(s) "
                 "solve(s)\n";
    for (size_t k = 0; k < rep.keys.size(); ++k) {
      const rad::KeyTimeReport& r = rep.keys[k];
      keys.push_back({{"key", k},
                      {"time", r.time},
                      {"links", r.links},
                      {"recomputed", r.recomputed},
                      {"reused", r.reused},
                      {"visibility_only", r.visibilityOnly},
                      {"nodes", r.nodes},
                      {"iterations", r.iterations},
                      {"refine_rounds", r.refineRounds},
                      {"seconds_links", r.secondsLinks},
                      {"seconds_solve", r.secondsSolve},
                      {"seconds_coherence", r.secondsCoherence}});
      std::cerr << std::setw(5) << k << std::setw(10) << std::fixed << std::setprecision(3)
                << r.time << std::setw(9) << r.links << std::setw(12) << r.recomputed
                << std::setw(10) << r.reused << std::setw(7) << r.nodes << std::setw(8)
                << r.iterations << std::setw(10) << r.secondsLinks << std::setw(9) << r.secondsSolve
                << "\n";
      recomputed += r.recomputed;
      reused += r.reused;
      visibilityOnly += r.visibilityOnly;
      total += r.links;
      secondsLinks += r.secondsLinks;
      secondsSolve += r.secondsSolve;
      secondsCoherence += r.secondsCoherence;
      iterations += r.iterations;
    }
    double secondsTotal =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - tStart).count();
    nlohmann::json j = {{"key_times", keys},
                        {"totals",
                         {{"links", total},
                          {"recomputed", recomputed},
                          {"reused", reused},
                          {"visibility_only", visibilityOnly},
                          {"iterations", iterations},
                          {"union_nodes", rep.unionNodes},
                          {"link_rows", rep.linkRows},
                          {"bad_pairs", rep.badPairs}}},
                        {"seconds",
                         {{"read", secondsRead},
                          {"setup", rep.secondsSetup},
                          {"links", secondsLinks},
                          {"solve", secondsSolve},
                          {"coherence", secondsCoherence},
                          {"merge", rep.secondsMerge},
                          {"write", secondsWrite},
                          {"total", secondsTotal}}},
                        {"peak_memory_mb", rad::peakMemoryMb()},
                        {"coherence", !o.noCoherence}};
    std::cerr << "  total: " << total << " links, " << recomputed << " recomputed ("
              << visibilityOnly << " of them visibility only), " << reused << " reused; "
              << rep.unionNodes << " union nodes, " << rep.linkRows << " link rows, "
              << rep.badPairs << " bad pairs\n"
              << "  seconds: links " << secondsLinks << ", solve " << secondsSolve << ", merge "
              << rep.secondsMerge << ", write " << secondsWrite << ", total " << secondsTotal
              << "; peak memory " << std::setprecision(1) << rad::peakMemoryMb() << " MB\n";
    if (!o.report.empty()) rad::writeTextFile(o.report, j.dump(1) + "\n");
    return 0;
  });
}
