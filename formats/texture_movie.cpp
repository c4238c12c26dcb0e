#include "formats/texture_movie.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <regex>
#include <tuple>
#include <utility>

#include <OpenEXR/openexr.h>

#include "formats/atomic_file.h"
#include "formats/checksum.h"
#include "formats/exr_header_scan.h"
#include "formats/exr_image.h"
#include "formats/pixel_checksum.h"
#include "formats/scanline_exr_writer.h"
#include "formats/uncompressed_exr_part.h"
#include "libcommon/core/error.h"

namespace rad {

void TextureMovie::keysAround(double t, size_t& k0, size_t& k1) const {
  if (keyTimes.size() == 1 || t <= keyTimes.front()) {
    k0 = k1 = 0;
  } else if (t >= keyTimes.back()) {
    k0 = k1 = keyTimes.size() - 1;
  } else {
    k1 = size_t(std::upper_bound(keyTimes.begin(), keyTimes.end(), t) - keyTimes.begin());
    k0 = k1 - 1;
  }
}

void TextureMovie::textureAt(double t, std::vector<float>& out) const {
  size_t n = size_t(width) * height * 3;
  out.resize(n);
  size_t k0, k1;
  keysAround(t, k0, k1);
  if (k0 == k1) {
    std::copy(keys[k0].begin(), keys[k0].end(), out.begin());
    return;
  }
  float w = keyWeight(t, k0, k1);
  const float* a = keys[k0].data();
  const float* b = keys[k1].data();
  for (size_t i = 0; i < n; ++i) out[i] = (1.0f - w) * a[i] + w * b[i];
}

TextureMovie textureMovieOf(const MovieExtent& extent, std::string provenanceJson) {
  TextureMovie m;
  m.movie = extent.movie;
  m.patch = extent.patch;
  m.firstFrame = extent.firstFrame;
  m.lastFrame = extent.lastFrame;
  m.width = extent.width;
  m.height = extent.height;
  m.provenanceJson = std::move(provenanceJson);
  return m;
}

std::string textureMoviePath(const std::string& dir, uint32_t id) {
  char name[32];
  std::snprintf(name, sizeof name, "/%06u.exr", id);
  return dir + name;
}

std::string textureMoviePiecePath(const std::string& dir, uint32_t id, int index) {
  char name[48];
  std::snprintf(name, sizeof name, "/%06u.piece-%04d.exr", id, index);
  return dir + name;
}

namespace {

std::string formatVersion(const TextureMoviePiece& piece) {
  return piece.isPiece() ? "texture-movie-piece " + std::to_string(kTextureMoviePieceMajor) + "." +
                               std::to_string(kTextureMoviePieceMinor)
                         : "texture-movie " + std::to_string(kTextureMovieMajor) + "." +
                               std::to_string(kTextureMovieMinor);
}

// The part headers' rad attributes (and name, type) of a movie with the given keys (key
// frames/times of the parts); ScanlineExrWriter adds the standard ones.
std::vector<std::vector<ExrAttribute>> movieHeaders(const TextureMovie& m,
                                                    const std::vector<int>& keyFrames,
                                                    const std::vector<double>& keyTimes) {
  using A = ExrAttribute;
  std::vector<std::vector<ExrAttribute>> headers(keyFrames.size());
  for (size_t k = 0; k < keyFrames.size(); ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "key%04zu", k);
    std::vector<ExrAttribute>& h = headers[k];
    h = {A::text("name", name),
         A::text("type", "scanlineimage"),
         A::text("rad.format", formatVersion(m.piece)),
         A::integer("rad.movie", int(m.movie)),
         A::text("rad.patch", m.patch.toString()),
         A::text("rad.patchPacked", std::to_string(m.patch.packed())),
         A::integer("rad.level", m.patch.level()),
         A::integer("rad.firstFrame", m.firstFrame),
         A::integer("rad.lastFrame", m.lastFrame),
         A::integer("rad.keyCount", int(keyFrames.size())),
         A::integer("rad.keyIndex", int(k)),
         A::integer("rad.keyFrame", keyFrames[k]),
         A::real("rad.keyTime", keyTimes[k]),
         A::text("rad.units", "irradiance W/m^2")};
    if (m.piece.isPiece()) {  // texture_movie_piece.md
      h.push_back(A::integer("rad.pieceIndex", m.piece.index));
      h.push_back(A::integer("rad.pieceCount", m.piece.count));
      h.push_back(A::integer("rad.pieceFirstKey", m.piece.firstKey));
      h.push_back(A::integer("rad.pieceKeys", m.piece.keys));
      h.push_back(A::integer("rad.movieKeyCount", m.piece.movieKeys));
    }
    if (k == 0 && !m.provenanceJson.empty())
      h.push_back(A::text("rad.provenance", m.provenanceJson));
    // The pixels are not known yet when the headers are laid out (keys stream in): a
    // placeholder of the checksum's length, filled in by commit() (fillInChecksums).
    h.push_back(A::text(kPixelChecksumAttribute, kPixelChecksumPlaceholder));
  }
  return headers;
}

}  // namespace

