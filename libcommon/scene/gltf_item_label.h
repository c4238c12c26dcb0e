// How every message names a glTF item (issue 57): by its glTF name and its index,
// `node "Lamp.001" (8)`, so a Blender user finds it in the outliner by name and a reader of the
// file by index. Item kinds are glTF's: node, mesh, material, camera, texture, animation.
#pragma once

#include <string>

#include "libcommon/scene/scene.h"

namespace rad {

// `KIND "NAME" (INDEX)`, or `KIND INDEX` when the item has no name. The name is kept on one line
// (control characters become spaces) and cut at 120 bytes, so a message stays one line.
std::string gltfItemLabel(const std::string& kind, int index, const std::string& name);

// The scene's node, mesh and material `index` (Scene::nodes, Scene::meshes, Scene::materials)
// labelled so. A material is labelled by its glTF index (Material::gltfIndex); the glTF default
// material (index -1) is `the default material`.
std::string nodeLabel(const Scene& scene, int node);
std::string meshLabel(const Scene& scene, int mesh);
std::string materialLabel(const Scene& scene, int material);

}  // namespace rad
