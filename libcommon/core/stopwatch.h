// Wall-clock seconds for the stage reports (seconds_* keys): one steady clock for every stage.
#pragma once

#include <chrono>

namespace rad {

using SteadyClock = std::chrono::steady_clock;

// Seconds from `start` to now, on the steady clock.
inline double secondsSince(SteadyClock::time_point start) {
  return std::chrono::duration<double>(SteadyClock::now() - start).count();
}

}  // namespace rad
