// rad-intervals: texture-movie extents from per-frame item buffers (paper §4.1, §4.3;
// DESIGN.md §6 rad-intervals). The algorithm is libcommon/intervals/texture_intervals_builder.h; this
// main parses, reads the scene, runs the frames, writes intervals.rti and reports.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "formats/atomic_file.h"
#include "formats/container.h"
#include "formats/gltf_scene.h"
#include "formats/item_buffer_exr.h"
#include "formats/provenance.h"
#include "formats/texture_intervals.h"
#include "libcommon/intervals/texture_intervals_builder.h"
#include "tools/common/tool_main.h"

namespace {

constexpr const char* kTool = "rad-intervals";

struct Options {
  std::string scene;
  std::string output;
  std::string frames;  // empty: 0 .. the animation's end at --fps
  std::string size = "352x240";
  std::string camera;
  std::string itemBuffers;
  std::string report;
  rad::TextureIntervalsOptions build;
};

nlohmann::json parametersOf(const Options& o, const std::string& frames) {
  const rad::TextureIntervalsOptions& b = o.build;
  return {{"frames", frames},
          {"fps", b.fps},
          {"size", o.size},
          {"camera", o.camera},
          {"item-buffers", o.itemBuffers},
          {"max-level", b.maxLevel},
          {"min-visible-fraction", b.minVisibleFraction},
          {"level-hysteresis", b.levelHysteresis},
          {"texel-density", b.texelDensity},
          {"min-size", b.minSize},
          {"max-size", b.maxSize},
          {"resize-tolerance", b.resizeTolerance},
          {"max-length", b.maxLength}};
}

int run(const Options& given, int argc, char** argv) {
  Options o = given;
  auto [w, h] = rad::parseImageSize(o.size);
  o.build.imageSize = {w, h};
  o.build.validate();
  rad::Scene scene = rad::readGltfScene(o.scene);
  int camera = scene.cameraNode(o.camera);
  if (camera < 0)
    throw rad::inputError(o.scene,
                          o.camera.empty() ? "no camera" : "no camera named '" + o.camera + "'");
  std::string frameSpec = o.frames;
  if (frameSpec.empty())
    frameSpec = "0-" + std::to_string(std::max(0L, std::lround(scene.endTime() * o.build.fps)));
  std::vector<int> frames = rad::parseFrameRange(frameSpec);
  if (frames.empty()) throw rad::Error(rad::ExitCode::kUsage, "", "--frames: no frames");
  for (size_t i = 1; i < frames.size(); ++i)
    if (frames[i] <= frames[i - 1])
      throw rad::Error(rad::ExitCode::kUsage, "", "--frames: frames must increase");

  rad::Provenance provenance = rad::makeProvenance(kTool, argc, argv, parametersOf(o, frameSpec));
  rad::addInput(provenance, o.scene);
  std::string provenanceJson = provenance.toJson().dump();
  if (!o.itemBuffers.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(o.itemBuffers, ec);
    if (ec) throw rad::outputError(o.itemBuffers, ec.message());
  }

  auto start = std::chrono::steady_clock::now();
  rad::TextureIntervalsBuilder builder(scene, camera, o.build);
  double setupSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::vector<double> itemSeconds;
  rad::Progress progress(kTool, long(frames.size()));
  for (int f : frames) {
    builder.addFrame(f, [&](const rad::IntervalFrame& fr) {
      itemSeconds.push_back(fr.itemBufferSeconds);
      if (o.itemBuffers.empty()) return;
      char name[32];
      std::snprintf(name, sizeof name, "/%04d.exr", fr.frame);
      rad::writeItemBufferExr(o.itemBuffers + name, *fr.itemBuffer, fr.frame, fr.time,
                              provenanceJson);
    });
    progress.advance();
  }
  progress.done();
  std::vector<rad::MovieExtent> extents = builder.finish();
  double totalSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  rad::TextureIntervals iv;
  iv.firstFrame = frames.front();
  iv.lastFrame = frames.back();
  iv.fps = o.build.fps;
  iv.imageWidth = w;
  iv.imageHeight = h;
  iv.movies = extents;  // one record: finish() numbers them 0..n-1
  const rad::PatchHierarchy& ph = builder.hierarchy();
  nlohmann::json metadata = {{"top_patches", ph.topCount()},
                             {"patch_nodes", ph.size()},
                             {"max_level", o.build.maxLevel},
                             {"camera", scene.nodes[camera].name},
                             {"frame_step", frames.size() > 1 ? frames[1] - frames[0] : 1}};
  rad::writeTextureIntervals(o.output, iv, provenance, metadata);

  // The report summarises what was written (read back: also checks the file).
  nlohmann::json report = rad::summarizeTextureIntervals(rad::ContainerReader::open(o.output));
  int n = builder.framesAdded();
  report["output"] = o.output;
  report["frames"] = n;
  report["image_size"] = {w, h};
  report["top_patches"] = ph.topCount();
  report["patch_nodes"] = ph.size();
  report["item_buffer_ms_per_frame"] = 1e3 * builder.itemBufferSeconds() / n;
  // The first frame pays for shader compilation and driver warm-up: the median is the figure.
  std::sort(itemSeconds.begin(), itemSeconds.end());
  report["item_buffer_ms_median"] = 1e3 * itemSeconds[itemSeconds.size() / 2];
  report["item_buffer_ms_max"] = 1e3 * itemSeconds.back();
  report["setup_seconds"] = setupSeconds;
  report["total_seconds"] = totalSeconds;
  report["ms_per_frame"] = 1e3 * (totalSeconds - setupSeconds) / n;
  if (!o.report.empty()) rad::writeTextFile(o.report, report.dump(1) + "\n");
  std::fprintf(stderr,
               "%s: %d frames, %zu movies, mean length %.1f frames, %.0f texels/frame, "
               "item buffer %.2f ms/frame (median %.2f), %.2f ms/frame total\n",
               kTool, n, extents.size(), report["mean_length_frames"].get<double>(),
               report["texels_per_frame"].get<double>(),
               report["item_buffer_ms_per_frame"].get<double>(),
               report["item_buffer_ms_median"].get<double>(), report["ms_per_frame"].get<double>());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Computes texture-movie extents (which patch node gets a movie, from which frame "
      "to which, at what size) from per-frame item buffers (paper §4.1, §4.3)."};
  Options o;
  rad::setUpApp(app, kTool,
                "rad-intervals scene.gltf -o intervals.rti --frames 0-95 --fps 24 --size 352x240");
  app.add_option("SCENE", o.scene, "glTF 2.0 scene (.gltf or .glb)")->required();
  app.add_option("-o,--output", o.output, "output intervals file (.rti)")->required();
  app.add_option("--frames", o.frames,
                 "frame range a-b or a-bxstep (default: 0 to the animation's end)");
  app.add_option("--fps", o.build.fps, "frames per second; frame f is at time f/fps")
      ->capture_default_str();
  app.add_option("--size", o.size, "item buffer size WxH (the final frame size)")
      ->capture_default_str();
  app.add_option("--camera", o.camera, "camera node or camera name (default: the first)");
  app.add_option("--item-buffers", o.itemBuffers,
                 "also write each frame's item buffer to DIR/NNNN.exr (UINT id, FLOAT Z)");
  app.add_option("--report", o.report, "write a JSON report (times, movies, texels) to FILE");
  app.add_option("--max-level", o.build.maxLevel, "subdivision depth below the top-level patches")
      ->capture_default_str();
  app.add_option("--min-visible-fraction", o.build.minVisibleFraction,
                 "theta: below this visible fraction a patch is represented by its children")
      ->capture_default_str();
  app.add_option("--level-hysteresis", o.build.levelHysteresis,
                 "keep a patch's level while its visible fraction stays within this of theta")
      ->capture_default_str();
  app.add_option("--texel-density", o.build.texelDensity, "texels per covered pixel")
      ->capture_default_str();
  app.add_option("--min-size", o.build.minSize, "smallest texture side")->capture_default_str();
  app.add_option("--max-size", o.build.maxSize, "largest texture side")->capture_default_str();
  app.add_option("--resize-tolerance", o.build.resizeTolerance,
                 "keep a texture size while the ideal size is within a factor 1+tol of it")
      ->capture_default_str();
  app.add_option("--max-length", o.build.maxLength, "longest movie in frames (0 = no limit)")
      ->capture_default_str();
  if (int rc = rad::parseCommandLine(app, kTool, argc, argv); rc >= 0) return rc;
  return rad::runTool(kTool, [&]() { return run(o, argc, argv); });
}
