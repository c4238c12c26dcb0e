// rad-global as a stage (paper §3.1, §4.2; docs/design.md §6.1 "rad-global"): the options its
// command line binds and records as provenance, the key-time schedule and the min-area default
// derived from them, and the run report. The algorithm itself is solveSpaceTime
// (space_time_radiosity.h); the tool parses, calls the functions here and writes global.rlh.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "libcommon/core/parameter_table.h"
#include "libcommon/radiosity/space_time_radiosity.h"
#include "libcommon/scene/frame_range.h"
#include "libcommon/scene/scene.h"

namespace rad {

// Every parameter of rad-global's solve, defaults written here once.
struct GlobalOptions {
  // The frames as given, oiiotool style FIRST-LAST[xSTEP]; empty: the scene's whole animation
  // (animationFrames). The key times span the first to the last frame named.
  std::string frames;
  double fps = 24.0;  // frame f is at time f / fps
  // Frames between key times (>= 1; the last frame is always one). 16: on the bundled scene and 8
  // cubes 16 gave the error of 8 for less CPU time, so 8 was off the speed/accuracy front; with a
  // moving light, the frames midway between keys 16 apart stay well within the default setting's
  // error (docs/results.md, "A key time every 16 frames"). The good links' indirect light between
  // keys is smooth, and the lights' (bad) links are re-evaluated per movie key.
  int keyStep = 16;
  // radiosity.minArea 0 (the default): resolveMinArea's 1e-4 of the largest top-level patch.
  SpaceTimeOptions spaceTime;
  // The render farm (issue 17): `window` FIRST-LAST solves only the run's key times within
  // those frames and writes them as a key window file; `merge` names such files, made by the
  // same command line with other windows, to merge into the run's link hierarchy instead of
  // solving. Neither is a parameter of the solution (the merged file is the whole run's, byte
  // for byte, provenance included), so toJson leaves them out: a window file records its window
  // in its metadata.
  std::string window;
  std::vector<std::string> merge;

  // The provenance parameters: every entry of globalParameters() under its flag's name. Call
  // it once frames and min-area are resolved, so the record says what ran.
  nlohmann::json toJson() const;
};

// rad-global's parameters (everything but the render farm's --window and --merge, which are not
// parameters of the solution), declared once: flag name, field, help, check, help group.
const ParameterTable<GlobalOptions>& globalParameters();
// rad-global's quality presets (README "Recommended settings"): draft --eps 0.02; final
// --eps 1e-5 --key-step 4 --rays 64; default: the struct's values.
const std::vector<Preset>& globalPresets();

// The key indices (into keyTimesOf(frames, ...)) of the key frames within frames `window`
// (FIRST-LAST, the --window syntax). Usage Error when the window is malformed, leaves the run's
// frames or holds no key frame.
struct KeyIndexRange {
  size_t first = 0, last = 0;
};
KeyIndexRange windowKeys(const FrameRange& frames, int keyStep, const std::string& window);

// The run's frames split into at most `count` contiguous windows for --window, each holding
// whole key times: the key times are dealt out as evenly as they go, and each window runs from
// its first key frame to the frame before the next window's (the first from frames.first, the
// last to frames.last). A split of the frames alone leaves windows with no key frame once they
// are shorter than --key-step (the render farm's GLOBAL_WINDOWS, `rad-global --print-windows`).
std::vector<FrameRange> keyWindows(const FrameRange& frames, int keyStep, int count);

// The command line the whole run has that a --merge run stands for: argv without "--merge" and
// the values it took (`merged`, in order), nor "--merge=VALUE". The merged file's provenance
// records it, so it is the whole run's when the rest of the command line is.
std::vector<std::string> argumentsWithoutMerge(int argc, const char* const* argv,
                                               const std::vector<std::string>& merged);

// The key times of frames first..last: keyFrames(first, last, keyStep) (the one key schedule,
// frame_range.h), frame f at time f / fps (s).
std::vector<double> keyTimesOf(const FrameRange& frames, int keyStep, double fps);

// minArea when it is > 0; else 1e-4 of the world area (m^2) of the largest top-level patch at
// time t (rad-global: the first key time), so the subdivision depth does not depend on the
// scene's units.
double resolveMinArea(const Scene& scene, double minArea, double t);

// rad-global's run report: the solver's, plus what the tool measures around it.
struct GlobalReport {
  SpaceTimeReport solve;
  double secondsRead = 0, secondsWrite = 0, secondsTotal = 0;  // scene read, file write, all
  double peakMemoryMb = 0;                                     // of the process (getrusage)
  bool coherence = true;

  // The --report JSON: key_times[], totals, seconds, peak_memory_mb, coherence
  // (pipelines/bench.py and the CLI tests read these keys).
  nlohmann::json toJson() const;
  // The stderr table: a header line naming `tool`, one row per key time, two total lines. Of
  // more than kTableKeys key times only the first and last kTableKeys / 2 have rows, and one
  // line says how many are left out (--frames 0-100000 made 12,505 lines; --report has all).
  static constexpr size_t kTableKeys = 20;
  std::string table(const std::string& tool) const;
  // Key times whose refinement stopped at the link bound (RadiosityOptions::maxLinks).
  size_t keysAtLinkCap() const;
  // The one-line warning rad-global prints when keysAtLinkCap() > 0, else empty.
  std::string linkCapWarning(const std::string& tool, size_t maxLinks) const;
};

}  // namespace rad
