#include "libcommon/scene/frame_range.h"

#include <algorithm>
#include <cmath>

#include "libcommon/scene/scene.h"

namespace rad {

std::string FrameRange::toString() const {
  return std::to_string(first) + "-" + std::to_string(last);
}

FrameRange animationFrames(const Scene& scene, double fps) {
  const double end = std::max(0.0, scene.endTime()) * fps;
  // ceil(end) frames; clamped so an absurd end time cannot overflow the frame number.
  const double count = std::clamp(std::ceil(end - 1e-9), 1.0, 2e9);
  return {0, int(count) - 1};
}

std::vector<int> keyFrames(int first, int last, int step) {
  step = std::max(step, 1);
  std::vector<int> frames;
  for (long f = first; f < last; f += step) frames.push_back(int(f));
  frames.push_back(last);
  return frames;
}

}  // namespace rad
