#include "formats/frame_window.h"

#include <cmath>
#include <sstream>

#include "libcommon/core/error.h"

namespace rad {

void requireGlobalCoversIntervals(const std::string& globalPath, const GlobalSolution& global,
                                  const std::string& intervalsPath,
                                  const TextureIntervals& intervals) {
  const double t0 = global.keyTimes.front(), t1 = global.keyTimes.back();
  const double need0 = intervals.frameTime(intervals.firstFrame);
  const double need1 = intervals.frameTime(intervals.lastFrame);
  const double slack = 1e-9;
  if (t0 <= need0 + slack && need1 <= t1 + slack) return;
  std::ostringstream what;
  what << "its key times " << t0 << "-" << t1 << " s (frames " << std::lround(t0 * intervals.fps)
       << "-" << std::lround(t1 * intervals.fps) << " at " << intervals.fps
       << " fps) do not cover " << intervalsPath << "'s frames " << intervals.firstFrame << "-"
       << intervals.lastFrame << " (" << need0 << "-" << need1
       << " s); run rad-global with the same --frames";
  throw inputError(globalPath, what.str());
}

}  // namespace rad
