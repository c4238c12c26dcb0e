// glTF 2.0 scene reader (spec: formats/gltf_scene.md).
#pragma once

#include <string>

#include "libcommon/scene/scene.h"

namespace rad {

// Reads a .gltf (JSON) or .glb (binary; detected by the "glTF" magic, whatever the
// extension) file into the scene model: the default scene's node hierarchy, triangle meshes
// in node-local frames, diffuse/emissive materials with decoded base-colour textures,
// cameras and TRS animation channels.
// Throws rad::Error (ExitCode::kBadInput) whose message is `path: what is wrong` for a missing
// or malformed file, data out of bounds, non-finite values, and features outside the rigid
// model (skins, morph targets). Never reads outside the loaded buffers.
Scene readGltfScene(const std::string& path);

}  // namespace rad