// Member order matters: the EXR writer is done (headers and chunk tables written) before the
// stream hands its last bytes to the temporary, and both before the AtomicFile renames or
// removes it.
struct TextureMovieWriter::File {
  AtomicFile atomic;
  std::unique_ptr<ExrFileStream> stream;
  std::unique_ptr<ScanlineExrWriter> exr;
  File(const std::string& path, AtomicFile::Durability d) : atomic(path, d) {}
};

TextureMovieWriter::TextureMovieWriter(std::string path, const TextureMovie& movie,
                                       bool storeConstantAsOneKey,
                                       AtomicFile::Durability durability)
    : path_(std::move(path)), durability_(durability), collapse_(storeConstantAsOneKey) {
  meta_.movie = movie.movie;
  meta_.patch = movie.patch;
  meta_.firstFrame = movie.firstFrame;
  meta_.lastFrame = movie.lastFrame;
  meta_.width = movie.width;
  meta_.height = movie.height;
  meta_.keyFrames = movie.keyFrames;
  meta_.keyTimes = movie.keyTimes;
  meta_.provenanceJson = movie.provenanceJson;
  meta_.piece = movie.piece;
  if (meta_.keyFrames.empty() || meta_.keyFrames.size() != meta_.keyTimes.size())
    throw Error(ExitCode::kInternal, path_, "texture movie keys, times and frames differ");
  if (meta_.width < 1 || meta_.height < 1)
    throw Error(ExitCode::kInternal, path_, "texture movie has no texel");
  texelFloats_ = size_t(meta_.width) * size_t(meta_.height) * 3;
}

TextureMovieWriter::~TextureMovieWriter() = default;

void TextureMovieWriter::open(size_t parts) {
  std::vector<int> frames(meta_.keyFrames.begin(), meta_.keyFrames.begin() + long(parts));
  std::vector<double> times(meta_.keyTimes.begin(), meta_.keyTimes.begin() + long(parts));
  if (!file_) file_ = std::make_unique<File>(path_, durability_);
  file_->exr.reset();
  file_->stream.reset();
  file_->stream = std::make_unique<ExrFileStream>(file_->atomic.tempPath(), path_);
  file_->exr = std::make_unique<ScanlineExrWriter>(*file_->stream, meta_.width, meta_.height,
                                                   movieHeaders(meta_, frames, times));
  checksums_.assign(parts, 0);
}

void TextureMovieWriter::writePart(size_t k, const std::vector<float>& rgb) {
  file_->exr->writePart(k, rgb.data());
  checksums_[k] = rgbPixelChecksum(rgb.data(), meta_.width, meta_.height);
}

void TextureMovieWriter::writeKey(size_t k, const std::vector<float>& rgb) {
  if (committed_ || k != next_ || k >= meta_.keyFrames.size())
    throw Error(ExitCode::kInternal, path_,
                "texture movie key " + std::to_string(k) + " written out of order");
  if (rgb.size() != texelFloats_)
    throw Error(ExitCode::kInternal, path_, "texture movie key has the wrong size");
  if (collapse_ && !diverged_) {
    if (k == 0) {
      key0_ = rgb;
      ++next_;
      return;
    }
    if (std::memcmp(key0_.data(), rgb.data(), texelFloats_ * sizeof(float)) == 0) {
      ++next_;
      return;
    }
    // Key k differs: the movie is not constant; keys 0..k-1 were all key 0.
    diverged_ = true;
    open(meta_.keyFrames.size());
    for (size_t i = 0; i < k; ++i) writePart(i, key0_);
    std::vector<float>().swap(key0_);
  } else if (!file_) {
    open(meta_.keyFrames.size());
  }
  writePart(k, rgb);
  ++next_;
}

