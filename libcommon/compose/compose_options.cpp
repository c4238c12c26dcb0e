#include "libcommon/compose/compose_options.h"

#include "libcommon/core/shared_parameters.h"
#include "libcommon/scene/pixel_sampling_parameters.h"

namespace rad {

const ParameterTable<ComposeOptions>& composeParameters() {
  using O = ComposeOptions;
  using Group = ParameterGroup;
  static const ParameterTable<O> table = [] {
    ParameterTable<O> t;
    addFramesParameter(t, &O::frames, "the intervals' window");
    addFpsParameter(t, &O::fps, "the intervals'");
    addSizeParameter(t, &O::size, "the intervals'");
    addCameraParameter(t, &O::camera);
    t.add("exposure", &O::exposure, "PNG exposure in EV: PNG = sRGB(L * 2^EV) (default 0)",
          ParameterCheck::finite(), Group::kCommon);
    t.addFlag("auto-exposure", &O::autoExposure, true,
              "one exposure for the whole sequence: the 99th area percentile of the global "
              "solution's non-emitter radiance maps to white",
              Group::kCommon);
    t.addFlag("half", &O::half, true, "write HALF instead of FLOAT EXR channels");
    t.addEnum(
        "compression", &O::compression,
        EnumNames<std::string>({{"none", "none"}, {"rle", "rle"}, {"zip", "zip"}, {"piz", "piz"}}),
        "EXR compression: none, rle, zip, piz (ZIP saves ~7 % of noise-free float "
        "radiance and doubles the compose time)");
    t.addFlag("no-png", &O::noPng, true, "write only the EXR frames", Group::kCommon);
    addPixelFilterParameters(t, &O::pixelFilter, &O::filterWidth, "the intervals'");
    addPixelSamplesParameter(t, &O::pixelSamples, "the intervals'");
    t.addFlag("every-sample", &O::everySample, true,
              "shade every sample of every pixel's filter footprint (default: one sample a "
              "pixel where the footprint is one untextured surface, the filter's blur there "
              "taken to second order from the neighbouring centres)");
    return t;
  }();
  return table;
}

nlohmann::json ComposeOptions::toJson() const {
  nlohmann::json out = composeParameters().toJson(*this);
  out["output"] = output;  // -o
  return out;
}

}  // namespace rad
