// The OpenEXR file layout (openexr.com, "OpenEXR File Layout"): magic 20000630, a version field
// (2, with flags 0x200 single-part tiled, 0x400 long names, 0x800 deep, 0x1000 multi-part), then
// each part's header as attributes "name\0type\0" int32 size, value, ended by an empty name
// (a multi-part file's headers end with one more empty header), then each part's offset table,
// one uint64 per chunk, then the chunks. Bounds in exr_header_scan.h.
#include "formats/exr_header_scan.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <optional>

#include "formats/checksum.h"
#include "libcommon/core/error.h"

namespace rad {

namespace {

constexpr uint32_t kMagic = 20000630;
constexpr uint32_t kFlagTiled = 0x200, kFlagLongNames = 0x400, kFlagDeep = 0x800,
                   kFlagMultiPart = 0x1000;
constexpr size_t kMaxName = 256;  // names and types, with their terminator (long names: 255)
constexpr uint64_t kMiB = uint64_t(1) << 20;

// Imf::Compression: NONE RLE ZIPS ZIP PIZ PXR24 B44 B44A DWAA DWAB.
constexpr int kCompressions = 10;
// Scan lines per chunk of each compression (OpenEXR's numLinesInBuffer).
constexpr int kLinesPerChunk[kCompressions] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};

// The bytes a file holds, read on demand from the start (the headers are read in full, the
// pixels never).
class Bytes {
 public:
  Bytes(const uint8_t* data, size_t size) : data_(data), have_(size), fileBytes_(size) {}
  Bytes(int fd, uint64_t fileBytes) : fd_(fd), fileBytes_(fileBytes) {}
  uint64_t fileBytes() const { return fileBytes_; }
  // True if [0, end) is in the file (and now in memory).
  bool ensure(uint64_t end, const std::string& name) {
    if (end > fileBytes_) return false;
    if (end <= have_) return true;
    // Grow geometrically (64 KiB first) so a header of many attributes takes few reads.
    const uint64_t want =
        std::min(fileBytes_, std::max({end, uint64_t(have_) * 2, uint64_t(64 * 1024)}));
    buffer_.resize(size_t(want));
    while (have_ < want) {
      const ssize_t n = ::pread(fd_, buffer_.data() + have_, size_t(want - have_), off_t(have_));
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) throw inputError(name, std::string("cannot read: ") + std::strerror(errno));
      if (n == 0) {  // shorter than fstat said (changing under us): what we have is the file
        fileBytes_ = have_;
        buffer_.resize(have_);
        break;
      }
      have_ += size_t(n);
    }
    data_ = buffer_.data();
    return end <= have_;
  }
  const uint8_t* at(uint64_t pos) const { return data_ + pos; }

 private:
  const uint8_t* data_ = nullptr;
  size_t have_ = 0;
  int fd_ = -1;
  uint64_t fileBytes_ = 0;
  std::vector<uint8_t> buffer_;
};

// a * b, or kSaturated if that is more.
constexpr uint64_t kSaturated = uint64_t(1) << 62;
uint64_t product(uint64_t a, uint64_t b) {
  return a != 0 && b > kSaturated / a ? kSaturated : std::min(kSaturated, a * b);
}

uint32_t le32(const uint8_t* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}
int32_t lei32(const uint8_t* p) {
  const uint32_t u = le32(p);
  int32_t v;
  std::memcpy(&v, &u, sizeof v);
  return v;
}

// A name from the file for a message: printable ASCII, at most 40 characters.
std::string shown(const std::string& s) {
  std::string out;
  for (char c : s.substr(0, 40)) out += c >= 0x20 && c < 0x7f ? c : '?';
  return s.size() > 40 ? out + "..." : out;
}

struct Channel {
  int bytes = 0;  // per sample
  int64_t xSampling = 1, ySampling = 1;
};

// What a header declares that the bounds need.
struct PartHeader {
  std::optional<std::vector<Channel>> channels;
  std::optional<int> compression;
  int32_t window[4] = {};  // min.x, min.y, max.x, max.y
  bool hasWindow = false;
  std::optional<std::string> type;
  std::optional<int32_t> chunkCount;
  std::optional<uint32_t> tileX, tileY;
};

