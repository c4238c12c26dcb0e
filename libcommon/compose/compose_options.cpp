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
    t.addFlag("no-edge-coverage", &O::edgeCoverage, false,
              "give each sample's cell its sample's radiance where an edge crosses it (default: "
              "the radiance of each side weighed by the area it covers, from the polygons' "
              "outlines; the edge is placed to 1/S px without it)",
              Group::kQuality);
    t.add("edge-contrast", &O::edgeContrast,
          "weigh an edge cell by coverage only where the luminance step across it is at least "
          "this share of its brighter side (0: every edge cell; smaller: more exact, slower)",
          ParameterCheck::range(0.0, 1.0), Group::kQuality);
    return t;
  }();
  return table;
}

const std::vector<Preset>& composePresets() {
  static const std::vector<Preset> presets{{"final", {{"edge-contrast", "0"}}}};
  return presets;
}

nlohmann::json ComposeOptions::toJson() const {
  nlohmann::json out = composeParameters().toJson(*this);
  out["output"] = output;  // -o
  return out;
}

}  // namespace rad
