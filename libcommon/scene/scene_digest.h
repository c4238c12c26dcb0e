// Digests of the parts of a scene as the toolchain sees it (issue 54): computed from the
// in-memory Scene after loading, so they follow what a tool uses, not the file's bytes (a
// re-saved or re-indented file keeps its digests; a recoloured material changes one). A stage
// records the digests of the parts it used in its output's provenance parameters
// (kSceneDigestsKey); a later stage reading that output compares them with its own scene's and
// refuses a mismatch, naming the part (formats/container.md "Provenance").
//
// Each digest is FNV-1a 64 (Fowler, Noll, Vo) over the part's canonical bytes: integers as
// int64 and doubles as IEEE binary64, little-endian, strings as their length and bytes, in the
// scene's index order. Deterministic: independent of threads, machine and file layout.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "libcommon/scene/scene.h"

namespace rad {

// What each part covers:
//   geometry   the top-level patches (Scene::inputPolygons: each polygon's local vertices,
//              texture coordinates, shading normals, node, material index and back-face flag;
//              so a material's doubleSided, which adds the reversed copies, is geometry too)
//   materials  each material's reflectance, doubleSided, whether it has a base colour texture
//              and that texture's mean (the texels themselves are used by rad-compose only,
//              which reads them from the scene)
//   lights     each material's emission
//   animation  rest pose (parent, T, R, S) and channels (path, interpolation, times, values)
//              of every mesh node and its ancestors
//   camera     each camera node's name and lens, and the rest pose and channels of the camera
//              nodes and their ancestors
enum class ScenePart { kGeometry, kMaterials, kLights, kAnimation, kCamera };

// Every part, in the order above.
const std::vector<ScenePart>& allSceneParts();
// "geometry", "materials", "lights", "animation", "camera".
const char* scenePartName(ScenePart part);

// "fnv1a64:<16 hex>" of `part` of `scene`.
std::string sceneDigest(const Scene& scene, ScenePart part);

// The provenance parameter that holds a file's digests: {"geometry": "fnv1a64:...", ...}.
constexpr const char* kSceneDigestsKey = "scene_digests";

// {name: digest} for each of `parts`.
nlohmann::json sceneDigests(const Scene& scene, const std::vector<ScenePart>& parts);

// Compares the digests a file recorded (`recorded`: its kSceneDigestsKey object; null or
// absent in files written before digests existed, which are accepted) with `scene`'s. Returns
// "" when every recorded part agrees, else one line for the first that differs:
// "made from a scene whose materials differ (materials digest fnv1a64:... there, fnv1a64:...
// here); re-run PRODUCER" (producer: the tool named in the file's provenance). Names this version
// does not know are skipped (a newer writer may add parts); a recorded value that is not a string
// is a difference.
std::string sceneDigestMismatch(const nlohmann::json& recorded, const Scene& scene,
                                const std::string& producer);

// Throws rad::inputError(where, sceneDigestMismatch(...)) when the provenance `parameters` of
// the file at `where`, written by `producer`, record a part that differs from `scene`'s.
void requireSceneDigests(const nlohmann::json& parameters, const std::string& where,
                         const std::string& producer, const Scene& scene);

}  // namespace rad
