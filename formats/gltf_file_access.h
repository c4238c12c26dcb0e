// How the glTF reader touches the file system (spec: formats/gltf_scene.md "Files"): only
// regular files are opened, every read is bounded, and an image is decoded only when its header
// says it is within the pixel limit. Used by gltf_scene.cpp (through tinygltf's callbacks) and
// by gltf_inputs.cpp (rad-inspect --inputs).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace tinygltf {
class TinyGLTF;
struct Image;
}  // namespace tinygltf

namespace rad {

// A .gltf or .glb larger than this is refused before it is read (the JSON of the largest
// scenes this toolchain handles is a few hundred MB).
constexpr uint64_t kMaxSceneFileBytes = uint64_t(1) << 30;
// An external image file larger than this is ignored like an undecodable one (a PNG of
// kMaxTexturePixels RGBA 16-bit texels stored uncompressed is 512 MiB).
constexpr uint64_t kMaxImageFileBytes = uint64_t(1) << 30;
// Default bound on the pixels of one decoded image (8192 x 8192), checked from the image header
// before decoding; tools change it with --max-texture-pixels.
constexpr uint64_t kMaxTexturePixels = uint64_t(8192) * 8192;

// "" when `path` is a regular file (symbolic links followed), otherwise why it will not be read,
// without opening it (open() on a FIFO blocks): "no such file", "not a regular file (a FIFO)",
// "not a regular file (a directory)", "not a regular file (a character device)", or strerror.
std::string regularFileProblem(const std::string& path);

// Reads `path` if it is a regular file: stat before opening, opened non-blocking, checked again
// with fstat (a file swapped for a FIFO in between is refused, not waited on). Reads at most
// `limit` bytes into `out`; `fileSize` gets the file's size. A file larger than `refuseAbove` is
// not read ("file of N bytes, beyond the limit of M"). Returns false with `why` set (as
// regularFileProblem, or "cannot read: strerror").
bool readRegularFile(const std::string& path, uint64_t limit, std::vector<unsigned char>& out,
                     uint64_t& fileSize, std::string& why, uint64_t refuseAbove = UINT64_MAX);

// tinygltf's percent-decoding of a URI (dlib::urldecode: "%XX" -> byte, '+' -> space), which it
// applies before joining a URI to the scene's folder.
std::string gltfUriDecode(const std::string& uri);
// The scheme of a URI ("http", "file", "data"), lowercase, or "" for a relative reference.
std::string gltfUriScheme(const std::string& uri);
// The path tinygltf opens for a relative URI: `baseDir` + "/" + decoded URI ("" base: the URI).
std::string gltfResolvePath(const std::string& baseDir, const std::string& uri);

// One buffers[] or images[] entry with a "uri" that is not a data: URI.
struct GltfExternalFile {
  enum class Kind { kBuffer, kImage };
  Kind kind = Kind::kBuffer;
  size_t index = 0;     // in buffers[] or images[]
  std::string uri;      // as written in the file
  std::string scheme;   // gltfUriScheme(uri); not "" -> never read (http:, file:, ...)
  std::string path;     // gltfResolvePath(baseDir, uri) when scheme is ""
  uint64_t byteLength;  // buffers: the declared byteLength; images: 0
};

// The tinygltf callbacks of one load: file access only to the paths of `files` (no fallback to
// the working directory, which tinygltf tries when a URI is not found beside the scene), only
// regular files, buffers read up to their byteLength, images up to kMaxImageFileBytes; images
// decoded by stb_image after stbi_info says they have at most `maxPixels` pixels. An image that
// cannot be read or decoded is left empty (the load goes on) and why is kept for the warning.
// Decoding out of memory throws std::bad_alloc.
class GltfLoaderHooks {
 public:
  GltfLoaderHooks(const std::vector<GltfExternalFile>& files, uint64_t maxPixels);
  GltfLoaderHooks(const GltfLoaderHooks&) = delete;
  GltfLoaderHooks& operator=(const GltfLoaderHooks&) = delete;

  // Sets the file-system callbacks and the image loader of `loader`; this object must outlive
  // the load.
  void install(tinygltf::TinyGLTF& loader);

  // Why image `index` has no pixels: "not a regular file (a FIFO)", "12000x12000 pixels, above
  // the limit of ...", "URI scheme 'http' is not read", ...; "" when nothing is known.
  std::string imageProblem(size_t index) const;
  // The first buffer whose file could not be read, as "buffer 0 'a.bin': why"; "" if none.
  std::string bufferProblem() const;

 private:
  // tinygltf's FsCallbacks; `user` is this object.
  static bool fileExists(const std::string& path, void* user);
  static std::string expandFilePath(const std::string& path, void* user);
  static bool readWholeFile(std::vector<unsigned char>* out, std::string* err,
                            const std::string& path, void* user);
  static bool writeWholeFile(std::string* err, const std::string& path,
                             const std::vector<unsigned char>& contents, void* user);
  static bool loadImage(tinygltf::Image* image, int index, std::string* err, std::string* warn,
                        int width, int height, const unsigned char* bytes, int size, void* user);
  void decode(tinygltf::Image& image, size_t index, const unsigned char* bytes, size_t size);

  std::vector<GltfExternalFile> files_;
  std::map<std::string, uint64_t> readLimit_;       // resolved path -> bytes read at most
  std::map<std::string, std::string> fileProblem_;  // resolved path -> why it was not read
  std::map<size_t, std::string> imageProblem_;      // image index -> why it has no pixels
  uint64_t maxPixels_;
};

}  // namespace rad