// The value size of OpenEXR's fixed-size attribute types (0: not one). OpenEXR reads these
// many bytes whatever the declared size, so a different size would make its walk through the
// header and this scan's part ways (a fuzzed 126-byte box2i led it to a 1.6 GB string).
uint32_t fixedSize(const std::string& type) {
  static const std::pair<const char*, uint32_t> kSizes[] = {{"box2i", 16},
                                                            {"box2f", 16},
                                                            {"chromaticities", 32},
                                                            {"compression", 1},
                                                            {"deepImageState", 1},
                                                            {"double", 8},
                                                            {"envmap", 1},
                                                            {"float", 4},
                                                            {"int", 4},
                                                            {"keycode", 28},
                                                            {"lineOrder", 1},
                                                            {"m33d", 72},
                                                            {"m33f", 36},
                                                            {"m44d", 128},
                                                            {"m44f", 64},
                                                            {"rational", 8},
                                                            {"tiledesc", 9},
                                                            {"timecode", 8},
                                                            {"v2d", 16},
                                                            {"v2f", 8},
                                                            {"v2i", 8},
                                                            {"v3d", 24},
                                                            {"v3f", 12},
                                                            {"v3i", 12}};
  for (const auto& [name, size] : kSizes)
    if (type == name) return size;
  return 0;
}

std::string singlePartType(uint32_t version) {
  if (version & kFlagDeep) return (version & kFlagTiled) ? "deeptile" : "deepscanline";
  return (version & kFlagTiled) ? "tiledimage" : "scanlineimage";
}

class Scanner {
 public:
  Scanner(Bytes& bytes, const std::string& name) : bytes_(bytes), name_(name) {}

  ExrHeaderScan scan() {
    need(8);
    if (le32(bytes_.at(0)) != kMagic) fail("not an OpenEXR file (no magic number 20000630)");
    const uint32_t version = le32(bytes_.at(4));
    if ((version & 0xff) != 2)
      fail("OpenEXR version " + std::to_string(version & 0xff) + ", expected 2");
    if ((version & ~0xffu & ~(kFlagTiled | kFlagLongNames | kFlagDeep | kFlagMultiPart)) != 0)
      fail("unknown OpenEXR version flags " + std::to_string(version & ~0xffu));
    pos_ = 8;
    const bool multiPart = (version & kFlagMultiPart) != 0;
    std::vector<PartHeader> headers;
    for (;;) {
      if (multiPart) {  // an empty header (a lone 0) ends the list
        need(1);
        if (*bytes_.at(pos_) == 0) {
          ++pos_;
          break;
        }
      }
      headers.push_back(readHeader(int(headers.size())));
      if (!multiPart) break;
    }
    if (headers.empty()) fail("OpenEXR file with no parts");
    ExrHeaderScan scan;
    scan.headerBytes = pos_;
    scan.fileBytes = bytes_.fileBytes();
    scan.headerHash = fnv1a64(bytes_.at(0), size_t(pos_));
    uint64_t chunks = 0;
    for (size_t p = 0; p < headers.size(); ++p) {
      // A single-part file's type is in its version flags (a "type" attribute may repeat it).
      // Without the attribute, OpenEXR reads the part as an image whatever the deep flag, so it is
      // bounded as one (a small file flagged deep is otherwise read as an image of the size it
      // declares).
      std::string type = multiPart ? "scanlineimage" : singlePartType(version & ~kFlagDeep);
      if (headers[p].type) type = *headers[p].type;
      scan.parts.push_back(boundPart(headers[p], type, int(p)));
      chunks = std::min(kSaturated, chunks + scan.parts.back().chunks);
    }
    const uint64_t tableRoom = scan.fileBytes - scan.headerBytes;
    if (chunks > tableRoom / 8)
      fail("chunk offset tables of " + std::to_string(chunks) + " chunks (" +
           std::to_string(product(chunks, 8)) + " bytes) do not fit in the " +
           std::to_string(tableRoom) + " bytes after the headers");
    return scan;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw inputError(name_, what); }
  [[noreturn]] void failIn(int part, const std::string& what) const {
    fail("part " + std::to_string(part) + ": " + what);
  }

  void need(uint64_t n) {
    if (!bytes_.ensure(pos_ + n, name_))
      fail("OpenEXR header cut short at byte " + std::to_string(pos_));
  }

