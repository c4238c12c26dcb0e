// Recognises what a file is from its first bytes, so rad-inspect and the readers can say
// "not an OpenEXR file" instead of failing deep inside a library.
#pragma once

#include <string>

namespace rad {

enum class FileKind { kMissing, kUnknown, kContainer, kOpenExr, kGltfJson, kGltfBinary, kPng };

// Looks at the magic number (and for .gltf, the first non-blank character).
FileKind detectFileKind(const std::string& path);
const char* fileKindName(FileKind kind);

}  // namespace rad
