#include "libcommon/reference/reference_options.h"

namespace rad {

PathTracerOptions ReferenceOptions::pathTracer() const {
  PathTracerOptions options;
  options.samplesPerPixel = spp;
  options.maxDepth = maxDepth;
  options.seed = seed;
  options.decorrelateFrames = decorrelateFrames;
  options.pixelCentres = pixelCentres;
  return options;
}

nlohmann::json ReferenceOptions::toJson() const {
  return {{"frames", frames},
          {"fps", fps},
          {"size", size},
          {"spp", spp},
          {"camera", camera},
          {"max-depth", maxDepth},
          {"seed", seed},
          {"decorrelate-frames", decorrelateFrames},
          {"pixel-centres", pixelCentres}};
}

}  // namespace rad
