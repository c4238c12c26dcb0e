// rad-reference: independent Monte Carlo path-traced frames of a scene (issue 7), the
// "converged reference" of docs/design.md §8 that rad-diff compares the pipeline's frames with.
// Shares only the scene loader and the camera with the pipeline (see
// libcommon/reference/path_tracer.h). The options are libcommon/reference/reference_options.h,
// the frame loop tools/stages/reference_sequence.h; this main parses, calls it and reports.
#include <iostream>

#include <nlohmann/json.hpp>

#include "formats/container.h"
#include "formats/gltf_scene.h"
#include "formats/provenance.h"
#include "libcommon/reference/reference_options.h"
#include "libcommon/scene/frame_range.h"
#include "tools/common/parameter_cli.h"
#include "tools/common/tool_main.h"
#include "tools/stages/reference_sequence.h"

namespace {

constexpr const char* kTool = "rad-reference";

int run(const rad::ReferenceOptions& given, int argc, char** argv) {
  rad::ReferenceOptions o = given;
  rad::Scene scene = rad::readGltfScene(o.scene);
  rad::requireEmitter(scene);  // else every frame is black
  const int cameraNode = scene.cameraNode(o.camera);
  if (cameraNode < 0)
    throw rad::inputError(
        o.scene, o.camera.empty() ? "has no camera" : "has no camera named '" + o.camera + "'");
  const auto [width, height] = rad::parseImageSize(o.size);
  if (o.frames.empty()) o.frames = rad::animationFrames(scene, o.fps).toString();
  const std::vector<int> frames = rad::parseFrameRange(o.frames);

  rad::Provenance provenance = rad::makeProvenance(kTool, argc, argv, o.toJson());
  rad::addInput(provenance, o.scene);

  rad::Progress progress(kTool, long(frames.size()));
  double total = 0.0;
  rad::renderReferenceSequence(scene, cameraNode, {width, height}, frames, o,
                               provenance.toJson().dump(), [&](const rad::ReferenceFrame& f) {
                                 total += f.seconds;
                                 progress.advance();
                                 std::cout << f.path << ": frame " << f.frame << " t=" << f.time
                                           << " s, " << o.spp << " spp, " << f.seconds << " s\n"
                                           << std::flush;
                               });
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
  rad::ReferenceOptions o;
  rad::setUpApp(app, kTool,
                "rad-reference scene.gltf -o ref --frames 0-23 --size 176x120 --spp 256");
  app.add_option("SCENE", o.scene, "glTF 2.0 scene (.gltf or .glb)")->required();
  app.add_option("-o,--output", o.output, "output directory for NNNN.exr frames")
      ->required()
      ->group(rad::parameterGroupTitle(rad::ParameterGroup::kCommon));
  rad::bindParameters(app, rad::referenceParameters(), o);
  // The old spelling of --pixel-filter none.
  app.add_flag_callback(
         "--pixel-centres",
         [&o] {
           rad::warnDeprecated(kTool, "--pixel-centres", "--pixel-filter none");
           o.filter.type = rad::PixelFilterType::kNone;
         },
         "deprecated name of --pixel-filter none")
      ->excludes(app.get_option("--pixel-filter"))
      ->group("Deprecated");
  if (int rc = rad::parseCommandLine(app, kTool, argc, argv); rc >= 0) return rc;
  return rad::runTool(kTool, [&]() { return run(o, argc, argv); });
}
