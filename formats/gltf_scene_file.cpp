// The glTF scene file before tinygltf parses it (spec: formats/gltf_scene.md "Files").
// GLB layout: glTF 2.0 specification (Khronos, 2.0.1) section 4.4.
#include "formats/gltf_scene_file.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <functional>

#include "libcommon/core/error.h"

namespace rad {

namespace {

// Quoted input in messages is cut at 120 bytes (UTF-8 boundary), as in gltf_scene.cpp.
std::string clipQuoted(const std::string& s) {
  if (s.size() <= 120) return s;
  size_t end = 120;
  while (end > 0 && (static_cast<unsigned char>(s[end]) & 0xC0) == 0x80) --end;
  return s.substr(0, end) + "…";
}

// Deeper nesting is refused before parsing: tinygltf's JSON parser (nlohmann) recurses once per
// level and overflows the stack (SIGSEGV) near 100,000 levels. glTF itself nests < 10 levels;
// extras rarely reach 20.
constexpr int kMaxJsonDepth = 256;

// The deepest nesting of objects and arrays in the JSON text (strings and their escapes skipped),
// without recursion; counting stops above `limit`.
int jsonNestingDepth(const char* text, size_t size, int limit) {
  int depth = 0, deepest = 0;
  bool inString = false;
  for (size_t i = 0; i < size; ++i) {
    const char c = text[i];
    if (inString) {
      if (c == '\\')
        ++i;  // the escaped character, a quote included, is part of the string
      else if (c == '"')
        inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '{' || c == '[') {
      deepest = std::max(deepest, ++depth);
      if (deepest > limit) break;
    } else if (c == '}' || c == ']') {
      --depth;
    }
  }
  return deepest;
}

void checkJsonDepth(const std::string& path, const char* text, size_t size) {
  if (jsonNestingDepth(text, size, kMaxJsonDepth) > kMaxJsonDepth)
    throw inputError(
        path, "invalid gltf: JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
}

// Calls f(element, "bufferView 3") for each object of the top-level array `array`.
void forEach(const nlohmann::json& j, const char* array,
             const std::function<void(const nlohmann::json&, const std::string&)>& f) {
  auto it = j.find(array);
  if (it == j.end() || !it->is_array()) return;
  std::string name(array);
  name.pop_back();  // "bufferViews" -> "bufferView"
  for (size_t i = 0; i < it->size(); ++i)
    if ((*it)[i].is_object()) f((*it)[i], name + " " + std::to_string(i));
}

// tinygltf reads these with ParseUnsignedProperty, which keeps the default 0 without an error
// when the value is negative, fractional or not a number: a negative byteOffset silently read
// from the buffer's start (other meshes' data, hence garbage geometry and slow runs).
void checkUnsignedFields(const std::string& path, const nlohmann::json& j) {
  auto check = [&](const nlohmann::json& o, const char* key, const std::string& where) {
    if (!o.is_object() || !o.contains(key)) return;
    if (!o[key].is_number_unsigned())
      throw inputError(path, where + ": " + key + " " + clipQuoted(o[key].dump()) +
                                 " is not a non-negative integer");
  };
  forEach(j, "buffers",
          [&](const nlohmann::json& o, const std::string& w) { check(o, "byteLength", w); });
  forEach(j, "bufferViews", [&](const nlohmann::json& o, const std::string& w) {
    for (const char* key : {"byteOffset", "byteLength", "byteStride"}) check(o, key, w);
  });
  forEach(j, "accessors", [&](const nlohmann::json& o, const std::string& w) {
    check(o, "byteOffset", w);
    check(o, "count", w);
    if (!o.contains("sparse") || !o["sparse"].is_object()) return;
    const nlohmann::json& sparse = o["sparse"];
    check(sparse, "count", w + " sparse");
    for (const char* part : {"indices", "values"})
      if (sparse.contains(part)) check(sparse[part], "byteOffset", w + " sparse " + part);
  });
}

uint64_t unsignedField(const nlohmann::json& o, const char* key) {
  auto it = o.find(key);
  return it != o.end() && it->is_number_unsigned() ? it->get<uint64_t>() : 0;
}

// tinygltf hands an image's bufferView to the image decoder without checking that the view lies
// inside its buffer (an out-of-bounds read); a buffer holds exactly its byteLength.
void checkImageViews(const std::string& path, const nlohmann::json& j) {
  const nlohmann::json none = nlohmann::json::array();
  const nlohmann::json& views = j.contains("bufferViews") ? j["bufferViews"] : none;
  const nlohmann::json& buffers = j.contains("buffers") ? j["buffers"] : none;
  forEach(j, "images", [&](const nlohmann::json& o, const std::string& where) {
    if (!o.contains("bufferView") || !o["bufferView"].is_number_unsigned()) return;
    const uint64_t v = o["bufferView"].get<uint64_t>();
    if (!views.is_array() || v >= views.size() || !views[v].is_object()) return;  // tinygltf says
    const nlohmann::json& view = views[v];
    const uint64_t b = unsignedField(view, "buffer");
    if (!buffers.is_array() || b >= buffers.size() || !buffers[b].is_object()) return;
    const uint64_t offset = unsignedField(view, "byteOffset"),
                   length = unsignedField(view, "byteLength"),
                   size = unsignedField(buffers[b], "byteLength");
    if (offset > size || length > size - offset)
      throw inputError(path, where + ": bufferView " + std::to_string(v) + " (offset " +
                                 std::to_string(offset) + ", length " + std::to_string(length) +
                                 ") exceeds buffer " + std::to_string(b) + " of " +
                                 std::to_string(size) + " bytes");
  });
}

// buffers[].uri and images[].uri that are not data: URIs, in file order (buffers first).
std::vector<GltfExternalFile> externalFiles(const nlohmann::json& j, const std::string& baseDir) {
  std::vector<GltfExternalFile> files;
  auto add = [&](const char* array, GltfExternalFile::Kind kind) {
    auto it = j.find(array);
    if (it == j.end() || !it->is_array()) return;
    for (size_t i = 0; i < it->size(); ++i) {
      const nlohmann::json& o = (*it)[i];
      if (!o.is_object() || !o.contains("uri") || !o["uri"].is_string()) continue;
      GltfExternalFile f;
      f.kind = kind;
      f.index = i;
      f.uri = o["uri"].get<std::string>();
      f.scheme = gltfUriScheme(f.uri);
      if (f.scheme == "data") continue;
      if (f.scheme.empty()) f.path = gltfResolvePath(baseDir, f.uri);
      f.byteLength = kind == GltfExternalFile::Kind::kBuffer ? unsignedField(o, "byteLength") : 0;
      files.push_back(std::move(f));
    }
  };
  add("buffers", GltfExternalFile::Kind::kBuffer);
  add("images", GltfExternalFile::Kind::kImage);
  return files;
}

uint32_t readU32(const std::string& bytes, size_t at) {
  uint32_t v;
  std::memcpy(&v, bytes.data() + at, 4);
  return v;
}

// GLB (glTF section 4.4): 12-byte header (magic, version 2, total length), then the JSON chunk
// (length, type "JSON", text). Checked here before tinygltf sees the file (which checks the BIN
// chunk's length against the header's); returns the JSON text.
std::pair<const char*, size_t> glbJsonChunk(const std::string& path, const std::string& bytes) {
  const uint64_t fileSize = bytes.size();
  if (fileSize < 12)
    throw inputError(path, "truncated glb: " + std::to_string(fileSize) + " bytes");
  const uint32_t version = readU32(bytes, 4), length = readU32(bytes, 8);
  if (version != 2)
    throw inputError(path, "glb version " + std::to_string(version) + ", expected 2");
  if (length > fileSize)
    throw inputError(path, "truncated glb: header declares " + std::to_string(length) +
                               " bytes, file has " + std::to_string(fileSize));
  if (length < 20) throw inputError(path, "truncated glb: no JSON chunk");
  const uint32_t chunkLength = readU32(bytes, 12), chunkType = readU32(bytes, 16);
  if (chunkType != 0x4E4F534Au) throw inputError(path, "invalid glb: the first chunk is not JSON");
  if (chunkLength > length - 20)
    throw inputError(path, "invalid glb: JSON chunk of " + std::to_string(chunkLength) +
                               " bytes exceeds the file's " + std::to_string(length));
  return {bytes.data() + 20, chunkLength};
}

std::string readSceneBytes(const std::string& path) {
  std::vector<unsigned char> data;
  uint64_t size = 0;
  std::string why;
  if (!readRegularFile(path, kMaxSceneFileBytes, data, size, why, kMaxSceneFileBytes)) {
    if (why == "no such file") why = "cannot open file (no such file)";
    throw inputError(path, why);
  }
  return std::string(data.begin(), data.end());
}

}  // namespace

GltfSceneFile readGltfSceneFile(const std::string& path, bool requireJson) {
  GltfSceneFile f;
  f.path = path;
  f.baseDir = std::filesystem::path(path).parent_path().string();
  f.bytes = readSceneBytes(path);
  f.binary = f.bytes.size() >= 4 && std::memcmp(f.bytes.data(), "glTF", 4) == 0;
  if (f.binary) {
    std::tie(f.json, f.jsonSize) = glbJsonChunk(path, f.bytes);
  } else {
    f.json = f.bytes.data();
    f.jsonSize = f.bytes.size();
  }
  checkJsonDepth(path, f.json, f.jsonSize);
  f.document = nlohmann::json::parse(f.json, f.json + f.jsonSize, nullptr, false);
  if (!f.document.is_object()) {
    if (requireJson) throw inputError(path, "invalid gltf: not a JSON object");
    f.document = nullptr;  // tinygltf reports the syntax error
    return f;
  }
  checkUnsignedFields(path, f.document);
  checkImageViews(path, f.document);
  f.externalFiles = externalFiles(f.document, f.baseDir);
  return f;
}

}  // namespace rad
