// The frame window a stage's inputs must agree on: global.rlh's key times have to span every
// frame of intervals.rti, or the second pass would read the global solution outside the times
// it was solved for (GlobalSolution holds its end values there, silently).
#pragma once

#include <string>

#include "formats/texture_intervals.h"
#include "libcommon/radiosity/global_solution.h"

namespace rad {

// Throws rad::inputError naming both files and both ranges when the global solution's key
// times [first key, last key] do not contain the intervals' window [firstFrame, lastFrame] / fps
// (to 1e-9 s).
void requireGlobalCoversIntervals(const std::string& globalPath, const GlobalSolution& global,
                                  const std::string& intervalsPath,
                                  const TextureIntervals& intervals);

}  // namespace rad
