#include "libcommon/intervals/intervals_options.h"

namespace rad {

nlohmann::json IntervalsOptions::toJson() const {
  const TextureIntervalsOptions& b = build;
  return {{"frames", frames},
          {"fps", b.fps},
          {"size", size},
          {"camera", camera},
          {"item-buffers", itemBuffers},
          {"max-level", b.maxLevel},
          {"min-visible-fraction", b.minVisibleFraction},
          {"level-hysteresis", b.levelHysteresis},
          {"texel-density", b.texelDensity},
          {"min-size", b.minSize},
          {"max-size", b.maxSize},
          {"resize-tolerance", b.resizeTolerance},
          {"size-ratio", b.sizeRatio},
          {"max-length", b.maxLength},
          {"hidden-gap", b.hiddenGap}};
}

}  // namespace rad