  // A NUL-terminated name or type (not empty unless `mayBeEmpty`).
  std::string cString(bool mayBeEmpty, const char* what, int part) {
    std::string s;
    for (;;) {
      need(1);
      const char c = char(*bytes_.at(pos_++));
      if (c == 0) break;
      s += c;
      if (s.size() >= kMaxName) failIn(part, std::string(what) + " longer than 255 bytes");
    }
    if (s.empty() && !mayBeEmpty) failIn(part, std::string("empty ") + what);
    return s;
  }

  PartHeader readHeader(int part) {
    PartHeader h;
    for (;;) {
      const std::string name = cString(true, "attribute name", part);
      if (name.empty()) return h;
      const std::string type = cString(false, "attribute type", part);
      need(4);
      const int32_t size = lei32(bytes_.at(pos_));
      pos_ += 4;
      const uint64_t left = bytes_.fileBytes() - pos_;
      if (size < 0 || uint64_t(size) > left)
        failIn(part, "attribute '" + shown(name) + "' (" + shown(type) + ") declares " +
                         std::to_string(size) + " bytes, the file has " + std::to_string(left) +
                         " left");
      readValue(h, name, type, uint32_t(size), part);
      pos_ += uint64_t(size);
    }
  }

  void requireSize(const std::string& name, uint32_t size, uint32_t expected, int part) const {
    if (size != expected)
      failIn(part, "attribute '" + name + "' has " + std::to_string(size) + " bytes, expected " +
                       std::to_string(expected));
  }

  // Parses what the bounds need; checks counts inside values OpenEXR allocates by.
  void readValue(PartHeader& h, const std::string& name, const std::string& type, uint32_t size,
                 int part) {
    if (const uint32_t fixed = fixedSize(type)) requireSize(shown(name), size, fixed, part);
    if (type == "floatvector" && size % 4 != 0)
      failIn(part, "float vector '" + shown(name) + "' of " + std::to_string(size) + " bytes");
    const bool parsed =
        type == "chlist" || (name == "compression" && type == "compression") ||
        (name == "dataWindow" && type == "box2i") || (name == "type" && type == "string") ||
        (name == "chunkCount" && type == "int") || (name == "tiles" && type == "tiledesc") ||
        type == "preview" || type == "stringvector";
    if (!parsed) return;
    need(size);
    const uint8_t* v = bytes_.at(pos_);
    if (type == "chlist") {
      std::vector<Channel> channels = readChannels(v, size, part);
      if (name == "channels") h.channels = std::move(channels);
    } else if (name == "compression" && type == "compression") {
      requireSize(name, size, 1, part);
      h.compression = v[0];
    } else if (name == "dataWindow" && type == "box2i") {
      requireSize(name, size, 16, part);
      for (int i = 0; i < 4; ++i) h.window[i] = lei32(v + 4 * i);
      h.hasWindow = true;
    } else if (name == "type" && type == "string") {
      h.type = std::string(reinterpret_cast<const char*>(v), size);
    } else if (name == "chunkCount" && type == "int") {
      requireSize(name, size, 4, part);
      h.chunkCount = lei32(v);
    } else if (name == "tiles" && type == "tiledesc") {
      requireSize(name, size, 9, part);
      h.tileX = le32(v);
      h.tileY = le32(v + 4);
    } else if (type == "preview") {
      // uint32 width, height, then width x height RGBA bytes: OpenEXR allocates the declared.
      if (size < 8) failIn(part, "preview '" + shown(name) + "' shorter than 8 bytes");
      const uint64_t pixels = uint64_t(le32(v)) * le32(v + 4);
      if (pixels > (size - 8) / 4 || 8 + 4 * pixels != size)
        failIn(part, "preview '" + shown(name) + "' declares " + std::to_string(le32(v)) + "x" +
                         std::to_string(le32(v + 4)) + " pixels in " + std::to_string(size) +
                         " bytes");
    } else if (type == "stringvector") {
      // int32 length, bytes; repeated: each string read at its declared length.
      for (uint32_t at = 0; at < size;) {
        if (size - at < 4) failIn(part, "string vector '" + shown(name) + "' cut short");
        const int32_t n = lei32(v + at);
        at += 4;
        if (n < 0 || uint32_t(n) > size - at)
          failIn(part, "string vector '" + shown(name) + "' declares a string of " +
                           std::to_string(n) + " bytes, the attribute has " +
                           std::to_string(size - at) + " left");
        at += uint32_t(n);
      }
    }
  }