size_t TextureMovieWriter::commit() {
  if (committed_ || next_ != meta_.keyFrames.size())
    throw Error(ExitCode::kInternal, path_,
                "texture movie committed after " + std::to_string(next_) + " of " +
                    std::to_string(meta_.keyFrames.size()) + " keys");
  size_t parts = meta_.keyFrames.size();
  if (collapse_ && !diverged_) {
    parts = 1;
    open(1);
    writePart(0, key0_);
  }
  fillInChecksums();
  file_->exr->finish();  // writes the headers and chunk tables
  file_->exr.reset();
  file_->stream->close();
  file_->atomic.commit();
  committed_ = true;
  return parts;
}

void TextureMovieWriter::fillInChecksums() {
  for (size_t k = 0; k < checksums_.size(); ++k)
    file_->exr->setText(k, kPixelChecksumAttribute, formatFnv1a64(checksums_[k]));
}

void writeTextureMovie(const std::string& path, const TextureMovie& m) {
  if (m.keys.empty() || m.keys.size() != m.keyTimes.size() || m.keys.size() != m.keyFrames.size())
    throw Error(ExitCode::kInternal, path, "texture movie keys, times and frames differ");
  const size_t n = size_t(m.width) * m.height * 3;
  for (const std::vector<float>& key : m.keys)
    if (key.size() != n)
      throw Error(ExitCode::kInternal, path, "texture movie key has the wrong size");
  TextureMovieWriter writer(path, m, false);
  for (size_t k = 0; k < m.keys.size(); ++k) writer.writeKey(k, m.keys[k]);
  writer.commit();
}

namespace {

// OpenEXR core contexts report through rad::inputError (checkExr), not stderr lines.
void quietExrError(exr_const_context_t, exr_result_t, const char*) {}

void checkExr(exr_result_t rv, const std::string& path, const char* what) {
  if (rv != EXR_ERR_SUCCESS)
    throw inputError(path, std::string(what) + ": " + exr_get_default_error_message(rv));
}

// A core context on `path` that reads the file itself (readTextureMovieHeaders; the streams
// read through their own window).
struct CoreExrFile {
  exr_context_t ctx = nullptr;
  explicit CoreExrFile(const std::string& path) {
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = quietExrError;
    const exr_result_t rv = exr_start_read(&ctx, path.c_str(), &init);
    if (rv != EXR_ERR_SUCCESS && ctx) exr_finish(&ctx);
    checkExr(rv, path, "cannot open");
  }
  ~CoreExrFile() {
    if (ctx) exr_finish(&ctx);
  }
  CoreExrFile(const CoreExrFile&) = delete;
  CoreExrFile& operator=(const CoreExrFile&) = delete;
};

// A part's attributes through OpenEXR's core (C) API, each missing or mistyped one an input error
// naming the file.
class PartAttributes {
 public:
  PartAttributes(exr_const_context_t ctx, int part, const std::string& path)
      : ctx_(ctx), part_(part), path_(path) {}

  std::string string(const char* name) const {
    std::optional<std::string> s = optionalString(name);
    if (!s) check(EXR_ERR_NO_ATTR_BY_NAME, name);
    return std::move(*s);
  }
  // Absent, or not a string: none.
  std::optional<std::string> optionalString(const char* name) const {
    const exr_attribute_t* a = nullptr;
    if (exr_get_attribute_by_name(ctx_, part_, name, &a) != EXR_ERR_SUCCESS || !a ||
        a->type != EXR_ATTR_STRING || !a->string)
      return {};
    const exr_attr_string_t& s = *a->string;
    return s.length > 0 && s.str ? std::string(s.str, size_t(s.length)) : std::string();
  }
  int integer(const char* name) const {
    int32_t v = 0;
    check(exr_attr_get_int(ctx_, part_, name, &v), name);
    return v;
  }
  double real(const char* name) const {
    double v = 0.0;
    check(exr_attr_get_double(ctx_, part_, name, &v), name);
    return v;
  }

