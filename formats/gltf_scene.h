// glTF 2.0 scene reader (spec: formats/gltf_scene.md).
#pragma once

#include <string>

#include "libcommon/scene/scene.h"

namespace rad {

struct GltfReadOptions {
  // Animated scale is outside the rigid model (patches keep their shape): a scale channel whose
  // values are not all 1 (within 1e-6) is refused. true only to test glTF's animation semantics
  // on files that animate scale (no tool sets it).
  bool allowScaleAnimation = false;
};

// Reads a .gltf (JSON) or .glb (binary; detected by the "glTF" magic, whatever the
// extension) file into the scene model: the default scene's node hierarchy, triangle meshes
// in node-local frames, diffuse/emissive materials with decoded base-colour textures,
// cameras and TRS animation channels.
// Throws rad::Error (ExitCode::kBadInput) whose message is `path: what is wrong` for a missing
// or malformed file, data out of bounds, non-finite values, and features outside the rigid
// model (skins, morph targets, animated scale), values beyond the limits of scene.h
// (kMaxCoordinate, kMaxEmission) and JSON nested deeper than 256 levels. Never reads outside
// the loaded buffers; every error message is one line with quoted input cut at 120 bytes.
Scene readGltfScene(const std::string& path, const GltfReadOptions& options = {});

}  // namespace rad