  std::vector<Channel> readChannels(const uint8_t* v, uint32_t size, int part) const {
    // name\0, int32 pixel type, uint8 pLinear, 3 reserved, int32 xSampling, ySampling; an empty
    // name ends the list.
    std::vector<Channel> channels;
    uint32_t at = 0;
    for (;;) {
      const void* end = at < size ? std::memchr(v + at, 0, size - at) : nullptr;
      if (!end) failIn(part, "channel list cut short");
      const uint32_t length = uint32_t(static_cast<const uint8_t*>(end) - (v + at));
      const std::string channel(reinterpret_cast<const char*>(v + at), length);
      at += length + 1;
      if (length > 255) failIn(part, "channel name longer than 255 bytes");
      if (channel.empty()) {
        // OpenEXR reads to the list's end marker: it must be the attribute's last byte.
        if (at != size) failIn(part, "channel list ends before its attribute does");
        break;
      }
      if (size - at < 16) failIn(part, "channel list cut short");
      const int32_t pixelType = lei32(v + at);
      Channel c;
      c.bytes = pixelType == 1 ? 2 : (pixelType == 0 || pixelType == 2) ? 4 : 0;
      if (c.bytes == 0)
        failIn(part, "channel '" + shown(channel) + "' has unknown pixel type " +
                         std::to_string(pixelType));
      c.xSampling = lei32(v + at + 8);
      c.ySampling = lei32(v + at + 12);
      if (c.xSampling < 1 || c.ySampling < 1)
        failIn(part, "channel '" + shown(channel) + "' has sampling " +
                         std::to_string(c.xSampling) + "x" + std::to_string(c.ySampling));
      at += 16;
      channels.push_back(c);
    }
    return channels;
  }

  ExrScannedPart boundPart(const PartHeader& h, const std::string& type, int part) const {
    if (!h.channels) failIn(part, "no channels attribute");
    if (!h.compression) failIn(part, "no compression attribute");
    if (!h.hasWindow) failIn(part, "no dataWindow attribute");
    ExrScannedPart p;
    p.type = type;
    p.compression = *h.compression;
    if (p.compression >= kCompressions)
      failIn(part, "unknown compression " + std::to_string(p.compression));
    p.width = int64_t(h.window[2]) - h.window[0] + 1;
    p.height = int64_t(h.window[3]) - h.window[1] + 1;
    if (p.width < 1 || p.height < 1)
      failIn(part, "empty data window (" + std::to_string(p.width) + "x" +
                       std::to_string(p.height) + ")");
    p.channels = int(h.channels->size());
    const bool deep = type.rfind("deep", 0) == 0;
    const bool tiled = type == "tiledimage" || type == "deeptile";
    // Samples of a channel along an axis: at most size / sampling + 1 (every x with
    // x % sampling == 0). Products saturate at 2^62 (w, h < 2^32; channels < 2^28).
    uint64_t rowBytes = 0, decoded = 0, pixelBytes = 0;
    for (const Channel& c : *h.channels) {
      const uint64_t xs = uint64_t(std::min<int64_t>(p.width, p.width / c.xSampling + 1));
      const uint64_t ys = uint64_t(std::min<int64_t>(p.height, p.height / c.ySampling + 1));
      rowBytes += xs * uint64_t(c.bytes);
      pixelBytes += uint64_t(c.bytes);
      decoded = std::min(kSaturated, decoded + product(product(xs, ys), uint64_t(c.bytes)));
    }
    // The buffer OpenEXR decodes one chunk into: a chunk's scan lines, or one whole tile.
    uint64_t chunkBytes = 0;
    if (tiled) {
      if (!h.tileX || !h.tileY || *h.tileX < 1 || *h.tileY < 1)
        failIn(part, "tiled part without a valid tiles attribute");
      const uint64_t tx = *h.tileX, ty = *h.tileY;
      // Level 0 alone; mipmaps and ripmaps have more (at most 4x), so this is a lower bound.
      p.chunks = product((uint64_t(p.width) + tx - 1) / tx, (uint64_t(p.height) + ty - 1) / ty);
      chunkBytes = product(product(tx, ty), pixelBytes);
    } else {
      const uint64_t lines = uint64_t(kLinesPerChunk[p.compression]);
      p.chunks = (uint64_t(p.height) + lines - 1) / lines;
      chunkBytes = product(rowBytes, lines);
    }
    if (h.chunkCount) {
      if (*h.chunkCount < 0) failIn(part, "negative chunkCount " + std::to_string(*h.chunkCount));
      p.chunks = std::max(p.chunks, uint64_t(*h.chunkCount));
    }
    if (deep) return p;  // samples per pixel are in the chunks: only the tables are bounded
    p.decodedBytes = decoded;
    const uint64_t limit = exrDecodedLimit(p.compression, bytes_.fileBytes());
    if (decoded > limit)
      failIn(part, "data window " + std::to_string(p.width) + "x" + std::to_string(p.height) +
                       " of " + std::to_string(p.channels) + " channel(s) decodes to " +
                       std::to_string(decoded) + " bytes, more than a " +
                       std::to_string(bytes_.fileBytes()) + "-byte file can hold (at most " +
                       std::to_string(limit) + ")");
    if (chunkBytes > limit)
      failIn(part, std::string(tiled ? "a tile" : "a chunk of scan lines") + " decodes to " +
                       std::to_string(chunkBytes) + " bytes, more than a " +
                       std::to_string(bytes_.fileBytes()) + "-byte file can hold (at most " +
                       std::to_string(limit) + ")");
    return p;
  }