 private:
  void check(exr_result_t rv, const char* name) const {
    if (rv != EXR_ERR_SUCCESS)
      throw inputError(path_, std::string("not a texture movie: no attribute ") + name);
  }
  exr_const_context_t ctx_;
  int part_;
  const std::string& path_;
};

// rad.format names what the reader expects (`kind`) in a version it reads. A piece read where a
// whole movie is expected (or the reverse) is refused by name: rad-compose must never take the
// first keys of a movie for the movie.
void checkFormatVersion(const PartAttributes& h, const std::string& fmt, MovieFileKind kind,
                        const std::string& path) {
  const std::string piecePrefix = "texture-movie-piece ", wholePrefix = "texture-movie ";
  const bool isPiece = fmt.rfind(piecePrefix, 0) == 0;
  if (!isPiece && fmt.rfind(wholePrefix, 0) != 0) throw inputError(path, "not a texture movie");
  if (isPiece && kind == MovieFileKind::kWhole)
    throw inputError(path, "a piece of texture movie " + std::to_string(h.integer("rad.movie")) +
                               " (" + fmt +
                               "), not a whole movie: rad-movies --merge-pieces "
                               "joins the pieces into the movie");
  if (!isPiece && kind == MovieFileKind::kPiece)
    throw inputError(path, "a whole texture movie, not a piece of one (texture-movie-piece)");
  const std::string version = fmt.substr(isPiece ? piecePrefix.size() : wholePrefix.size());
  const int major = std::atoi(version.c_str());
  const int supported = isPiece ? kTextureMoviePieceMajor : kTextureMovieMajor;
  if (!isPiece && major < kTextureMovieMajor)
    throw inputError(path, "texture-movie version " + version +
                               " is no longer read (its pixels carry no checksum): re-run "
                               "rad-movies");
  if (major != supported)
    throw inputError(path, fmt.substr(0, fmt.find(' ')) + " version " + version + ", expected " +
                               std::to_string(supported) + ".x");
}

// A piece's place in its movie (texture_movie_piece.md), checked against the file's `parts`.
TextureMoviePiece pieceOf(const PartAttributes& h, int parts, const std::string& path,
                          const std::string& part) {
  TextureMoviePiece p;
  p.index = h.integer("rad.pieceIndex");
  p.count = h.integer("rad.pieceCount");
  p.firstKey = h.integer("rad.pieceFirstKey");
  p.keys = h.integer("rad.pieceKeys");
  p.movieKeys = h.integer("rad.movieKeyCount");
  if (p.count < 1 || p.index < 0 || p.index >= p.count || p.firstKey < 0 || p.keys < 1 ||
      p.movieKeys < 1 || int64_t(p.firstKey) + p.keys > p.movieKeys ||
      (parts != p.keys && parts != 1))
    throw inputError(path, part + ": piece " + std::to_string(p.index) + " of " +
                               std::to_string(p.count) + ", keys " + std::to_string(p.firstKey) +
                               "+" + std::to_string(p.keys) + " of " + std::to_string(p.movieKeys) +
                               " in " + std::to_string(parts) + " parts: inconsistent");
  return p;
}

// Every part's header checked and the movie's metadata filled in (keys left empty), from a core
// context: OpenEXR's C++ reader, which this replaces, builds every part's Header (a map of
// allocated attributes) and reads the chunk tables, where the core context parses the headers
// alone.
TextureMovie readHeaders(exr_const_context_t ctx, const std::string& path, MovieFileKind kind) {
  TextureMovie m;
  int parts = 0;
  if (exr_get_count(ctx, &parts) != EXR_ERR_SUCCESS || parts < 1)
    throw inputError(path, "no parts");
  for (int k = 0; k < parts; ++k) {
    const PartAttributes h(ctx, k, path);
    const std::string part = "part " + std::to_string(k);
    const std::string fmt = h.string("rad.format");
    checkFormatVersion(h, fmt, kind, path);
    if (kind == MovieFileKind::kPiece) {
      const TextureMoviePiece piece = pieceOf(h, parts, path, part);
      if (k > 0 &&
          std::tie(piece.index, piece.count, piece.firstKey, piece.keys, piece.movieKeys) !=
              std::tie(m.piece.index, m.piece.count, m.piece.firstKey, m.piece.keys,
                       m.piece.movieKeys))
        throw inputError(path, part + ": piece attributes differ from part 0's");
      m.piece = piece;
    }
    const std::optional<std::string> stored = h.optionalString(kPixelChecksumAttribute);
    m.keyChecksums.push_back(requiredPixelChecksum(stored ? &*stored : nullptr, path, part));
    exr_attr_box2i_t dw;
    if (exr_get_data_window(ctx, k, &dw) != EXR_ERR_SUCCESS)
      throw inputError(path, part + ": invalid data window");
    const int64_t w = int64_t(dw.max.x) - dw.min.x + 1, hh = int64_t(dw.max.y) - dw.min.y + 1;
    if (dw.min.x != 0 || dw.min.y != 0 || w < 1 || hh < 1 || w > 16384 || hh > 16384)
      throw inputError(path, part + ": invalid data window");
    if (h.integer("rad.keyCount") != parts || h.integer("rad.keyIndex") != k)
      throw inputError(path, part + ": key index/count disagree");
    const exr_attr_chlist_t* channels = nullptr;
    if (exr_get_channels(ctx, k, &channels) != EXR_ERR_SUCCESS || !channels)
      throw inputError(path, part + ": no channel list");
    for (const char* c : {"R", "G", "B"}) {
      bool found = false;
      for (int i = 0; i < channels->num_channels; ++i) {
        const exr_attr_chlist_entry_t& e = channels->entries[i];
        if (e.name.length == 1 && e.name.str && e.name.str[0] == c[0])
          found = e.pixel_type == EXR_PIXEL_FLOAT;
      }
      if (!found) throw inputError(path, part + ": no FLOAT channel " + c);
    }
    // The checksum covers every channel and the readers decode R, G, B only.
    if (channels->num_channels != 3) throw inputError(path, part + ": channels other than R, G, B");
    if (k == 0) {
      m.width = int(w);
      m.height = int(hh);
      m.movie = uint32_t(h.integer("rad.movie"));
      const std::string packed = h.string("rad.patchPacked");
      char* end = nullptr;
      errno = 0;
      const unsigned long long v = std::strtoull(packed.c_str(), &end, 10);
      if (packed.empty() || errno != 0 || !end || *end != '\0')
        throw inputError(path, "malformed rad.patchPacked '" + packed + "'");
      m.patch = PatchId::fromPacked(uint64_t(v));
      m.firstFrame = h.integer("rad.firstFrame");
      m.lastFrame = h.integer("rad.lastFrame");
      if (std::optional<std::string> p = h.optionalString("rad.provenance"))
        m.provenanceJson = std::move(*p);
    } else if (w != m.width || hh != m.height) {
      throw inputError(path, "parts differ in size");
    }
    m.keyFrames.push_back(h.integer("rad.keyFrame"));
    m.keyTimes.push_back(h.real("rad.keyTime"));
    if (k > 0 && !(m.keyTimes[size_t(k)] > m.keyTimes[size_t(k) - 1]))
      throw inputError(path, "key times are not increasing");
  }
  if (m.firstFrame > m.lastFrame) throw inputError(path, "first frame after last frame");
  return m;
}

// Maps OpenEXR's exceptions to rad's one-line input error.
template <class F>
auto readingExr(const std::string& path, F&& f) {
  try {
    return f();
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw inputError(path, e.what());
  }
}

}  // namespace

