#include "tools/stages/reference_sequence.h"

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "formats/exr_image.h"
#include "libcommon/core/error.h"

namespace rad {

void renderReferenceSequence(const Scene& scene, int cameraNode, ImageSize size,
                             const std::vector<int>& frames, const ReferenceOptions& options,
                             const std::string& provenanceJson,
                             const std::function<void(const ReferenceFrame&)>& frameDone) {
  std::error_code ec;
  std::filesystem::create_directories(options.output, ec);
  if (ec) throw outputError(options.output, "cannot create directory: " + ec.message());

  const PathTracerOptions tracing = options.pathTracer();
  PathTracer tracer(scene, frames.empty() ? 0.0 : frames.front() / options.fps);
  for (int frame : frames) {
    const auto start = std::chrono::steady_clock::now();
    const double t = frame / options.fps;  // docs/design.md §4: frame f is at f / fps
    tracer.setTime(t);
    const CameraView view = scene.cameraAt(cameraNode, t);
    FloatImage image = tracer.render(view, size, tracing, frame);
    char name[32];
    std::snprintf(name, sizeof name, "%04d.exr", frame);
    const std::string path = (std::filesystem::path(options.output) / name).string();
    writeExrImage(path, image,
                  {{"rad.provenance", provenanceJson},
                   {"rad.units", "radiance W/(m^2 sr), linear"},
                   {"rad.frame", std::to_string(frame)},
                   {"rad.time", std::to_string(t)}});
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (frameDone) frameDone({frame, t, path, seconds});
  }
}

}  // namespace rad