  Bytes& bytes_;
  const std::string& name_;
  uint64_t pos_ = 0;
};

}  // namespace

uint64_t exrMaxRatio(int compression) {
  // Decoded bytes per file byte, the most each compression reaches: measured on 4096^2
  // constant (all-zero) RGB images, FLOAT and HALF, scan lines and 64^2 tiles, OpenEXR 3.1.5:
  //   NONE 1 (every decoded byte is stored);  RLE 62.5 (a run of at most 128 bytes in 2);
  //   ZIPS 565, ZIP 980, PIZ 405 (deflate's limit is 1032:1; PIZ's Huffman runs of 255 symbols
  //   in >= 10 bits give about 410);  PXR24 1287 (deflate over 24 of a FLOAT's 32 bits:
  //   1032 x 4/3 = 1376);  B44 2.3, B44A 10.7 (a flat 4x4 block of HALF in 3 bytes);
  //   DWAA 7582, DWAB 24312 (DCT's DC, 1 in 64 values, then deflate: up to 64 x 1032 x 2).
  // The bounds are those limits with room to spare; a file beyond them cannot be one OpenEXR
  // wrote for that data window.
  static constexpr uint64_t kRatio[kCompressions] = {
      1, 128, 2048, 2048, 2048, 2048, 32, 32, uint64_t(1) << 18, uint64_t(1) << 18};
  return compression >= 0 && compression < kCompressions ? kRatio[compression] : uint64_t(1) << 18;
}

uint64_t exrDecodedLimit(int compression, uint64_t fileBytes) {
  // + 1 MiB: any part that small is read whatever its ratio (cheap, and no valid small file is
  // refused over a header's worth of bytes); file sizes are < 2^44, ratios <= 2^18.
  return exrMaxRatio(compression) * std::min<uint64_t>(fileBytes, uint64_t(1) << 44) + kMiB;
}

ExrHeaderScan scanExrHeaders(const uint8_t* bytes, size_t size, const std::string& name) {
  Bytes b(bytes, size);
  return Scanner(b, name).scan();
}

ExrHeaderScan scanExrFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    throw inputError(path, errno == ENOENT ? "cannot open (missing)"
                                           : std::string("cannot open: ") + std::strerror(errno));
  }
  struct Close {
    int fd;
    ~Close() { ::close(fd); }
  } close{fd};
  struct stat st;
  if (::fstat(fd, &st) != 0)
    throw inputError(path, std::string("cannot open: ") + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) throw inputError(path, "is not a regular file");
  Bytes b(fd, uint64_t(st.st_size));
  return Scanner(b, path).scan();
}

}  // namespace rad