// Every key through a stream: the one pixel reader (checksums, finite values), the file's headers
// parsed once.
TextureMovie readTextureMovie(const std::string& path) {
  TextureMovieStream stream(path);
  for (size_t k = 0; k < stream.movie().keyTimes.size(); ++k) stream.key(k);
  return stream.movie();
}

namespace {

// ExrHeaderScan's end of the headers if every part is one uncompressed chunk a scan line, else 0
// (TextureMovie::uncompressedTablesAt).
uint64_t uncompressedTablesAt(const ExrHeaderScan& scan) {
  for (const ExrScannedPart& p : scan.parts)
    if (p.type != "scanlineimage" || p.compression != 0 || p.chunks != uint64_t(p.height) ||
        p.height != scan.parts[0].height)
      return 0;
  return scan.headerBytes;
}

}  // namespace

TextureMovie readTextureMovieHeaders(const std::string& path, MovieFileKind kind) {
  return readingExr(path, [&] {
    const ExrHeaderScan scan = scanExrFile(path);
    TextureMovie m = readHeaders(CoreExrFile(path).ctx, path, kind);
    m.headerHash = scan.headerHash;
    m.uncompressedTablesAt = uncompressedTablesAt(scan);
    return m;
  });
}

// The pixels are read with OpenEXR's core (C) API: the C++ MultiPartInputFile keeps a decoder for
// every part it has read until the file is closed, and reopening it for each key parses every
// part's header each time. The core context holds only the headers and the chunk tables of the
// parts read.
//
// An uncompressed part is one chunk per scanline, and the core API reads each with its own pread, a
// system call per scanline. Reads go through a window instead (one pread fills it; the window is
// dropped after each key so memory stays flat).
struct TextureMovieStream::Reader {
  static constexpr size_t kWindow = size_t(1) << 16;
  exr_context_t ctx = nullptr;
  int fd = -1;
  int64_t fileSize = 0;
  std::mutex mutex;  // OpenEXR requires read_fn to be safe for concurrent calls
  std::vector<uint8_t> window;
  uint64_t windowOffset = 0;

