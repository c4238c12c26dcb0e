// rad-intervals: texture-movie extents from per-frame item buffers (paper §4.1, §4.3;
// docs/design.md §6.2 rad-intervals). The options are libcommon/intervals/intervals_options.h, the
// algorithm libcommon/intervals/texture_intervals_builder.h, the frame loop
// tools/stages/interval_sequence.h; this main parses, calls them, writes intervals.rti and reports.
#include <algorithm>
#include <cstdio>
#include <map>
#include <vector>

#include "formats/atomic_file.h"
#include "formats/container.h"
#include "formats/gltf_scene.h"
#include "formats/provenance.h"
#include "formats/texture_intervals.h"
#include "formats/visible_samples.h"
#include "libcommon/intervals/intervals_options.h"
#include "libcommon/scene/frame_range.h"
#include "libcommon/scene/scene_digest.h"
#include "tools/common/parameter_cli.h"
#include "tools/common/tool_main.h"
#include "tools/stages/interval_sequence.h"

namespace {

constexpr const char* kTool = "rad-intervals";

// --frames as strictly increasing frame numbers (the builder's contract).
std::vector<int> increasingFrames(const std::string& spec) {
  std::vector<int> frames = rad::parseFrameRange(spec);
  if (frames.empty()) throw rad::Error(rad::ExitCode::kUsage, "", "--frames: no frames");
  for (size_t i = 1; i < frames.size(); ++i)
    if (frames[i] <= frames[i - 1])
      throw rad::Error(rad::ExitCode::kUsage, "", "--frames: frames must increase");
  return frames;
}

void printSummary(const nlohmann::json& report, size_t movies) {
  std::fprintf(stderr,
               "%s: %d frames, %zu movies, mean length %.1f frames, %.0f texels/frame, "
               "item buffer %.2f ms/frame (median %.2f), %.2f ms/frame total\n",
               kTool, report["frames"].get<int>(), movies,
               report["mean_length_frames"].get<double>(), report["texels_per_frame"].get<double>(),
               report["item_buffer_ms_per_frame"].get<double>(),
               report["item_buffer_ms_median"].get<double>(), report["ms_per_frame"].get<double>());
}

// The render farm (docs/design.md §7): item buffers by windows of frames side by side, then the
// one sequential pass over their counts.
struct FarmOptions {
  std::string window;              // FIRST-LAST: write this window's visible samples to -o
  std::vector<std::string> merge;  // visible-samples files to read instead of drawing
};

// argv without --merge and its files: the merged intervals.rti carries the provenance of the
// run without --merge, byte for byte (the files are that run's item buffers, counted).
std::vector<const char*> argvWithoutMerge(int argc, char** argv) {
  std::vector<const char*> out;
  for (int i = 0; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--merge=", 0) == 0) continue;
    if (a == "--merge") {
      while (i + 1 < argc && argv[i + 1][0] != '-') ++i;
      continue;
    }
    out.push_back(argv[i]);
  }
  return out;
}

// Every frame of `frames` once, from files made with `parameters`.
std::vector<rad::VisibleSamplesFrame> readCounts(const std::vector<std::string>& files,
                                                 const nlohmann::json& parameters,
                                                 const std::vector<int>& frames) {
  std::map<int, rad::VisibleSamplesFrame> byFrame;
  for (const std::string& path : files) {
    rad::VisibleSamples v = rad::readVisibleSamples(path);
    if (v.parameters != parameters) {
      std::string differs = "the scene or parameters";
      for (auto it = parameters.begin(); it != parameters.end(); ++it)
        if (!v.parameters.contains(it.key()) || v.parameters.at(it.key()) != it.value()) {
          differs = it.key();
          break;
        }
      throw rad::inputError(path, "made with another " + differs + " than this run");
    }
    for (rad::VisibleSamplesFrame& f : v.frames) {
      const int frame = f.frame;
      if (!std::binary_search(frames.begin(), frames.end(), frame))
        throw rad::inputError(path, "frame " + std::to_string(frame) + " is not one of --frames");
      if (!byFrame.emplace(frame, std::move(f)).second)
        throw rad::inputError(path, "frame " + std::to_string(frame) + " is in another file too");
    }
  }
  std::vector<rad::VisibleSamplesFrame> out;
  for (int frame : frames) {
    auto it = byFrame.find(frame);
    if (it == byFrame.end())
      throw rad::Error(rad::ExitCode::kUsage, "",
                       "--merge: no file holds frame " + std::to_string(frame));
    out.push_back(std::move(it->second));
  }
  return out;
}

// --window FIRST-LAST: the frames of `frames` within it.
std::vector<int> windowFrames(const std::vector<int>& frames, const std::string& window) {
  const std::vector<int> bounds = rad::parseFrameRange(window);
  std::vector<int> out;
  for (int f : frames)
    if (f >= bounds.front() && f <= bounds.back()) out.push_back(f);
  if (out.empty())
    throw rad::Error(rad::ExitCode::kUsage, "", "--window " + window + ": none of --frames in it");
  return out;
}

int run(const rad::IntervalsOptions& given, const FarmOptions& farm, const std::string& preset,
        int argc, char** argv) {
  rad::IntervalsOptions o = given;
  auto [w, h] = rad::parseImageSize(o.size);
  o.build.imageSize = {w, h};
  o.build.sampling = o.sampling;
  o.build.validate();
  rad::Scene scene = rad::readGltfScene(o.scene);
  int camera = scene.cameraNode(o.camera);
  if (camera < 0)
    throw rad::inputError(o.scene,
                          o.camera.empty() ? "no camera" : "no camera named '" + o.camera + "'");
  if (o.frames.empty()) o.frames = rad::animationFrames(scene, o.build.fps).toString();
  const std::vector<int> frames = increasingFrames(o.frames);

  // The item buffers see the patches where the camera sees them: geometry, motion, camera.
  nlohmann::json parameters = o.toJson();
  parameters["preset"] = preset;
  parameters[rad::kSceneDigestsKey] = rad::sceneDigests(
      scene, {rad::ScenePart::kGeometry, rad::ScenePart::kAnimation, rad::ScenePart::kCamera});
  const std::vector<const char*> recorded = argvWithoutMerge(argc, argv);
  rad::Provenance provenance =
      rad::makeProvenance(kTool, int(recorded.size()), recorded.data(), parameters);
  rad::addInput(provenance, o.scene);
  if (!farm.window.empty()) {
    const std::vector<int> mine = windowFrames(frames, farm.window);
    rad::Progress progress(kTool, long(mine.size()));
    const rad::VisibleSamples counts = rad::computeVisibleSamples(
        scene, camera, mine, o.build, parameters, [&]() { progress.advance(); });
    progress.done();
    rad::writeVisibleSamples(o.output, counts, provenance);
    std::fprintf(stderr, "%s: window %s: %zu frames' visible samples in %s\n", kTool,
                 farm.window.c_str(), mine.size(), o.output.c_str());
    return 0;
  }
  rad::Progress progress(kTool, long(frames.size()));
  rad::IntervalSequence sequence =
      farm.merge.empty()
          ? rad::computeIntervalSequence(scene, camera, frames, o.build, o.itemBuffers,
                                         provenance.toJson().dump(), [&]() { progress.advance(); })
          : rad::computeIntervalSequence(scene, camera, frames, o.build,
                                         readCounts(farm.merge, parameters, frames),
                                         [&]() { progress.advance(); });
  progress.done();
  rad::writeTextureIntervals(o.output, sequence.intervals, provenance, sequence.metadata);

  // The report summarises what was written (read back: also checks the file).
  nlohmann::json report = rad::intervalSequenceReport(sequence, o.output);
  report["peak_memory_mb"] = rad::peakMemoryMb();  // of the process (getrusage), issue 16
  if (!o.report.empty()) rad::writeTextFile(o.report, report.dump(1) + "\n");
  printSummary(report, sequence.intervals.movies.size());
  if (!sequence.emptyFrames.empty())
    std::fputs(
        rad::emptyFramesWarning(kTool, sequence.emptyFrames.size(), sequence.emptyFrames.front(),
                                frames.size(), scene.cameras[scene.nodes[camera].camera])
            .c_str(),
        stderr);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Computes texture-movie extents (which patch node gets a movie, from which frame "
      "to which, at what size) from per-frame item buffers (paper §4.1, §4.3)."};
  rad::IntervalsOptions o;
  std::string preset;
  rad::setUpApp(app, kTool,
                "rad-intervals scene.gltf -o intervals.rti --frames 0-95 --fps 24 --size 352x240");
  rad::intervalsParameters().apply(
      o, rad::findPreset(rad::intervalsPresets(), rad::addPresetOption(app, preset, argc, argv))
             .values);
  const std::string common = rad::parameterGroupTitle(rad::ParameterGroup::kCommon);
  app.add_option("SCENE", o.scene, "glTF 2.0 scene (.gltf or .glb)")->required();
  app.add_option("-o,--output", o.output, "output intervals file (.rti)")
      ->required()
      ->group(common);
  rad::bindParameters(app, rad::intervalsParameters(), o);
  app.add_option("--report", o.report, "write a JSON report (times, movies, texels) to FILE")
      ->group(common);
  const std::string farmGroup = "Render farm";
  FarmOptions farm;
  auto* window =
      app.add_option("--window", farm.window,
                     "render farm: draw only the item buffers of the frames of --frames within "
                     "FIRST-LAST (put the whole run's --frames) and write their visible samples "
                     "to -o for --merge")
          ->type_name("FIRST-LAST")
          ->group(farmGroup);
  auto* merge =
      app.add_option("--merge", farm.merge,
                     "render farm: instead of drawing item buffers, read these --window files "
                     "(runs of this same command line that together hold every frame): the same "
                     "intervals.rti as the run without --merge, provenance included")
          ->type_name("WINDOW")
          ->excludes(window)
          ->group(farmGroup);
  app.get_option("--item-buffers")->excludes(window)->excludes(merge);
  if (int rc = rad::parseCommandLine(app, kTool, argc, argv); rc >= 0) return rc;
  return rad::runTool(kTool, [&]() { return run(o, farm, preset, argc, argv); });
}
