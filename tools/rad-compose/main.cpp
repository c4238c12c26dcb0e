// rad-compose: final frames from the texture movies (paper §3.1 last step; docs/design.md §6.4
// "rad-compose"). Reads the scene, the global solution, the intervals and the movies; writes
// FRAMES_DIR/NNNN.exr (linear radiance) and NNNN.png (sRGB). The options are
// libcommon/compose/compose_options.h; the work is in libcommon/compose/frame_composer.h and
// tools/stages/frame_sequence.h (the frame loop). This main parses, checks the inputs agree, fills
// in the defaults they give, calls the loop and reports.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <optional>
#include <utility>

#include "formats/atomic_file.h"
#include "formats/container.h"
#include "formats/frame_image.h"
#include "formats/frame_window.h"
#include "formats/gltf_scene.h"
#include "formats/link_hierarchy.h"
#include "formats/provenance.h"
#include "formats/texture_intervals.h"
#include "libcommon/compose/compose_options.h"
#include "tools/common/made_from_scene.h"
#include "tools/common/parameter_cli.h"
#include "tools/common/tool_main.h"
#include "tools/stages/frame_sequence.h"

namespace {

constexpr const char* kTool = "rad-compose";

// The loop's options for `o`, after filling in `o`'s defaults from the inputs so that
// o.toJson() records every value in effect: frames = the intervals' window, fps and size = the
// intervals', camera = the camera node's name.
rad::ComposeSequenceOptions resolve(rad::ComposeOptions& o, const rad::Scene& scene,
                                    const rad::TextureIntervals& intervals) {
  rad::ComposeSequenceOptions c;
  c.moviesDir = o.movies;
  c.framesDir = o.output;
  if (o.frames.empty()) {
    for (int f = intervals.firstFrame; f <= intervals.lastFrame; ++f) c.frames.push_back(f);
    o.frames = std::to_string(c.frames.front()) + "-" + std::to_string(c.frames.back());
  } else {
    c.frames = rad::parseFrameRange(o.frames);
  }
  c.fps = o.fps.value_or(intervals.fps);
  if (!(c.fps > 0.0)) throw rad::Error(rad::ExitCode::kUsage, "", "--fps must be positive");
  o.fps = c.fps;
  if (o.size.empty()) {
    c.size = {intervals.imageWidth, intervals.imageHeight};
  } else {
    auto [w, h] = rad::parseImageSize(o.size);
    c.size = {w, h};
  }
  if (c.size.width < 1 || c.size.height < 1)
    throw rad::inputError(o.intervals, "no image size; pass --size");
  o.size = std::to_string(c.size.width) + "x" + std::to_string(c.size.height);
  c.cameraNode = scene.cameraNode(o.camera);
  if (c.cameraNode < 0)
    throw rad::inputError(o.scene,
                          o.camera.empty() ? "no camera" : "no camera named '" + o.camera + "'");
  o.camera = scene.nodes[c.cameraNode].name;
  c.autoExposure = o.autoExposure;
  c.exposureEV = o.exposure.value_or(0.0);
  c.half = o.half;
  c.compression = rad::frameCompressionOf(o.compression);
  c.png = !o.noPng;
  // The pixel sampling: the intervals' unless given (their item buffers saw its samples).
  c.sampling.filter.type = o.pixelFilter.value_or(intervals.sampling.filter.type);
  c.sampling.filter.width = o.filterWidth.value_or(intervals.sampling.filter.width);
  c.sampling.samplesPerAxis = o.pixelSamples.value_or(intervals.sampling.samplesPerAxis);
  c.sampling.validate();
  o.pixelFilter = c.sampling.filter.type;
  o.filterWidth = c.sampling.filter.width;
  o.pixelSamples = c.sampling.samplesPerAxis;
  c.everySample = o.everySample;
  c.edgeCoverage = o.edgeCoverage;
  c.edgeContrast = o.edgeContrast;
  return c;
}

// The movies were sized and timed for the intervals' image, fps and camera: say so when this
// run differs (still allowed: a quick preview at another size is legitimate).
void warnAboutDifferences(const rad::ComposeSequenceOptions& c, const std::string& givenCamera,
                          const std::string& intervalsPath, const rad::ContainerReader& reader,
                          const rad::TextureIntervals& intervals) {
  if (c.size != rad::ImageSize{intervals.imageWidth, intervals.imageHeight})
    std::cerr << kTool << ": warning: composing at " << c.size.width << "x" << c.size.height << "; "
              << intervalsPath << " sized the movies for " << intervals.imageWidth << "x"
              << intervals.imageHeight << "\n";
  // A sample the intervals' item buffers did not see may lie in no movie (then it falls back to
  // the global solution, and the frame's warning counts it).
  if (c.size == rad::ImageSize{intervals.imageWidth, intervals.imageHeight} &&
      !rad::PixelSampling::covers(intervals.sampling.grid(c.size), c.sampling.grid(c.size)))
    std::cerr << kTool << ": warning: sampling " << c.sampling.toString() << "; " << intervalsPath
              << " decided the movies' coverage for " << intervals.sampling.toString()
              << ": samples it did not see may fall back to the global solution\n";
  if (c.fps != intervals.fps)
    std::cerr << kTool << ": warning: --fps " << c.fps << "; " << intervalsPath
              << " was built with " << intervals.fps << " fps\n";
  const nlohmann::json& built = reader.provenance().parameters;
  if (!givenCamera.empty() && built.contains("camera"))
    for (const std::string& m :
         rad::parameterMismatch(built, {{"camera", givenCamera}}, {"camera"}))
      std::cerr << kTool << ": warning: " << intervalsPath << ": " << m << "\n";
}

// Frames in which no pixel shows a surface: black frames.
std::vector<int> emptyFrames(const rad::ComposeSequenceReport& report) {
  std::vector<int> empty;
  for (const rad::ComposeFrameStats& f : report.frames)
    if (f.coveredPixels == 0) empty.push_back(f.frame);
  return empty;
}

int run(const rad::ComposeOptions& given, const std::string& preset, int argc, char** argv) {
  const auto start = std::chrono::steady_clock::now();
  rad::ComposeOptions o = given;
  rad::Scene scene = rad::readGltfScene(o.scene);
  // Of global.rlh only the radiosity (fallback pixels, auto exposure) is kept, and the file's bytes
  // are released once read; otherwise the file and a copy of its links and F·V samples would be
  // held for the whole sequence.
  rad::GlobalSolution solution;
  rad::InputRecord globalInput;  // taken while the file's bytes are held
  {
    rad::ContainerReader globalReader = rad::ContainerReader::open(o.global);
    rad::requireMadeFrom(globalReader, rad::kLinkHierarchyKind, rad::kLinkHierarchyMajor, scene);
    solution = rad::readLinkHierarchyRadiosity(globalReader, scene);
    globalInput = rad::inputRecordOf(globalReader);
  }
  rad::ContainerReader intervalsReader = rad::ContainerReader::open(o.intervals);
  rad::requireMadeFrom(intervalsReader, rad::kTextureIntervalsKind, rad::kTextureIntervalsMajor,
                       scene);
  rad::TextureIntervals intervals = rad::readTextureIntervals(intervalsReader);
  rad::requireGlobalCoversIntervals(o.global, solution, o.intervals, intervals);

  const rad::ComposeSequenceOptions c = resolve(o, scene, intervals);
  nlohmann::json parameters = o.toJson();
  parameters["preset"] = preset;
  rad::Provenance provenance = rad::makeProvenance(kTool, argc, argv, parameters);
  rad::addInput(provenance, o.scene);
  provenance.inputs.push_back(std::move(globalInput));
  rad::addInput(provenance, intervalsReader);
  rad::UsedMovies movies = rad::readUsedMovies(intervals, o.movies, c.frames);
  rad::addMoviesInput(provenance, o.movies, movies);
  rad::requireMoviesMadeFrom(provenance.inputs.back(), scene);
  warnAboutDifferences(c, given.camera, o.intervals, intervalsReader, intervals);

  // What every farm chunk pays before its first frame (pipelines/farm_model.py's compose_fixed):
  // the scene, global.rlh, intervals.rti and the used movies' headers read, the provenance made.
  const double inputSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  rad::Progress progress(kTool, long(c.frames.size()));
  auto warn = [&](const std::string& message) {
    if (rad::stderrIsTerminal()) std::fprintf(stderr, "\r\033[K");
    std::cerr << kTool << ": " << message << "\n";
  };
  rad::ComposeSequenceReport report =
      rad::composeSequence(scene, solution, intervals, c, provenance, std::move(movies), warn,
                           [&]() { progress.advance(); });
  progress.done();
  if (o.autoExposure)
    std::cerr << kTool << ": auto exposure " << report.exposureEV << " EV for all frames\n";
  const std::vector<int> empty = emptyFrames(report);
  if (!empty.empty())
    std::cerr << rad::emptyFramesWarning(kTool, empty.size(), empty.front(), report.frames.size(),
                                         scene.cameras[scene.nodes[c.cameraNode].camera]);
  if (!o.report.empty()) {
    nlohmann::json j = report.toJson();
    j["empty_frames"] = empty.size();
    j["seconds_inputs"] = inputSeconds;
    j["provenance"] = provenance.toJson();
    j["peak_memory_mb"] = rad::peakMemoryMb();  // of the process (getrusage), issue 16
    rad::writeTextFile(o.report, j.dump(1) + "\n");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Composes the final frames: each visible patch textured with its texture movie's\n"
      "irradiance H at the frame's time, L = Le + rho/pi H (paper §3.1); pixels no movie\n"
      "covers fall back to the global solution (counted in a warning). Writes FRAMES_DIR/\n"
      "NNNN.exr (linear radiance, W/(m^2 sr)) and NNNN.png (sRGB, exposure applied)."};
  rad::ComposeOptions o;
  rad::setUpApp(app, kTool,
                "rad-compose scene.gltf out/global.rlh out/intervals.rti out/movies -o out/frames "
                "--frames 0-95 --auto-exposure");
  std::string preset;
  rad::composeParameters().apply(
      o,
      rad::findPreset(rad::composePresets(), rad::addPresetOption(app, preset, argc, argv)).values);
  const std::string common = rad::parameterGroupTitle(rad::ParameterGroup::kCommon);
  app.add_option("SCENE", o.scene, "glTF 2.0 scene (.gltf or .glb)")->required();
  app.add_option("GLOBAL", o.global, "global solution from rad-global (global.rlh)")->required();
  app.add_option("INTERVALS", o.intervals, "texture-movie extents from rad-intervals (.rti)")
      ->required();
  app.add_option("MOVIES_DIR", o.movies, "texture movies from rad-movies (MMMMMM.exr)")->required();
  app.add_option("-o,--output", o.output, "output directory for NNNN.exr / NNNN.png (created)")
      ->required()
      ->group(common);
  rad::bindParameters(app, rad::composeParameters(), o);
  app.get_option("--auto-exposure")->excludes(app.get_option("--exposure"));
  app.add_option("--report", o.report, "write per-frame times and fallback pixel counts as JSON")
      ->group(common);
  if (int rc = rad::parseCommandLine(app, kTool, argc, argv); rc >= 0) return rc;
  return rad::runTool(kTool, [&]() { return run(o, preset, argc, argv); });
}