  ~Reader() {
    if (ctx) exr_finish(&ctx);
    if (fd >= 0) ::close(fd);
  }

  // pread until sz bytes or end of file; -1 on error.
  int64_t readFully(void* buffer, uint64_t sz, uint64_t offset) const {
    uint64_t done = 0;
    while (done < sz) {
      const ssize_t n =
          ::pread(fd, static_cast<uint8_t*>(buffer) + done, sz - done, off_t(offset + done));
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) return -1;
      if (n == 0) break;
      done += uint64_t(n);
    }
    return int64_t(done);
  }

  static int64_t read(exr_const_context_t ctx, void* user, void* buffer, uint64_t sz,
                      uint64_t offset, exr_stream_error_func_ptr_t error) {
    Reader& r = *static_cast<Reader*>(user);
    std::lock_guard<std::mutex> lock(r.mutex);
    if (sz >= kWindow) {
      const int64_t n = r.readFully(buffer, sz, offset);
      if (n < 0 && error) error(ctx, EXR_ERR_READ_IO, "read failed: %s", std::strerror(errno));
      return n;
    }
    if (offset < r.windowOffset || offset + sz > r.windowOffset + r.window.size()) {
      r.window.resize(kWindow);
      const int64_t n = r.readFully(r.window.data(), kWindow, offset);
      if (n < 0) {
        r.window.clear();
        if (error) error(ctx, EXR_ERR_READ_IO, "read failed: %s", std::strerror(errno));
        return -1;
      }
      r.window.resize(size_t(n));
      r.windowOffset = offset;
    }
    const uint64_t available = std::min<uint64_t>(sz, r.windowOffset + r.window.size() - offset);
    std::memcpy(buffer, r.window.data() + (offset - r.windowOffset), size_t(available));
    return int64_t(available);
  }

  static int64_t size(exr_const_context_t, void* user) {
    return static_cast<Reader*>(user)->fileSize;
  }

  void dropWindow() {
    std::lock_guard<std::mutex> lock(mutex);
    std::vector<uint8_t>().swap(window);
    windowOffset = 0;
  }
};

TextureMovieStream::TextureMovieStream(std::string path, MovieFileKind kind)
    : path_(std::move(path)) {
  const ExrHeaderScan scan = readingExr(path_, [&] { return scanExrFile(path_); });
  open();
  startExr();
  movie_ = readHeaders(reader_->ctx, path_, kind);
  movie_.uncompressedTablesAt = uncompressedTablesAt(scan);
  movie_.keys.assign(movie_.keyTimes.size(), {});
}

