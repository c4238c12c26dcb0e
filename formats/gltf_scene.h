// glTF 2.0 scene reader (spec: formats/gltf_scene.md).
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "formats/gltf_file_access.h"
#include "formats/gltf_lights.h"
#include "libcommon/scene/scene.h"

namespace rad {

struct GltfReadOptions {
  // An image whose header gives more pixels than this is not decoded: its texture is ignored
  // with a warning (a 450 KB PNG of 12,000^2 pixels decoded to 2.3 GB).
  uint64_t maxTexturePixels = kMaxTexturePixels;
  // The units of KHR_lights_punctual intensities (gltf_lights.h; --light-units).
  LightUnits lightUnits = LightUnits::kAuto;
};

// The options readGltfScene(path) uses. Process-wide: the tools set it once from their command
// line (--max-texture-pixels, tools/common) before any scene is read.
GltfReadOptions& defaultGltfReadOptions();

// Called with the path and each warning (Scene::warnings) of every scene readGltfScene reads,
// after the read succeeded; none by default. The tools install one that prints them on stderr.
using GltfWarningHandler = std::function<void(const std::string& path, const std::string& warning)>;
void setGltfWarningHandler(GltfWarningHandler handler);

// Reads a .gltf (JSON) or .glb (binary; detected by the "glTF" magic, whatever the
// extension) file into the scene model: the default scene's node hierarchy, triangle meshes
// in node-local frames, diffuse/emissive materials with decoded base-colour textures,
// cameras and TRS animation channels.
// Throws rad::Error (ExitCode::kBadInput) whose message is `path: what is wrong` for a missing,
// non-regular (FIFO, device, directory) or malformed file, data out of bounds, non-finite values,
// and features outside the affine model (skins, morph targets), values beyond the
// limits of scene.h (kMaxCoordinate, kMaxEmission) and JSON nested deeper than 256 levels. Never
// reads outside the loaded buffers; every error message is one line with quoted input cut at 120
// bytes. Out of memory while reading is rad::Error (ExitCode::kEnvironment) `path: out of memory
// ...`. A texture that cannot be read, decoded or is over maxTexturePixels is a warning, not an
// error.
Scene readGltfScene(const std::string& path, const GltfReadOptions& options);
Scene readGltfScene(const std::string& path);  // with defaultGltfReadOptions()

}  // namespace rad
