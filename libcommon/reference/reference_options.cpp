#include "libcommon/reference/reference_options.h"

#include "libcommon/core/shared_parameters.h"
#include "libcommon/scene/pixel_sampling_parameters.h"

namespace rad {

PathTracerOptions ReferenceOptions::pathTracer() const {
  PathTracerOptions options;
  options.samplesPerPixel = spp;
  options.maxDepth = maxDepth;
  options.seed = seed;
  options.decorrelateFrames = decorrelateFrames;
  options.filter = filter;
  return options;
}

const ParameterTable<ReferenceOptions>& referenceParameters() {
  using O = ReferenceOptions;
  using Check = ParameterCheck;
  static const ParameterTable<O> table = [] {
    ParameterTable<O> t;
    addFramesParameter(t, &O::frames, "the scene's animation, docs/design.md §1");
    addFpsParameter(t, &O::fps);
    addSizeParameter(t, &O::size);
    addCameraParameter(t, &O::camera);
    t.add("spp", &O::spp, "samples per pixel", Check::range(1, 1 << 24), ParameterGroup::kQuality);
    t.add("max-depth", &O::maxDepth, "maximum number of reflections per path",
          Check::range(0, 100000));
    t.add("seed", &O::seed, "random seed");
    t.addFlag("decorrelate-frames", &O::decorrelateFrames, true,
              "independent noise per frame (default: the same per-pixel seeds every frame, so "
              "what does not change does not flicker)");
    addPixelFilterParameters(
        t, [](O& o) -> PixelFilterType& { return o.filter.type; },
        [](O& o) -> double& { return o.filter.width; });
    return t;
  }();
  return table;
}

nlohmann::json ReferenceOptions::toJson() const {
  return referenceParameters().toJson(*this);
}

}  // namespace rad
