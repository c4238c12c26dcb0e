// rad-global: the first pass (paper §3.1, §4.2; docs/design.md §6.1 "rad-global"): space-time
// hierarchical radiosity over the key times of a frame range, written as global.rlh. The
// options, key times, min-area default and report are libcommon/radiosity/global_stage.h, the
// driver tools/stages/global_run.h, the algorithm solveSpaceTime; this main parses, calls and
// reports. For a render farm (issue 17)
// --window solves a time window's keys into a key window file (solveKeyWindow,
// formats/key_window.h) and --merge joins such files into the very global.rlh the whole run
// writes (mergeKeyWindows).
#include <chrono>
#include <iostream>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "formats/atomic_file.h"
#include "formats/gltf_scene.h"
#include "formats/key_window.h"
#include "libcommon/core/stopwatch.h"
#include "libcommon/radiosity/global_stage.h"
#include "libcommon/radiosity/solve_cost_warnings.h"
#include "tools/common/parameter_cli.h"
#include "tools/common/tool_main.h"
#include "tools/stages/global_run.h"

namespace {

constexpr const char* kTool = "rad-global";

struct Options {
  std::string scene, output, report;
  std::string preset;    // --preset: recorded in the provenance beside the values it set
  int printWindows = 0;  // > 0: print that many --window ranges and exit (no solve)
  rad::GlobalOptions global;
};

// Binds the parameter table (globalParameters) and the run's plumbing: files and the farm.
void addOptions(CLI::App& app, Options& o) {
  rad::GlobalOptions& g = o.global;
  app.add_option("SCENE", o.scene, "glTF scene")->required();
  app.add_option("-o,--output", o.output, "output link hierarchy (.rlh)")
      ->required()
      ->group(rad::parameterGroupTitle(rad::ParameterGroup::kCommon));
  rad::bindParameters(app, rad::globalParameters(), g);
  app.add_option("--report", o.report, "also write the run report as JSON to this file")
      ->group(rad::parameterGroupTitle(rad::ParameterGroup::kCommon));
  const std::string farm = "Render farm";
  // The render farm (issue 17): windows side by side, then one merge.
  auto* window =
      app.add_option(
             "--window", g.window,
             "render farm: solve only the run's key times within frames FIRST-LAST (the key grid "
             "of "
             "--frames and --key-step, so put the whole run's --frames) and write them to -o as a "
             "key "
             "window file for --merge; a window starts from scratch, so windows need not overlap")
          ->type_name("FIRST-LAST")
          ->group(farm);
  app.add_option("--merge", g.merge,
                 "render farm: instead of solving, merge these key window files (--window runs "
                 "of this same command line that together hold every key time) into -o: the "
                 "same bytes as the run without --merge, provenance included")
      ->type_name("WINDOW")
      ->excludes(window)
      ->group(farm);
  app.add_option("--print-windows", o.printWindows,
                 "render farm: print at most N --window ranges of the run's frames, each holding "
                 "whole key times, on one line, and exit without solving (pipelines/slurm.mk's "
                 "GLOBAL_WINDOWS)")
      ->type_name("N")
      ->check(rad::positiveInteger())
      ->excludes(window)
      ->group(farm);
}

// --print-windows: the --window ranges of a farm run, on one line.
int printWindows(const rad::FrameRange& frames, int keyStep, int count) {
  const char* sep = "";
  for (const rad::FrameRange& w : rad::keyWindows(frames, keyStep, count))
    std::cout << sep << w.toString(), sep = " ";
  std::cout << "\n";
  return 0;
}

int run(Options o, int argc, char** argv) {
  auto tStart = std::chrono::steady_clock::now();
  rad::GlobalOptions& g = o.global;
  std::vector<int> given = g.frames.empty() ? std::vector<int>{} : rad::parseFrameRange(g.frames);
  if (o.printWindows > 0 && !given.empty())  // the key grid alone: no scene read, no solve
    return printWindows({given.front(), given.back()}, g.keyStep, o.printWindows);
  rad::GlobalReport report;
  auto tRead = std::chrono::steady_clock::now();
  rad::Scene scene = rad::readGltfScene(o.scene);
  rad::requireEmitter(scene);  // else the solution is zero and every frame black
  for (const std::string& w : rad::slowSolveWarnings(scene, g.spaceTime.radiosity.tol))
    std::cerr << kTool << ": " << o.scene << ": warning: " << w << "\n";
  report.secondsRead = rad::secondsSince(tRead);
  rad::FrameRange frames = given.empty() ? rad::animationFrames(scene, g.fps)
                                         : rad::FrameRange{given.front(), given.back()};
  if (given.empty()) g.frames = frames.toString();  // the provenance says what ran
  if (o.printWindows > 0) return printWindows(frames, g.keyStep, o.printWindows);
  std::vector<double> keyTimes = rad::keyTimesOf(frames, g.keyStep, g.fps);
  g.spaceTime.radiosity.minArea =
      rad::resolveMinArea(scene, g.spaceTime.radiosity.minArea, keyTimes.front());

  const rad::KeyIndexRange keys = g.window.empty() ? rad::KeyIndexRange{0, keyTimes.size() - 1}
                                                   : rad::windowKeys(frames, g.keyStep, g.window);

  rad::Progress progress(kTool, g.merge.empty() ? long(keys.last - keys.first + 1) : 0);
  g.spaceTime.onKeySolved = [&]() { progress.advance(); };
  const rad::GlobalRun globalRun{o.scene, o.output, o.preset, g, frames, keyTimes};
  if (g.window.empty())
    rad::writeGlobalHierarchy(globalRun, scene, report, argc, argv);
  else
    rad::writeGlobalWindow(globalRun, scene, keys, report, argc, argv);
  progress.done();

  report.secondsTotal = rad::secondsSince(tStart);
  report.peakMemoryMb = rad::peakMemoryMb();
  report.coherence = g.spaceTime.coherence;
  std::cerr << report.table(kTool) << report.linkCapWarning(kTool, g.spaceTime.radiosity.maxLinks);
  if (!o.report.empty()) rad::writeTextFile(o.report, report.toJson().dump(1) + "\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
#if defined(__GLIBC__)
  // Arrays of 1 MB and more are mapped and unmapped on their own. glibc's threshold otherwise
  // grows with each large block freed, and the key solves' freed arrays would stay in the heap
  // and raise the peak RSS; the cost is the fresh pages' faults (docs/results.md, "Figures
  // moved out of the radiosity code's comments (issue 55)").
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
#endif
  CLI::App app{
      "Space-time hierarchical radiosity (first pass): solves the scene at key times of a frame "
      "range with temporal coherence and writes the link hierarchy global.rlh."};
  Options o;
  rad::setUpApp(
      app, kTool,
      "rad-global scene.gltf -o global.rlh --frames 0-95 --fps 24 --key-step 16\n"
      "Render farm: windows side by side, then the merge (the bytes of the run without --window\n"
      "or --merge; the windows need the run's --frames):\n"
      "  rad-global scene.gltf -o w0.rkw --frames 0-95 --window 0-47\n"
      "  rad-global scene.gltf -o w1.rkw --frames 0-95 --window 48-95\n"
      "  rad-global scene.gltf -o global.rlh --frames 0-95 --merge w0.rkw w1.rkw");
  const std::string preset = rad::addPresetOption(app, o.preset, argc, argv);
  rad::globalParameters().apply(o.global, rad::findPreset(rad::globalPresets(), preset).values);
  addOptions(app, o);
  if (int rc = rad::parseCommandLine(app, kTool, argc, argv); rc >= 0) return rc;
  return rad::runTool(kTool, [&]() { return run(o, argc, argv); });
}
