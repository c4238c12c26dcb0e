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
#include "tools/stages/movie_sequence.h"

namespace {

constexpr const char* kTool = "rad-movies";

struct Options {
  std::string scene, global, intervals, outDir;
  rad::TextureMovieBakerOptions baker;  // bound to the flags; its toJson() is the provenance
  std::string preset;                   // --preset, recorded beside the values it set
  std::string shard = "0/1";
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
  addDeprecatedOptions(app, b);
  if (int rc = rad::parseCommandLine(app, kTool, argc, argv); rc >= 0) return rc;
  return rad::runTool(kTool, [&]() { return run(o, argc, argv); });
}
