#include "formats/file_kind.h"

#include <cstring>
#include <fstream>

namespace rad {

FileKind detectFileKind(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return FileKind::kMissing;
  char b[16] = {};
  in.read(b, sizeof b);
  std::streamsize n = in.gcount();
  // The container magic (formats/container.md).
  if (n >= 8 && std::memcmp(b, "\x89RAD\r\n\x1a\n", 8) == 0) return FileKind::kContainer;
  if (n >= 4 && std::memcmp(b, "\x76\x2f\x31\x01", 4) == 0) return FileKind::kOpenExr;
  if (n >= 4 && std::memcmp(b, "glTF", 4) == 0) return FileKind::kGltfBinary;
  if (n >= 8 && std::memcmp(b, "\x89PNG\r\n\x1a\n", 8) == 0) return FileKind::kPng;
  for (std::streamsize i = 0; i < n; ++i) {
    if (b[i] == ' ' || b[i] == '\n' || b[i] == '\r' || b[i] == '\t') continue;
    // A UTF-8 byte-order mark or '{' starts a JSON glTF.
    if (b[i] == '{' || static_cast<unsigned char>(b[i]) == 0xEF) return FileKind::kGltfJson;
    break;
  }
  return FileKind::kUnknown;
}

const char* fileKindName(FileKind kind) {
  switch (kind) {
    case FileKind::kMissing:
      return "missing";
    case FileKind::kUnknown:
      return "unknown";
    case FileKind::kContainer:
      return "rad container";
    case FileKind::kOpenExr:
      return "OpenEXR";
    case FileKind::kGltfJson:
      return "glTF";
    case FileKind::kGltfBinary:
      return "glTF binary";
    case FileKind::kPng:
      return "PNG";
  }
  return "unknown";
}

}  // namespace rad