TextureMovieStream::TextureMovieStream(std::string path, TextureMovie headers)
    : path_(std::move(path)), movie_(std::move(headers)) {
  open();
  movie_.keys.assign(movie_.keyTimes.size(), {});
  if (movie_.uncompressedTablesAt == 0) startExr();
}

void TextureMovieStream::open() {
  reader_ = std::make_unique<Reader>();
  reader_->fd = ::open(path_.c_str(), O_RDONLY | O_CLOEXEC);
  struct stat st;
  if (reader_->fd < 0 || ::fstat(reader_->fd, &st) != 0)
    throw inputError(path_, std::string("cannot open: ") + std::strerror(errno));
  reader_->fileSize = int64_t(st.st_size);
}

void TextureMovieStream::startExr() {
  if (reader_->ctx) return;
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.error_handler_fn = quietExrError;  // errors become rad::inputError, not stderr lines
  init.user_data = reader_.get();
  init.read_fn = &Reader::read;
  init.size_fn = &Reader::size;
  checkExr(exr_start_read(&reader_->ctx, path_.c_str(), &init), path_, "cannot open");
  int parts = 0;
  checkExr(exr_get_count(reader_->ctx, &parts), path_, "part count");
  if (size_t(parts) != movie_.keyTimes.size() && !movie_.keyTimes.empty())
    throw inputError(path_, "changed since its headers were read: " + std::to_string(parts) +
                                " parts, not " + std::to_string(movie_.keyTimes.size()));
}

TextureMovieStream::~TextureMovieStream() = default;

void TextureMovieStream::load(size_t k) {
  if (!movie_.keys[k].empty()) return;
  const int part = int(k), w = movie_.width, h = movie_.height;
  std::vector<float> px;
  const uint64_t at = movie_.uncompressedTablesAt;
  if (at == 0 || !readUncompressedRgbPart(reader_->fd, uncompressedPartTableAt(at, part, h),
                                          movie_.keyTimes.size() > 1, part, w, h, px)) {
    startExr();
    decodeWithOpenExr(k, px);
  }
  requirePixelChecksum(movie_.keyChecksums[k], rgbPixelChecksum(px.data(), w, h), path_,
                       "part " + std::to_string(k));
  for (float v : px)
    if (!std::isfinite(v))
      throw inputError(path_, "non-finite irradiance in part " + std::to_string(k));
  movie_.keys[k] = std::move(px);
  ++keysRead_;
}

// Key k through OpenEXR's core decoder, any compression and layout.
void TextureMovieStream::decodeWithOpenExr(size_t k, std::vector<float>& px) {
  const int part = int(k), w = movie_.width, h = movie_.height;
  exr_context_t ctx = reader_->ctx;
  px.assign(size_t(w) * size_t(h) * 3, 0.0f);
  int32_t linesPerChunk = 0;
  checkExr(exr_get_scanlines_per_chunk(ctx, part, &linesPerChunk), path_, "part header");
  if (linesPerChunk < 1) throw inputError(path_, "part " + std::to_string(k) + ": no scanlines");
  exr_decode_pipeline_t decoder = EXR_DECODE_PIPELINE_INITIALIZER;
  struct Destroy {
    exr_context_t ctx;
    exr_decode_pipeline_t* d;
    ~Destroy() { exr_decoding_destroy(ctx, d); }
  } destroy{ctx, &decoder};
  bool first = true;
  for (int y = 0; y < h; y += linesPerChunk) {
    exr_chunk_info_t chunk;
    checkExr(exr_read_scanline_chunk_info(ctx, part, y, &chunk), path_, "chunk table");
    if (chunk.start_y < 0 || chunk.height < 1 || chunk.start_y + chunk.height > h ||
        chunk.width != w)
      throw inputError(path_, "part " + std::to_string(k) + ": chunk outside the image");
    checkExr(first ? exr_decoding_initialize(ctx, part, &chunk, &decoder)
                   : exr_decoding_update(ctx, part, &chunk, &decoder),
             path_, "decoding");
    for (int c = 0; c < decoder.channel_count; ++c) {
      exr_coding_channel_info_t& ch = decoder.channels[c];
      std::string name = ch.channel_name ? ch.channel_name : "";
      int offset = name == "R" ? 0 : name == "G" ? 1 : name == "B" ? 2 : -1;
      if (offset < 0 || ch.height != chunk.height || ch.width != w) {
        ch.decode_to_ptr = nullptr;  // not ours (or subsampled): skipped
        continue;
      }
      ch.decode_to_ptr =
          reinterpret_cast<uint8_t*>(px.data() + size_t(chunk.start_y) * size_t(w) * 3 + offset);
      ch.user_pixel_stride = 3 * int32_t(sizeof(float));
      ch.user_line_stride = w * 3 * int32_t(sizeof(float));
      ch.user_data_type = EXR_PIXEL_FLOAT;
      ch.user_bytes_per_element = int16_t(sizeof(float));
    }
    if (first)
      checkExr(exr_decoding_choose_default_routines(ctx, part, &decoder), path_, "decoding");
    first = false;
    checkExr(exr_decoding_run(ctx, part, &decoder), path_, "decoding");
  }
  reader_->dropWindow();
}

