// rad-global's driver (paper §3.1, §4.2; docs/design.md §6.1 "rad-global"), next to the other
// stages' drivers: solves (or merges) the key times of a run and writes global.rlh, or solves one
// farm window's keys and writes a key window file (formats/key_window.h). The options, key times
// and report are libcommon/radiosity/global_stage.h; the algorithm is solveSpaceTime.
#pragma once

#include <string>
#include <vector>

#include "libcommon/radiosity/global_stage.h"
#include "libcommon/scene/frame_range.h"
#include "libcommon/scene/scene.h"

namespace rad {

// One rad-global run: what the command line named, with the frames in effect.
struct GlobalRun {
  std::string scenePath;  // the glTF read into `scene`
  std::string output;     // -o
  std::string preset;     // --preset, recorded beside the values it set
  GlobalOptions global;
  FrameRange frames;             // the run's frames (the key grid's span)
  std::vector<double> keyTimes;  // keyTimesOf(frames, keyStep, fps)
};

// The run's global.rlh, solved or merged from key windows (run.global.merge). A merge records
// the whole run's command line (argv without the --merge words), so its bytes are the whole
// run's, provenance included.
void writeGlobalHierarchy(const GlobalRun& run, const Scene& scene, GlobalReport& report, int argc,
                          char** argv);

// The key-time pass alone on `keys` (a --window's), written as a key window file.
void writeGlobalWindow(const GlobalRun& run, const Scene& scene, const KeyIndexRange& keys,
                       GlobalReport& report, int argc, char** argv);

}  // namespace rad
