// rad-intervals: texture-movie extents from per-frame item buffers (paper §4.1, §4.3;
// docs/design.md §6.2 rad-intervals). The options are libcommon/intervals/intervals_options.h, the
// algorithm libcommon/intervals/texture_intervals_builder.h, the frame loop
// tools/stages/interval_sequence.h; this main parses, calls them, writes intervals.rti and reports.
#include <cstdio>
#include <vector>

#include "formats/atomic_file.h"
#include "formats/container.h"
#include "formats/gltf_scene.h"
#include "formats/provenance.h"
#include "formats/texture_intervals.h"
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

int run(const rad::IntervalsOptions& given, const std::string& preset, int argc, char** argv) {
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
  rad::Provenance provenance = rad::makeProvenance(kTool, argc, argv, parameters);
  rad::addInput(provenance, o.scene);
  rad::Progress progress(kTool, long(frames.size()));
  rad::IntervalSequence sequence =
      rad::computeIntervalSequence(scene, camera, frames, o.build, o.itemBuffers,
                                   provenance.toJson().dump(), [&]() { progress.advance(); });
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
  // A preset sets nothing here (README "Recommended settings"); it is taken so one --preset
  // goes to every stage, and recorded.
  rad::addPresetOption(app, preset, argc, argv);
  const std::string common = rad::parameterGroupTitle(rad::ParameterGroup::kCommon);
  app.add_option("SCENE", o.scene, "glTF 2.0 scene (.gltf or .glb)")->required();
  app.add_option("-o,--output", o.output, "output intervals file (.rti)")
      ->required()
      ->group(common);
  rad::bindParameters(app, rad::intervalsParameters(), o);
  app.add_option("--report", o.report, "write a JSON report (times, movies, texels) to FILE")
      ->group(common);
  if (int rc = rad::parseCommandLine(app, kTool, argc, argv); rc >= 0) return rc;
  return rad::runTool(kTool, [&]() { return run(o, preset, argc, argv); });
}