const std::vector<float>& TextureMovieStream::key(size_t k) {
  if (k >= movie_.keys.size())
    throw Error(ExitCode::kInternal, path_, "no key " + std::to_string(k));
  load(k);
  return movie_.keys[k];
}

void TextureMovieStream::loadAround(double t, size_t& k0, size_t& k1) {
  // The keys TextureMovie::textureAt reads at t; every other one is dropped.
  movie_.keysAround(t, k0, k1);
  for (size_t k = 0; k < movie_.keys.size(); ++k)
    if (k != k0 && k != k1) std::vector<float>().swap(movie_.keys[k]);
  load(k0);
  load(k1);
}

void TextureMovieStream::textureAt(double t, std::vector<float>& out) {
  size_t k0, k1;
  loadAround(t, k0, k1);
  movie_.textureAt(t, out);
}

void TextureMovieStream::keysAt(double t, const float*& from, const float*& to, float& weight) {
  size_t k0, k1;
  loadAround(t, k0, k1);
  from = movie_.keys[k0].data();
  to = k0 == k1 ? nullptr : movie_.keys[k1].data();
  weight = k0 == k1 ? 0.0f : movie_.keyWeight(t, k0, k1);
}

nlohmann::json summarizeTextureMovieDirectory(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw inputError(dir, "is not a directory");
  std::vector<std::string> files;
  static const std::regex name("[0-9]{6}\\.exr");
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (std::regex_match(e.path().filename().string(), name)) files.push_back(e.path().string());
  if (ec) throw inputError(dir, ec.message());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw inputError(dir, "no texture movie (NNNNNN.exr) in it");
  size_t keys = 0, constant = 0, bytes = 0;
  double texels = 0, minH = 1e300, maxH = -1e300;
  int first = 1 << 30, last = -(1 << 30);
  std::map<int, int> levels;
  for (const std::string& f : files) {
    TextureMovie m = readTextureMovie(f);
    keys += m.keys.size();
    constant += m.constant();
    bytes += size_t(fs::file_size(f, ec));
    texels += double(m.width) * m.height * (m.lastFrame - m.firstFrame + 1);
    first = std::min(first, m.firstFrame);
    last = std::max(last, m.lastFrame);
    levels[m.patch.level()]++;
    for (const auto& k : m.keys)
      for (float v : k) {
        minH = std::min(minH, double(v));
        maxH = std::max(maxH, double(v));
      }
  }
  nlohmann::json lv = nlohmann::json::object();
  for (auto& [l, n] : levels) lv[std::to_string(l)] = n;
  return {{"type", "texture-movies"},
          {"path", dir},
          {"movies", files.size()},
          {"keys", keys},
          {"constant_movies", constant},
          {"frames", {first, last}},
          {"texel_frames", texels},
          {"movies_per_level", lv},
          {"bytes", bytes},
          {"irradiance", {{"min", minH}, {"max", maxH}}}};
}

}  // namespace rad
