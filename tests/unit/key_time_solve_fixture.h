// Scenes written by the generators of pipelines/scenes/ and one key-time solve of them at time 0,
// for the tests of issue 57's and 58's generated scenes (contact, clutter, slab room).
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "formats/gltf_scene.h"
#include "libcommon/radiosity/hierarchical_radiosity.h"
#include "libcommon/radiosity/key_solve_inputs.h"
#include "libcommon/radiosity/lamp_coherence.h"
#include "libcommon/radiosity/scene_visibility.h"
#include "libcommon/scene/scene_emitters.h"

namespace rad {

// Runs `python3 pipelines/scenes/SCRIPT ARGS` with "{out}" in ARGS replaced by a temporary glTF
// path, and reads that scene.
inline Scene generatedScene(const std::string& script, std::string args) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() /
                       ("rad_" + fs::path(script).stem().string() + "_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const std::string path = (dir / "scene.gltf").string();
  args.replace(args.find("{out}"), 5, path);
  const std::string command =
      "python3 " RAD_SOURCE_DIR "/pipelines/scenes/" + script + " " + args + " >/dev/null 2>&1";
  if (std::system(command.c_str()) != 0) throw std::runtime_error("failed: " + command);
  Scene s = readGltfScene(path, GltfReadOptions());
  fs::remove_all(dir);
  return s;
}

// A key-time solve of the scene at time 0 with its clusters, visibility and lamps, as rad-global
// makes one (space_time_radiosity.cpp).
struct KeyTimeSolve {
  PatchHierarchy hierarchy;  // the solve subdivides it
  std::vector<SurfaceProperties> surfaces;
  KeySolution solution;

  KeyTimeSolve(const Scene& scene, const RadiosityOptions& options)
      : hierarchy(scene.inputPolygons()) {
    surfaces = surfacePropertiesOf(scene, hierarchy);
    SceneVisibility visibility(scene, hierarchy, 0.0, 0.0);
    visibility.setTime(0.0);
    const ClusterTree tree = clusterTreeOf(scene, hierarchy, 0.0, 0.0);
    const SceneEmitters emitters(scene, hierarchy.tops());
    const PlacedLamps lamps = placeLamps(emitters, 0.0);
    KeySolveInput in;
    in.topToWorld = topTransforms(scene, hierarchy, 0.0);
    in.visibility = &visibility.visibility();
    in.movingTops = movingTopsOf(scene, hierarchy, 0.0, 0.0);
    in.clusters = &tree;
    in.lamps = lamps.lamps;
    solution = solveKeyTime(hierarchy, surfaces, in, options);
  }

  // Absorbed over emitted power, the largest channel: at most 1 in a closed room (1 when every
  // row sums to 1 exactly).
  double absorbedShare() const {
    const glm::dvec3 a = solution.absorbedPower(hierarchy, surfaces);
    const glm::dvec3 e = solution.emittedPower(hierarchy, surfaces);
    return std::max({a.x, a.y, a.z}) / std::max({e.x, e.y, e.z});
  }
};

}  // namespace rad
