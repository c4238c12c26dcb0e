// rad-reference: independent Monte Carlo path-traced frames of a scene (issue 7), the
// "converged reference" of DESIGN.md §8 that rad-diff compares the pipeline's frames with.
// Shares only the scene loader and the camera with the pipeline (see libcommon/reference/path_tracer.h).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include <nlohmann/json.hpp>

#include "formats/exr_image.h"
#include "formats/gltf_scene.h"
#include "formats/provenance.h"
#include "libcommon/reference/path_tracer.h"
#include "tools/common/tool_main.h"

namespace {

constexpr const char* kTool = "rad-reference";

struct Options {
  std::string scene, outDir, frames, size = "352x240", camera;
  double fps = 24.0;
  int spp = 256, maxDepth = 64;
  std::uint64_t seed = 0;
  bool decorrelateFrames = false;
  bool pixelCentres = false;
};

int run(const Options& o, int argc, char** argv) {
  rad::Scene scene = rad::readGltfScene(o.scene);
  const int cameraNode = scene.cameraNode(o.camera);
  if (cameraNode < 0)
    throw rad::inputError(
        o.scene, o.camera.empty() ? "has no camera" : "has no camera named '" + o.camera + "'");
  const auto [width, height] = rad::parseImageSize(o.size);
  const rad::ImageSize size{width, height};
  std::vector<int> frames;
  if (o.frames.empty()) {
    const int last = int(std::floor(scene.endTime() * o.fps + 1e-9));
    for (int f = 0; f <= std::max(0, last); ++f) frames.push_back(f);
  } else {
    frames = rad::parseFrameRange(o.frames);
  }

  nlohmann::json parameters = {{"frames", o.frames.empty() ? "all" : o.frames},
                               {"fps", o.fps},
                               {"size", o.size},
                               {"spp", o.spp},
                               {"camera", o.camera},
                               {"max-depth", o.maxDepth},
                               {"seed", o.seed},
                               {"decorrelate-frames", o.decorrelateFrames},
                               {"pixel-centres", o.pixelCentres}};
  rad::Provenance provenance = rad::makeProvenance(kTool, argc, argv, parameters);
  rad::addInput(provenance, o.scene);
  const std::string provenanceJson = provenance.toJson().dump();

  std::error_code ec;
  std::filesystem::create_directories(o.outDir, ec);
  if (ec) throw rad::outputError(o.outDir, "cannot create directory: " + ec.message());

  rad::PathTracerOptions options;
  options.samplesPerPixel = o.spp;
  options.maxDepth = o.maxDepth;
  options.seed = o.seed;
  options.decorrelateFrames = o.decorrelateFrames;
  options.pixelCentres = o.pixelCentres;

  rad::PathTracer tracer(scene, frames.empty() ? 0.0 : frames.front() / o.fps);
  rad::Progress progress("rad-reference", long(frames.size()));
  double total = 0.0;
  for (int frame : frames) {
    const auto start = std::chrono::steady_clock::now();
    const double t = frame / o.fps;  // DESIGN.md §4: frame f is at f / fps
    tracer.setTime(t);
    const rad::CameraView view = scene.cameraAt(cameraNode, t);
    rad::FloatImage image = tracer.render(view, size, options, frame);
    char name[32];
    std::snprintf(name, sizeof name, "%04d.exr", frame);
    const std::string path = (std::filesystem::path(o.outDir) / name).string();
    rad::writeExrImage(path, image,
                       {{"rad.provenance", provenanceJson},
                        {"rad.units", "radiance W/(m^2 sr), linear"},
                        {"rad.frame", std::to_string(frame)},
                        {"rad.time", std::to_string(t)}});
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    total += seconds;
    progress.advance();
    std::cout << path << ": frame " << frame << " t=" << t << " s, " << o.spp << " spp, " << seconds
              << " s\n"
              << std::flush;
  }
  progress.done();
  if (frames.size() > 1)
    std::cout << frames.size() << " frames, " << total / double(frames.size()) << " s per frame\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Path-traces reference frames of a glTF scene (Lambertian surfaces, area emitters, "
      "next-event estimation): OUTDIR/NNNN.exr, linear RGB radiance."};
  Options o;
  rad::setUpApp(app, kTool,
                "rad-reference scene.gltf -o ref --frames 0-23 --size 176x120 --spp 256");
  app.add_option("SCENE", o.scene, "glTF 2.0 scene (.gltf or .glb)")->required();
  app.add_option("-o,--output", o.outDir, "output directory for NNNN.exr frames")->required();
  app.add_option("--frames", o.frames, "frame range a-b (default: the whole animation)");
  app.add_option("--fps", o.fps, "frames per second")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--size", o.size, "image size WxH")->capture_default_str();
  app.add_option("--spp", o.spp, "samples per pixel")
      ->capture_default_str()
      ->check(CLI::Range(1, 1 << 24));
  app.add_option("--camera", o.camera, "camera node or camera name (default: the first)");
  app.add_option("--max-depth", o.maxDepth, "maximum number of reflections per path")
      ->capture_default_str()
      ->check(CLI::Range(0, 100000));
  app.add_option("--seed", o.seed, "random seed")->capture_default_str();
  app.add_flag("--pixel-centres", o.pixelCentres,
               "every sample through the pixel centre (no antialiasing), as rad-compose samples");
  app.add_flag("--decorrelate-frames", o.decorrelateFrames,
               "independent noise per frame (default: the same per-pixel seeds every frame, so "
               "what does not change does not flicker)");
  if (int rc = rad::parseCommandLine(app, kTool, argc, argv); rc >= 0) return rc;
  return rad::runTool(kTool, [&]() { return run(o, argc, argv); });
}
