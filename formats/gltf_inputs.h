// The files a glTF scene is made of, with their content hashes, for rad-inspect --inputs (the
// Makefile layer's dependencies; spec: formats/gltf_scene.md "Inputs").
#pragma once

#include <string>
#include <vector>

namespace rad {

struct GltfInput {
  std::string hash;  // hashFile()'s "fnv1a64:<16 hex>", or "missing" (an image only)
  std::string path;  // as the reader opens it: resolved against the scene's folder
};

// The scene file itself first, then every external buffer and image file it references
// (buffers[].uri, then images[].uri; not data: URIs, not URIs with a scheme such as http:, which
// the reader never reads), each path once, in file order. Parses only the JSON (or the GLB's
// JSON chunk): no image is decoded and no scene model built. An image file that is missing or
// not a regular file is listed as "missing". Throws rad::Error (kBadInput) `path: ...` when the
// scene is not a regular file, not JSON or a malformed GLB, or a buffer file is missing or not a
// regular file.
std::vector<GltfInput> gltfInputs(const std::string& scenePath);

// One line per input: "HASH\tPATH\n".
std::string gltfInputsText(const std::vector<GltfInput>& inputs);

}  // namespace rad
