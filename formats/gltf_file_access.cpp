// File access of the glTF reader (spec: formats/gltf_scene.md "Files", "Materials").
//
// tinygltf opens external files itself (FsCallbacks) and decodes images itself (stb_image through
// its LoadImageData callback). Its defaults open any path with fopen (a FIFO blocks forever, a
// directory reads as an endless stream, /dev/zero without end), fall back to the working
// directory, and decode an image of any size. These callbacks replace them.
#include "formats/gltf_file_access.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <tiny_gltf.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <memory>
#include <new>

#include <stb/stb_image.h>

namespace rad {

namespace {

unsigned char uchar(char c) {
  return static_cast<unsigned char>(c);
}

// Quoted input is cut at 120 bytes (at a UTF-8 boundary), as every quote of gltf_scene.cpp.
std::string quoted(const std::string& s) {
  if (s.size() <= 120) return "'" + s + "'";
  size_t end = 120;
  while (end > 0 && (uchar(s[end]) & 0xC0) == 0x80) --end;
  return "'" + s.substr(0, end) + "…'";
}

std::string kindProblem(mode_t mode) {
  if (S_ISREG(mode)) return "";
  if (S_ISFIFO(mode)) return "not a regular file (a FIFO)";
  if (S_ISDIR(mode)) return "not a regular file (a directory)";
  if (S_ISCHR(mode)) return "not a regular file (a character device)";
  if (S_ISBLK(mode)) return "not a regular file (a block device)";
  if (S_ISSOCK(mode)) return "not a regular file (a socket)";
  return "not a regular file";
}

std::string statProblem(int error) {
  return error == ENOENT ? std::string("no such file") : std::string(std::strerror(error));
}

std::string pixelsText(uint64_t pixels) {
  return std::to_string(pixels / 1000000) + "." + std::to_string(pixels / 100000 % 10) +
         " megapixels";
}

}  // namespace

std::string regularFileProblem(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) return statProblem(errno);
  return kindProblem(st.st_mode);
}

bool readRegularFile(const std::string& path, uint64_t limit, std::vector<unsigned char>& out,
                     uint64_t& fileSize, std::string& why, uint64_t refuseAbove) {
  out.clear();
  fileSize = 0;
  why = regularFileProblem(path);  // before open(): opening a FIFO or a device has effects
  if (!why.empty()) return false;
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    why = statProblem(errno);
    return false;
  }
  struct stat st;
  const bool statted = ::fstat(fd, &st) == 0;
  if (!statted || !S_ISREG(st.st_mode)) {
    why = statted ? kindProblem(st.st_mode) : statProblem(errno);
    ::close(fd);
    return false;
  }
  fileSize = uint64_t(st.st_size);
  if (fileSize > refuseAbove) {
    why = "file of " + std::to_string(fileSize) + " bytes, beyond the limit of " +
          std::to_string(refuseAbove);
    ::close(fd);
    return false;
  }
  out.resize(size_t(std::min(fileSize, limit)));
  size_t done = 0;
  while (done < out.size()) {
    const ssize_t n = ::read(fd, out.data() + done, out.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      why = std::string("cannot read: ") + std::strerror(errno);
      ::close(fd);
      return false;
    }
    if (n == 0) break;  // shrank since fstat
    done += size_t(n);
  }
  ::close(fd);
  out.resize(done);
  return true;
}

