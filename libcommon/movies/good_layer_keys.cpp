// The good layer gathered at coarser keys than its movie's and interpolated between them
// (good_layer_keys.h).
#include "libcommon/movies/good_layer_keys.h"

#include <algorithm>
#include <utility>

#include "libcommon/scene/frame_range.h"

namespace rad {

std::vector<double> goodLayerGatherTimes(int firstFrame, int lastFrame, int keyStep, int goodStep,
                                         double fps) {
  keyStep = std::max(keyStep, 1);
  if (goodStep <= keyStep) return {};
  const int step = keyStep * ((goodStep + keyStep - 1) / keyStep);
  std::vector<double> times;
  for (int f : keyFrames(firstFrame, lastFrame, step)) times.push_back(f / fps);
  return times;
}

GoodLayerKeys::GoodLayerKeys(const GoodLinkGather& gather, std::vector<double> gatherTimes)
    : gather_(gather), times_(std::move(gatherTimes)) {}

const std::vector<glm::dvec3>& GoodLayerKeys::gathered(double t, size_t texels) {
  for (const Kept& k : kept_)
    if (k.valid && k.t == t) return k.g;
  Kept& slot = kept_[size_t(next_)];
  next_ = 1 - next_;
  slot.valid = true;
  slot.t = t;
  slot.g.assign(texels, glm::dvec3(0.0));
  gather_.gather(t, slot.g);
  ++gathers_;
  return slot.g;
}

void GoodLayerKeys::at(double t, std::vector<glm::dvec3>& acc) {
  const auto above = std::lower_bound(times_.begin(), times_.end(), t);
  if (times_.empty() || above == times_.end() || *above == t || above == times_.begin()) {
    const std::vector<glm::dvec3>& g = gathered(t, acc.size());
    std::copy(g.begin(), g.end(), acc.begin());
    return;
  }
  const double t0 = *(above - 1), t1 = *above, w = (t - t0) / (t1 - t0);
  const std::vector<glm::dvec3>& g0 = gathered(t0, acc.size());
  const std::vector<glm::dvec3>& g1 = gathered(t1, acc.size());
  for (size_t x = 0; x < acc.size(); ++x) acc[x] = (1.0 - w) * g0[x] + w * g1[x];
}

}  // namespace rad
