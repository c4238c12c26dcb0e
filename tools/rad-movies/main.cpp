// rad-movies: bakes the texture movies of intervals.rti from the global solution (paper §3.1
// transmittance textures, §5 frame-to-frame coherence; docs/design.md §6.3 "rad-movies"). The baker
// is libcommon/movies/texture_movie_baker.h, the shard loop and the movie files
// tools/stages/movie_sequence.h; this main parses, reads and checks the inputs, calls, reports.
#include <chrono>
#include <iostream>

#include "formats/atomic_file.h"
#include "formats/container.h"
#include "formats/form_factor_scratch_file.h"
#include "formats/frame_window.h"
#include "formats/gltf_scene.h"
#include "formats/link_hierarchy.h"
#include "formats/provenance.h"
#include "formats/texture_intervals.h"
#include "libcommon/core/stopwatch.h"
#include "libcommon/movies/texture_movie_baker.h"
#include "libcommon/scene/scene_digest.h"
#include "tools/common/made_from_scene.h"
#include "tools/common/tool_main.h"
#include "tools/stages/movie_sequence.h"

namespace {

constexpr const char* kTool = "rad-movies";

struct Options {
  std::string scene, global, intervals, outDir;
  rad::TextureMovieBakerOptions baker;  // bound to the flags; its toJson() is the provenance
  std::string merge = "exact";
  std::string goodLayer = "gather";
  std::string shard = "0/1";
  std::string report;
};

int run(Options o, int argc, char** argv) {
  auto start = rad::SteadyClock::now();
  const rad::MovieShard shard = rad::MovieShard::parse(o.shard);
  o.baker.merge = rad::parseMergeMode(o.merge);
  o.baker.goodLayer = rad::parseGoodLayer(o.goodLayer);
  rad::Scene scene = rad::readGltfScene(o.scene);
  rad::GlobalSolution solution;
  rad::InputRecord globalInput, intervalsInput;  // taken while the files' bytes are held
  {
    const rad::ContainerReader reader = rad::ContainerReader::open(o.global);
    rad::requireMadeFrom(reader, rad::kLinkHierarchyKind, rad::kLinkHierarchyMajor, scene);
    solution = rad::readLinkHierarchy(reader, scene);
    globalInput = rad::inputRecordOf(reader);
  }
  rad::TextureIntervals intervals;
  {
    const rad::ContainerReader reader = rad::ContainerReader::open(o.intervals);
    rad::requireMadeFrom(reader, rad::kTextureIntervalsKind, rad::kTextureIntervalsMajor, scene);
    intervals = rad::readTextureIntervals(reader);
    intervalsInput = rad::inputRecordOf(reader);
  }
  rad::requireGlobalCoversIntervals(o.global, solution, o.intervals, intervals);
  const double secondsRead = rad::secondsSince(start);

  nlohmann::json parameters = o.baker.toJson();
  parameters["shard"] = o.shard;
  parameters["output"] = o.outDir;
  parameters[rad::kSceneDigestsKey] =
      rad::sceneDigests(scene, {rad::ScenePart::kGeometry, rad::ScenePart::kMaterials,
                                rad::ScenePart::kLights, rad::ScenePart::kAnimation});
  rad::Provenance provenance = rad::makeProvenance(kTool, argc, argv, parameters);
  rad::addInput(provenance, o.scene);
  provenance.inputs.push_back(std::move(globalInput));
  provenance.inputs.push_back(std::move(intervalsInput));

  rad::TextureMovieBakerBackends backends;
  backends.formFactorSpill = rad::formFactorScratchFiles();
  rad::TextureMovieBaker baker(scene, solution, intervals.fps, o.baker, backends);
  rad::Progress progress(kTool, long(rad::shardMovies(intervals, shard).size()));
  const rad::MovieSequenceReport written = rad::bakeMovieSequence(
      baker, intervals, {o.intervals, o.outDir, shard}, provenance, [&] { progress.advance(); });
  progress.done();
  const rad::TextureMovieBakerStats& stats = baker.stats();
  for (const std::string& w : stats.warnings) std::cerr << kTool << ": warning: " << w << "\n";

  if (!o.report.empty()) {
    nlohmann::json report = stats.toJson();
    report["tool"] = kTool;
    report["shard"] = o.shard;
    report["movies_in_file"] = intervals.movies.size();
    report["parameters"] = parameters;
    report["renderer"] = written.rendererName;
    report["seconds"]["read"] = secondsRead;
    report["seconds"]["write"] = written.secondsWrite;
    report["seconds"]["total"] = rad::secondsSince(start);
    report["movie_seconds"] = written.movieSeconds;  // [[movie id, seconds], ...]
    report["peak_memory_mb"] = rad::peakMemoryMb();
    rad::writeTextFile(o.report, report.dump(1) + "\n");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Bakes the texture movies of intervals.rti: per key frame the good-link irradiance of the "
      "global solution plus every bad link's shooter radiosity x form factor x transmittance "
      "(projective shadows with OSMesa; static blockers rendered once per movie)."};
  Options o;
  rad::TextureMovieBakerOptions& b = o.baker;
  rad::setUpApp(app, kTool,
                "rad-movies scene.gltf out/global.rlh out/intervals.rti -o out/movies "
                "--movie-key-step 6 --report out/movies.json");
  app.add_option("SCENE", o.scene, "glTF 2.0 scene (.gltf/.glb)")->required();
  app.add_option("GLOBAL", o.global, "global solution (global.rlh from rad-global)")->required();
  app.add_option("INTERVALS", o.intervals, "texture-movie intervals (intervals.rti)")->required();
  app.add_option("-o,--output", o.outDir, "directory for the movies (NNNNNN.exr)")->required();
  CLI::Option* keyStep =
      app.add_option("--movie-key-step", b.keyStep, "frames between key textures of a movie")
          ->capture_default_str()
          ->check(rad::positiveInteger());
  app.add_option_function<int>(
         "--key-step",
         [&b](const int& step) {
           std::cerr << kTool << ": warning: --key-step is deprecated; use --movie-key-step\n";
           b.keyStep = step;
         },
         "deprecated name of --movie-key-step")
      ->check(rad::positiveInteger())
      ->excludes(keyStep)
      ->group("Deprecated");
  app.add_option("--moving-shadow-key-step", b.movingShadowKeyStep,
                 "frames between key textures of a movie whose bad links' shadows move (a "
                 "moving blocker in the shaft, or a moving end); 0: --movie-key-step")
      ->capture_default_str()
      ->check(rad::nonNegativeInteger());
  app.add_option("--min-samples", b.minSamples,
                 "shooter samples per bad link, at least (at most --max-samples)")
      ->capture_default_str();
  app.add_option("--weak-share", b.weakShare,
                 "a bad link giving less than this share of every texel's direct light takes a "
                 "quarter of --min-samples at least (0: off)")
      ->capture_default_str()
      ->check(rad::finiteRange(0.0, 1.0));
  app.add_option("--max-samples", b.maxSamples, "shooter samples per bad link, at most (<= 64)")
      ->capture_default_str();
  app.add_option("--samples-per-form-factor", b.samplesPerFormFactor,
                 "samples = this x the largest texel-to-shooter form factor (paper §3.1)")
      ->capture_default_str()
      ->check(rad::nonNegativeFinite());
  app.add_option("--merge", o.merge,
                 "static/dynamic occlusion merge: exact (bit masks ORed), or the approximate "
                 "max, sum, independent")
      ->capture_default_str()
      ->check(CLI::IsMember({"exact", "max", "sum", "independent"}));
  app.add_option("--ray-cast-budget", b.rayCastBudget,
                 "ray cast a pair's occlusion masks on the CPU while texels x samples is at most "
                 "this, else render them with OSMesa; 0: always OSMesa")
      ->capture_default_str()
      ->check(rad::nonNegativeFinite());
  app.add_option("--good-layer", o.goodLayer,
                 "indirect light of the good links: gather (per texel, exact point form factors "
                 "to each link's shooter) or gouraud (the global solution's vertex values, paper "
                 "§3.1)")
      ->capture_default_str()
      ->check(CLI::IsMember({"gather", "gouraud"}));
  app.add_option("--gather-shooter-ratio", b.gatherShooterRatio,
                 "gather: split a link's shooter into the parts of its sub-tree larger than "
                 "this times their distance to the receiver (0: no split)")
      ->capture_default_str()
      ->check(rad::nonNegativeFinite());
  app.add_option("--gather-rays", b.gatherRays,
                 "gather: shadow rays from each texel to a partly occluded link's shooter, "
                 "1..64 (0: the link's one visibility over its receiver)")
      ->capture_default_str();
  app.add_option("--gather-partial-share", b.gatherPartialShare,
                 "gather: a partly occluded link takes its visibility per texel when B F (1 - V) "
                 "is at least this share of what the texel gathers, or when the smaller ones "
                 "left on their V would sum to more than 10 shares (smaller: more links per "
                 "texel, slower; the final setting uses 0.001)")
      ->capture_default_str()
      ->check(rad::finiteRange(0.0, 1.0));
  app.add_option("--cluster-visibility-rays", b.clusterVisibilityRays,
                 "gather: rays from each texel to points on its top's far surfaces, whose open "
                 "share against the top's mean scales the cluster light, 0..64 (0: the top's "
                 "one value)")
      ->capture_default_str();
  app.add_option("--near-shooter-levels", b.nearShooterLevels,
                 "gather: split a near leaf shooter into up to 4^L cells, each with its radiosity "
                 "re-gathered at its centre from the leaf's links, 0..3 (0: the leaf's one "
                 "radiosity; the final setting uses 2)")
      ->capture_default_str();
  app.add_flag_callback(
      "--no-fill-covered", [&b] { b.fillCovered = false; },
      "leave the texels under a touching solid as they come out (~0) instead of giving them "
      "their exposed neighbours' values (the pixels beside a box's foot interpolate both)");
  app.add_flag_callback(
      "--no-coherence", [&b] { b.coherence = false; },
      "re-render every blocker and recompute every form factor at every key, store every "
      "key (the per-frame baseline)");
  app.add_option("--shard", o.shard, "bake only movies with id % n == i")->capture_default_str();
  app.add_option("--max-texture-memory", b.maxTextureMemoryMiB,
                 "MiB of working memory per movie: one key's texel buffers plus, per bad shooter "
                 "of a static pair, its form factors and static-blocker masks (independent of "
                 "the number of keys); a movie that needs more is refused (exit 4). The gather "
                 "keeps its per-texel form factors in half of it, else recomputes them per key")
      ->capture_default_str()
      ->check(rad::positiveFinite());
  app.add_option("--report", o.report, "write timings and counts as JSON to this file");
  if (int rc = rad::parseCommandLine(app, kTool, argc, argv); rc >= 0) return rc;
  return rad::runTool(kTool, [&]() { return run(o, argc, argv); });
}