std::string gltfUriDecode(const std::string& uri) {
  auto hex = [](unsigned char c) -> unsigned char {  // dlib::from_hex: not a digit -> 0
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return 0;
  };
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '+') {
      out += ' ';
    } else if (uri[i] == '%' && uri.size() > i + 2) {
      out += char((hex(uchar(uri[i + 1])) << 4) | hex(uchar(uri[i + 2])));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

std::string gltfUriScheme(const std::string& uri) {
  // RFC 3986 section 3.1: scheme = ALPHA *( ALPHA / DIGIT / "+" / "-" / "." ) ":"
  if (uri.empty() || !std::isalpha(uchar(uri[0]))) return "";
  for (size_t i = 1; i < uri.size(); ++i) {
    const char c = uri[i];
    if (c == ':') {
      std::string scheme = uri.substr(0, i);
      for (char& s : scheme) s = char(std::tolower(uchar(s)));
      return scheme;
    }
    if (!std::isalnum(uchar(c)) && c != '+' && c != '-' && c != '.') return "";
  }
  return "";
}

std::string gltfResolvePath(const std::string& baseDir, const std::string& uri) {
  const std::string decoded = gltfUriDecode(uri);
  if (baseDir.empty()) return decoded;  // tinygltf's JoinPath
  return baseDir.back() == '/' ? baseDir + decoded : baseDir + "/" + decoded;
}

GltfLoaderHooks::GltfLoaderHooks(const std::vector<GltfExternalFile>& files, uint64_t maxPixels)
    : files_(files), maxPixels_(maxPixels) {
  for (const GltfExternalFile& f : files_) {
    if (!f.scheme.empty()) continue;
    const uint64_t limit =
        f.kind == GltfExternalFile::Kind::kBuffer ? f.byteLength : kMaxImageFileBytes;
    auto [it, added] = readLimit_.emplace(f.path, limit);
    if (!added) it->second = std::max(it->second, limit);
  }
}

void GltfLoaderHooks::install(tinygltf::TinyGLTF& loader) {
  tinygltf::FsCallbacks fs{};
  fs.FileExists = &GltfLoaderHooks::fileExists;
  fs.ExpandFilePath = &GltfLoaderHooks::expandFilePath;
  fs.ReadWholeFile = &GltfLoaderHooks::readWholeFile;
  fs.WriteWholeFile = &GltfLoaderHooks::writeWholeFile;
  fs.user_data = this;
  loader.SetFsCallbacks(fs);
  loader.SetImageLoader(&GltfLoaderHooks::loadImage, this);
}

bool GltfLoaderHooks::fileExists(const std::string& path, void* user) {
  auto* self = static_cast<GltfLoaderHooks*>(user);
  if (!self->readLimit_.count(path)) return false;  // e.g. tinygltf's "./" + uri fallback
  const std::string why = regularFileProblem(path);
  if (!why.empty()) self->fileProblem_.emplace(path, why);
  return why.empty();
}

std::string GltfLoaderHooks::expandFilePath(const std::string& path, void*) {
  return path;  // no ~ or $VAR expansion (tinygltf's own default since 2.6)
}

bool GltfLoaderHooks::readWholeFile(std::vector<unsigned char>* out, std::string* err,
                                    const std::string& path, void* user) {
  auto* self = static_cast<GltfLoaderHooks*>(user);
  auto limit = self->readLimit_.find(path);
  std::string why = "not a file this scene references";
  uint64_t size = 0;
  const bool image = std::any_of(self->files_.begin(), self->files_.end(), [&](const auto& f) {
    return f.path == path && f.kind == GltfExternalFile::Kind::kImage;
  });
  if (limit != self->readLimit_.end() && readRegularFile(path, limit->second, *out, size, why,
                                                         image ? kMaxImageFileBytes : UINT64_MAX)) {
    if (size == 0) {
      why = "empty file";
    } else if (!image && size < limit->second) {
      why = "file has " + std::to_string(size) + " bytes, byteLength declares " +
            std::to_string(limit->second);
    } else {
      return true;
    }
    out->clear();
  }
  self->fileProblem_.emplace(path, why);
  if (err) *err += why;
  return false;
}

bool GltfLoaderHooks::writeWholeFile(std::string* err, const std::string&,
                                     const std::vector<unsigned char>&, void*) {
  if (err) *err += "the reader writes no files";
  return false;
}

bool GltfLoaderHooks::loadImage(tinygltf::Image* image, int index, std::string*, std::string*, int,
                                int, const unsigned char* bytes, int size, void* user) {
  auto* self = static_cast<GltfLoaderHooks*>(user);
  if (image && index >= 0 && bytes && size > 0)
    self->decode(*image, size_t(index), bytes, size_t(size));
  return true;  // an image without pixels is the reader's warning, never a failed load
}

void GltfLoaderHooks::decode(tinygltf::Image& image, size_t index, const unsigned char* bytes,
                             size_t size) {
  const int length = int(std::min<size_t>(size, size_t(INT32_MAX)));
  int w = 0, h = 0, comp = 0;
  if (!stbi_info_from_memory(bytes, length, &w, &h, &comp)) {
    imageProblem_[index] = std::string("not an image stb_image reads (") + stbi_failure_reason() +
                           "); PNG and JPEG are supported";
    return;
  }
  const uint64_t pixels = uint64_t(std::max(w, 0)) * uint64_t(std::max(h, 0));
  if (pixels > maxPixels_) {
    imageProblem_[index] = std::to_string(w) + "x" + std::to_string(h) + " pixels (" +
                           pixelsText(pixels) + "), above the limit of " + pixelsText(maxPixels_) +
                           " (--max-texture-pixels)";
    return;
  }
  // Channels as stored (1-4), 16 bits when the file has them; as tinygltf's own loader.
  const bool sixteen = stbi_is_16_bit_from_memory(bytes, length) != 0;
  std::unique_ptr<void, void (*)(void*)> data(
      sixteen ? static_cast<void*>(stbi_load_16_from_memory(bytes, length, &w, &h, &comp, 0))
              : static_cast<void*>(stbi_load_from_memory(bytes, length, &w, &h, &comp, 0)),
      &stbi_image_free);
  if (!data) {
    const std::string reason = stbi_failure_reason() ? stbi_failure_reason() : "unknown";
    if (reason == "outofmem") throw std::bad_alloc();
    imageProblem_[index] = "cannot be decoded (stb_image: " + reason + "; truncated or corrupt)";
    return;
  }
  const size_t bytesPer = sixteen ? 2 : 1;
  const auto* p = static_cast<const unsigned char*>(data.get());
  image.image.assign(p, p + size_t(w) * size_t(h) * size_t(comp) * bytesPer);
  image.width = w;
  image.height = h;
  image.component = comp;
  image.bits = sixteen ? 16 : 8;
  image.pixel_type =
      sixteen ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT : TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
}

std::string GltfLoaderHooks::imageProblem(size_t index) const {
  auto decoded = imageProblem_.find(index);
  if (decoded != imageProblem_.end()) return decoded->second;
  for (const GltfExternalFile& f : files_) {
    if (f.kind != GltfExternalFile::Kind::kImage || f.index != index) continue;
    if (!f.scheme.empty())
      return "URI scheme '" + f.scheme + ":' is not read (only relative paths and data: URIs)";
    auto read = fileProblem_.find(f.path);
    const std::string why = read != fileProblem_.end() ? read->second : "cannot be read";
    // An absolute or "../" URI is joined to the scene's folder like any other (as tinygltf does).
    return why == "no such file" && f.path != f.uri ? why + " (looked for " + quoted(f.path) + ")"
                                                    : why;
  }
  return "";
}

std::string GltfLoaderHooks::bufferProblem() const {
  for (const GltfExternalFile& f : files_) {
    if (f.kind != GltfExternalFile::Kind::kBuffer) continue;
    std::string why;
    if (!f.scheme.empty()) {
      why = "URI scheme '" + f.scheme + ":' is not read (only relative paths and data: URIs)";
    } else {
      auto read = fileProblem_.find(f.path);
      if (read == fileProblem_.end()) continue;
      why = read->second;
    }
    return "buffer " + std::to_string(f.index) + " " + quoted(f.uri) + ": " + why;
  }
  return "";
}

}  // namespace rad
