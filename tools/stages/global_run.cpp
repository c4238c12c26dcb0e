// rad-global's driver. Contracts in global_run.h.
#include "tools/stages/global_run.h"

#include <chrono>

#include "formats/key_window.h"
#include "formats/link_hierarchy.h"
#include "formats/provenance.h"
#include "libcommon/core/stopwatch.h"
#include "libcommon/scene/scene_digest.h"

namespace rad {
namespace {

constexpr const char* kTool = "rad-global";

// The parameters both outputs' provenance records: the options and the digests of the scene's
// parts the solution depends on (the camera is not one of them).
nlohmann::json provenanceParameters(const GlobalRun& run, const Scene& scene) {
  nlohmann::json params = run.global.toJson();
  params["preset"] = run.preset;
  params[kSceneDigestsKey] = sceneDigests(scene, {ScenePart::kGeometry, ScenePart::kMaterials,
                                                  ScenePart::kLights, ScenePart::kAnimation});
  return params;
}

// The metadata of both outputs: what ran.
nlohmann::json runMetadata(const GlobalRun& run) {
  return {{"parameters", run.global.toJson()},
          {"first_frame", run.frames.first},
          {"last_frame", run.frames.last},
          {"coherence", run.global.spaceTime.coherence}};
}

}  // namespace

void writeGlobalWindow(const GlobalRun& run, const Scene& scene, const KeyIndexRange& keys,
                       GlobalReport& report, int argc, char** argv) {
  const GlobalOptions& g = run.global;
  KeyWindow window =
      solveKeyWindow(scene, run.keyTimes, keys.first, keys.last, g.spaceTime, &report.solve);
  Provenance prov = makeProvenance(kTool, argc, argv, provenanceParameters(run, scene));
  addInput(prov, run.scenePath);
  nlohmann::json metadata = runMetadata(run);
  metadata["window"] = g.window;
  metadata["run_key_count"] = run.keyTimes.size();
  auto tWrite = std::chrono::steady_clock::now();
  writeKeyWindow(run.output, window, prov, metadata);
  report.secondsWrite = secondsSince(tWrite);
}

void writeGlobalHierarchy(const GlobalRun& run, const Scene& scene, GlobalReport& report, int argc,
                          char** argv) {
  const GlobalOptions& g = run.global;
  std::vector<std::string> words(argv, argv + argc);
  GlobalSolution solution;
  if (g.merge.empty()) {
    solution = solveSpaceTime(scene, run.keyTimes, g.spaceTime, &report.solve);
  } else {
    auto tRead = std::chrono::steady_clock::now();
    std::vector<KeyWindow> windows =
        readKeyWindows(g.merge, scene, g.toJson(), hashFile(run.scenePath));
    report.secondsRead += secondsSince(tRead);
    solution = mergeKeyWindows(scene, run.keyTimes, std::move(windows), g.merge, &report.solve);
    words = argumentsWithoutMerge(argc, argv, g.merge);
  }
  std::vector<const char*> args;
  for (const std::string& w : words) args.push_back(w.c_str());
  Provenance prov =
      makeProvenance(kTool, int(args.size()), args.data(), provenanceParameters(run, scene));
  addInput(prov, run.scenePath);
  auto tWrite = std::chrono::steady_clock::now();
  writeLinkHierarchy(run.output, solution, prov, runMetadata(run));
  report.secondsWrite = secondsSince(tWrite);
}

}  // namespace rad
