// The glTF scene file before tinygltf parses it (spec: formats/gltf_scene.md "Files"): read
// bounded from a regular file, the GLB header and JSON chunk checked, the JSON's depth and
// unsigned fields checked, and the external files it references listed. Shared by the reader
// (gltf_scene.cpp) and rad-inspect --inputs (gltf_inputs.cpp).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/gltf_file_access.h"

namespace rad {

struct GltfSceneFile {
  std::string path;
  std::string baseDir;         // the folder URIs are resolved against (parent of path, may be "")
  std::string bytes;           // the whole file
  bool binary = false;         // starts with the GLB magic "glTF"
  const char* json = nullptr;  // the JSON text inside bytes (the whole file, or the GLB chunk)
  size_t jsonSize = 0;
  nlohmann::json document;  // the parsed JSON; discarded (null) when it does not parse
  std::vector<GltfExternalFile> externalFiles;  // buffers first, then images, in file order
};

// Reads and checks `path`. Throws rad::Error (kBadInput) `path: what is wrong` when it is not a
// regular file, exceeds kMaxSceneFileBytes, is a malformed GLB, nests JSON deeper than 256
// levels, has a negative or fractional size or offset, or an image's bufferView lies outside
// its buffer. JSON syntax errors are left to tinygltf (document stays null) unless
// `requireJson`, which refuses them as `invalid gltf: ...`.
GltfSceneFile readGltfSceneFile(const std::string& path, bool requireJson = false);

}  // namespace rad
