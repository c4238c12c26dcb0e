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
#include "libcommon/movies/movies_options.h"
#include "libcommon/movies/texture_movie_baker.h"
#include "libcommon/scene/scene_digest.h"
#include "tools/common/made_from_scene.h"
#include "tools/common/parameter_cli.h"
#include "tools/common/tool_main.h"
#include "tools/stages/movie_pieces.h"
#include "tools/stages/movie_sequence.h"

namespace {

constexpr const char* kTool = "rad-movies";

struct Options {
  std::string scene, global, intervals, outDir;
  rad::TextureMovieBakerOptions baker;  // bound to the flags; its toJson() is the provenance
  std::string preset;                   // --preset, recorded beside the values it set
  std::string shard = "0/1";
  int pieceKeys = 0;        // --piece-keys: render farm pieces (tools/stages/movie_pieces.h)
  int mergePieces = 0;      // --merge-pieces: join the pieces of that size instead of baking
  bool mergeReady = false;  // --merge-ready: only the movies whose pieces are all written
  // --piece-costs, --piece-seconds: the cut by an earlier run's costs (tools/stages/movie_cut.h).
  std::vector<std::string> pieceCosts;
  double pieceSeconds = 4.0;
  std::string report;
};

// The old spellings: --key-step (now --movie-key-step) and --merge (now --occlusion-merge: one
// flag name means one thing across the tools, and rad-global's --merge joins key windows). Each
// prints one warning line and sets what the new one sets.
void addDeprecatedOptions(CLI::App& app, rad::TextureMovieBakerOptions& b) {
  const auto& table = rad::moviesParameters();
  for (const auto& [oldFlag, name] :
       {std::pair<std::string, std::string>{"key-step", "movie-key-step"},
        {"merge", "occlusion-merge"}}) {
    const rad::Parameter<rad::TextureMovieBakerOptions>* p = table.find(name);
    CLI::Option* opt = app.add_option_function<std::string>(
                              "--" + oldFlag,
                              [p, &b, oldFlag = oldFlag](const std::string& s) {
                                rad::warnDeprecated(kTool, "--" + oldFlag, "--" + p->name);
                                p->set(b, s);
                              },
                              "deprecated name of --" + name)
                           ->type_name(p->typeName)
                           ->excludes(app.get_option("--" + name))
                           ->group("Deprecated");
    if (!p->choices.empty())
      opt->check(CLI::IsMember(p->choices));
    else
      opt->check(rad::validatorOf(p->check, p->typeName));
  }
}

// --merge-pieces: the pieces of --piece-keys tasks joined into their movies (movie_pieces.h).
// The cut of the movies into pieces: by keys (K), or by an earlier run's costs.
rad::MovieCut movieCut(const Options& o, int pieceKeys) {
  return o.pieceCosts.empty() ? rad::MovieCut(pieceKeys)
                              : rad::MovieCut::fromReports(o.pieceCosts, o.pieceSeconds, pieceKeys);
}

int mergePieces(const Options& o, const rad::TextureMovieBaker& baker,
                const rad::TextureIntervals& intervals, const rad::Provenance& provenance,
                const nlohmann::json& parameters, rad::SteadyClock::time_point start) {
  const rad::MovieShard shard = rad::MovieShard::parse(o.shard);
  const rad::MoviePieceMergeReport merged =
      o.mergeReady ? rad::mergeReadyMoviePieces(baker, intervals, o.outDir,
                                                movieCut(o, o.mergePieces), provenance, shard)
                   : rad::mergeMoviePieces(baker, intervals, o.outDir, movieCut(o, o.mergePieces),
                                           provenance, shard);
  std::cerr << kTool << ": merged " << merged.moviesMerged << " movies from " << merged.piecesRead
            << " pieces\n";
  if (!o.report.empty()) {
    nlohmann::json report;
    report["tool"] = kTool;
    report["merge_pieces"] = o.mergePieces;
    report["merge_ready"] = o.mergeReady;
    report["shard"] = o.shard;
    report["movies_merged"] = merged.moviesMerged;
    report["pieces_read"] = merged.piecesRead;
    report["parameters"] = parameters;
    report["seconds"]["merge"] = merged.seconds;
    report["seconds"]["total"] = rad::secondsSince(start);
    report["peak_memory_mb"] = rad::peakMemoryMb();
    rad::writeTextFile(o.report, report.dump(1) + "\n");
  }
  return 0;
}

int run(Options o, int argc, char** argv) {
  auto start = rad::SteadyClock::now();
  const rad::MovieShard shard = rad::MovieShard::parse(o.shard);
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
  parameters["preset"] = o.preset;
  // A merge's movies are the one-task bake's, whichever share of them it merges.
  parameters["shard"] = o.mergePieces > 0 ? std::string("0/1") : o.shard;
  parameters["output"] = o.outDir;
  parameters[rad::kSceneDigestsKey] =
      rad::sceneDigests(scene, {rad::ScenePart::kGeometry, rad::ScenePart::kMaterials,
                                rad::ScenePart::kLights, rad::ScenePart::kAnimation});
  // A merge records the command line without --merge-pieces: the whole bake's, byte for byte.
  const std::vector<std::string> words = o.mergePieces > 0
                                             ? rad::argumentsWithoutMergePieces(argc, argv)
                                             : std::vector<std::string>(argv, argv + argc);
  std::vector<const char*> args;
  for (const std::string& w : words) args.push_back(w.c_str());
  rad::Provenance provenance =
      rad::makeProvenance(kTool, int(args.size()), args.data(), parameters);
  rad::addInput(provenance, o.scene);
  provenance.inputs.push_back(std::move(globalInput));
  provenance.inputs.push_back(std::move(intervalsInput));

  rad::TextureMovieBakerBackends backends;
  backends.formFactorSpill = rad::formFactorScratchFiles();
  rad::TextureMovieBaker baker(scene, solution, intervals.fps, o.baker, backends);
  if (o.mergePieces > 0) return mergePieces(o, baker, intervals, provenance, parameters, start);
  const std::vector<rad::MovieWork> work =
      rad::shardWork(intervals, shard, movieCut(o, o.pieceKeys), baker);
  rad::Progress progress(kTool, long(work.size()));
  const rad::MovieSequenceReport written = rad::bakeMovieSequence(
      baker, work, {o.intervals, o.outDir}, provenance, [&] { progress.advance(); });
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
    // [[movie id, seconds], ...] of the whole movies, and of each movie or piece baked its keys
    // and planning seconds (pipelines/farm_model.py cuts movies into pieces with them).
    nlohmann::json movieSeconds = nlohmann::json::array(), work = nlohmann::json::array();
    for (const rad::MovieWorkSeconds& w : written.workSeconds) {
      if (w.piece < 0) movieSeconds.push_back({w.movie, w.seconds});
      work.push_back({{"movie", w.movie},
                      {"piece", w.piece},
                      {"keys", w.keys},
                      {"movie_keys", w.movieKeys},
                      {"texels", w.texels},
                      {"seconds", w.seconds},
                      {"seconds_plan", w.secondsPlan}});
    }
    report["movie_seconds"] = movieSeconds;
    report["work_seconds"] = work;
    report["pieces_baked"] = written.piecesBaked;
    report["piece_keys"] = o.pieceKeys;
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
  const std::string preset = rad::addPresetOption(app, o.preset, argc, argv);
  rad::moviesParameters().apply(b, rad::findPreset(rad::moviesPresets(), preset).values);
  const std::string common = rad::parameterGroupTitle(rad::ParameterGroup::kCommon);
  app.add_option("SCENE", o.scene, "glTF 2.0 scene (.gltf/.glb)")->required();
  app.add_option("GLOBAL", o.global, "global solution (global.rlh from rad-global)")->required();
  app.add_option("INTERVALS", o.intervals, "texture-movie intervals (intervals.rti)")->required();
  app.add_option("-o,--output", o.outDir, "directory for the movies (NNNNNN.exr)")
      ->required()
      ->group(common);
  rad::bindParameters(app, rad::moviesParameters(), b);
  app.add_option("--shard", o.shard, "bake only movies with id % n == i")
      ->capture_default_str()
      ->group(common);
  app.add_option("--report", o.report, "write timings and counts as JSON to this file")
      ->group(common);
  // The render farm (issue 58): a long movie's keys in pieces side by side, then one merge.
  const std::string farm = "Render farm";
  auto* pieces =
      app.add_option("--piece-keys", o.pieceKeys,
                     "render farm: bake a movie of more than K keys as pieces of at "
                     "most K keys, every movie's pieces dealt to the shards in order, each to "
                     "its own piece file (NNNNNN.piece-PPPP.exr) for --merge-pieces; "
                     "each piece plans the movie again (its static shadows too)")
          ->type_name("K")
          ->check(rad::nonNegativeInteger())
          ->capture_default_str()
          ->group(farm);
  auto* mergePieces =
      app.add_option(
             "--merge-pieces", o.mergePieces,
             "render farm: instead of baking, join the pieces that --piece-keys K runs of this "
             "same command line wrote into their movies (with --shard i/n, those with id % n "
             "== i): the same bytes as the run without --merge-pieces, provenance included")
          ->type_name("K")
          ->check(rad::positiveInteger())
          ->excludes(pieces)
          ->group(farm);
  app.add_flag("--merge-ready", o.mergeReady,
               "render farm: with --merge-pieces K --shard i/n, run in the task that baked "
               "--piece-keys K --shard i/n after it: join only the movies of which that shard "
               "baked a piece and whose pieces are all written, each under a lock "
               "(NNNNNN.merge-lock); the task that writes a movie's last piece joins it")
      ->needs(mergePieces)
      ->group(farm);
  app.add_option("--piece-costs", o.pieceCosts,
                 "render farm: cut by known cost instead: the --report files of an earlier run "
                 "of these movies (one a flag); a movie that took more than --piece-seconds is "
                 "cut into pieces of about that cost, the others baked whole (movies they do "
                 "not name: --piece-keys), every unit dealt to the shards longest first; give "
                 "the same files to --merge-pieces")
      ->type_name("REPORT")
      ->allow_extra_args(false)
      ->group(farm);
  app.add_option("--piece-seconds", o.pieceSeconds,
                 "render farm: with --piece-costs, the seconds of work a piece aims at")
      ->type_name("T")
      ->check(CLI::PositiveNumber)
      ->capture_default_str()
      ->group(farm);
  addDeprecatedOptions(app, b);
  if (int rc = rad::parseCommandLine(app, kTool, argc, argv); rc >= 0) return rc;
  return rad::runTool(kTool, [&]() { return run(o, argc, argv); });
}
