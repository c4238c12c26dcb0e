#include "libcommon/intervals/intervals_options.h"

#include "libcommon/core/shared_parameters.h"
#include "libcommon/scene/pixel_sampling_parameters.h"

namespace rad {

namespace {

using Group = ParameterGroup;
using Check = ParameterCheck;
using O = IntervalsOptions;

void addTextureParameters(ParameterTable<O>& t) {
  t.add(
      "max-level", [](O& o) -> int& { return o.build.maxLevel; },
      "subdivision depth below the top-level patches");
  t.add(
      "min-visible-fraction", [](O& o) -> double& { return o.build.minVisibleFraction; },
      "theta: below this visible fraction a patch is represented by its children",
      Check::range(0.0, 1.0));
  t.add(
      "level-hysteresis", [](O& o) -> double& { return o.build.levelHysteresis; },
      "keep a patch's level while its visible fraction stays within this of theta (each "
      "level change ends movies and starts new ones); 0: the paper's rule; not with "
      "--max-length 1 (from scratch)",
      Check::range(0.0, 1.0));
  t.add(
      "texel-density", [](O& o) -> double& { return o.build.texelDensity; },
      "texels per covered pixel", Check::positive());
  t.add(
      "min-size", [](O& o) -> int& { return o.build.minSize; }, "smallest texture side");
  t.add(
      "max-size", [](O& o) -> int& { return o.build.maxSize; }, "largest texture side");
  t.add(
      "resize-tolerance", [](O& o) -> double& { return o.build.resizeTolerance; },
      "keep a texture size while the ideal size is within a factor 1+tol of it",
      Check::nonNegative());
  t.add(
      "size-ratio", [](O& o) -> double& { return o.build.sizeRatio; },
      "texture sides are round(r^k): the default sqrt 2 holds a patch's pixels in at most "
      "twice their texels, 2 (the paper's powers of two) in up to four times",
      Check::range(1.2, 4.0));
  t.add(
      "max-length", [](O& o) -> int& { return o.build.maxLength; },
      "longest movie in frames (0 = no limit)");
  t.add(
      "hidden-gap", [](O& o) -> int& { return o.build.hiddenGap; },
      "keep a movie whose node is hidden for at most this many frames and then seen again "
      "at the same size (0: close it at the first hidden frame)");
}

}  // namespace

const ParameterTable<IntervalsOptions>& intervalsParameters() {
  static const ParameterTable<O> table = [] {
    ParameterTable<O> t;
    addFramesParameter(t, &O::frames, "the scene's animation, docs/design.md §1");
    addFpsParameter(t, [](O& o) -> double& { return o.build.fps; });
    addSizeParameter(t, &O::size);
    addCameraParameter(t, &O::camera);
    t.add("item-buffers", &O::itemBuffers,
          "also write each frame's item buffer to DIR/NNNN.exr (UINT id, FLOAT Z)", Check{},
          Group::kCommon);
    addPixelFilterParameters(
        t, [](O& o) -> PixelFilterType& { return o.sampling.filter.type; },
        [](O& o) -> double& { return o.sampling.filter.width; });
    addPixelSamplesParameter(t, [](O& o) -> int& { return o.sampling.samplesPerAxis; });
    addTextureParameters(t);
    return t;
  }();
  return table;
}

nlohmann::json IntervalsOptions::toJson() const {
  return intervalsParameters().toJson(*this);
}

}  // namespace rad
