#include "formats/pixel_checksum.h"

#include <cstdlib>
#include <cstring>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStringAttribute.h>

#include "formats/checksum.h"
#include "formats/exr_header_scan.h"
#include "formats/frame_image.h"
#include "formats/item_buffer_exr.h"
#include "formats/texture_movie.h"
#include "libcommon/core/error.h"

namespace rad {

namespace {

// FNV-1a over the 4 little-endian bytes of v, whatever the host's byte order.
inline uint64_t hashFloat(uint64_t h, float v) {
  uint32_t u;
  std::memcpy(&u, &v, sizeof u);
  h = (h ^ (u & 0xffu)) * kFnv1a64Prime;
  h = (h ^ ((u >> 8) & 0xffu)) * kFnv1a64Prime;
  h = (h ^ ((u >> 16) & 0xffu)) * kFnv1a64Prime;
  return (h ^ (u >> 24)) * kFnv1a64Prime;
}

// The rad formats whose current version stores rad.pixelChecksum in every part, and the stage
// that writes them (named when an older file is refused).
struct ChecksummedFormat {
  const char* prefix;
  int major;
  const char* stage;
};
const ChecksummedFormat kChecksummedFormats[] = {
    {"texture-movie ", kTextureMovieMajor, "rad-movies"},
    {"frame ", kFrameImageMajor, "rad-compose"},
    {"item-buffer ", kItemBufferExrMajor, "rad-intervals"},
};

}  // namespace

uint64_t pixelChecksum(const float* pixels, int width, int height, int channels,
                       const std::vector<int>& listOrder) {
  uint64_t h = kFnv1a64Offset;
  const size_t rowFloats = size_t(width) * size_t(channels);
  for (int y = 0; y < height; ++y) {
    const float* row = pixels + size_t(y) * rowFloats;
    for (int c : listOrder)
      for (int x = 0; x < width; ++x)
        h = hashFloat(h, row[size_t(x) * size_t(channels) + size_t(c)]);
  }
  return h;
}

uint64_t rgbPixelChecksum(const float* rgb, int width, int height) {
  static const std::vector<int> kBgr = {2, 1, 0};
  return pixelChecksum(rgb, width, height, 3, kBgr);
}

std::optional<uint64_t> parseFnv1a64(const std::string& text) {
  constexpr size_t kPrefix = 8, kDigits = 16;
  if (text.size() != kPrefix + kDigits || text.compare(0, kPrefix, "fnv1a64:") != 0) return {};
  uint64_t v = 0;
  for (size_t i = kPrefix; i < text.size(); ++i) {
    const char c = text[i];
    const int d = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
    if (d < 0) return {};
    v = (v << 4) | uint64_t(d);
  }
  return v;
}

std::string exrForeignWriter(const Imf::Header& header) {
  if (const auto* software = header.findTypedAttribute<Imf::StringAttribute>("Software")) {
    const std::string& s = software->value();
    if (s.rfind("rad", 0) != 0) return s.substr(0, 200);
  }
  switch (header.compression()) {
    case Imf::PXR24_COMPRESSION:
      return "a program writing PXR24 compression";
    case Imf::B44_COMPRESSION:
      return "a program writing B44 compression";
    case Imf::B44A_COMPRESSION:
      return "a program writing B44A compression";
    case Imf::DWAA_COMPRESSION:
      return "a program writing DWAA compression";
    case Imf::DWAB_COMPRESSION:
      return "a program writing DWAB compression";
    default:
      return "";
  }
}

std::optional<uint64_t> storedPixelChecksum(const Imf::Header& header, const std::string& path,
                                            const std::string& part) {
  if (!exrForeignWriter(header).empty()) return {};
  bool required = false;
  if (const auto* format = header.findTypedAttribute<Imf::StringAttribute>("rad.format")) {
    const std::string& f = format->value();
    for (const ChecksummedFormat& c : kChecksummedFormats) {
      if (f.rfind(c.prefix, 0) != 0) continue;
      if (std::atoi(f.c_str() + std::strlen(c.prefix)) < c.major)
        throw inputError(
            path, f + " is no longer read (its pixels carry no checksum): re-run " + c.stage);
      required = true;
    }
  }
  const auto* stored = header.findTypedAttribute<Imf::StringAttribute>(kPixelChecksumAttribute);
  if (!stored && !required) return {};
  return requiredPixelChecksum(stored ? &stored->value() : nullptr, path, part);
}

uint64_t requiredPixelChecksum(const std::string* stored, const std::string& path,
                               const std::string& part) {
  if (!stored) throw inputError(path, part + ": no " + kPixelChecksumAttribute);
  const std::optional<uint64_t> v = parseFnv1a64(*stored);
  if (!v) throw inputError(path, part + ": malformed " + kPixelChecksumAttribute);
  return *v;
}

void requirePixelChecksum(uint64_t stored, uint64_t computed, const std::string& path,
                          const std::string& part) {
  if (stored != computed)
    throw inputError(path, part + ": pixel checksum mismatch (stored " + formatFnv1a64(stored) +
                               ", pixels read " + formatFnv1a64(computed) +
                               "): the file is corrupted");
}

nlohmann::json verifyExrPixels(const std::string& path) {
  int checksummed = 0, parts = 0;
  scanExrFile(path);  // sizes the headers declare, bounded by the file's before OpenEXR reads
  try {
    Imf::MultiPartInputFile file(path.c_str());
    parts = file.parts();
    checksummed = verifyExrPartPixels(file, path, 0);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw inputError(path, std::string("not a readable OpenEXR file: ") + e.what());
  }
  return {{"parts", parts}, {"checksummed_parts", checksummed}};
}

int verifyExrPartPixels(Imf::MultiPartInputFile& file, const std::string& path, int firstPart) {
  int checksummed = 0;
  try {
    for (int p = firstPart; p < file.parts(); ++p) {
      const Imf::Header& h = file.header(p);
      const std::string part = "part " + std::to_string(p);
      const std::optional<uint64_t> stored = storedPixelChecksum(h, path, part);
      if (h.hasType() && h.type() != Imf::SCANLINEIMAGE) {
        if (stored) throw inputError(path, part + ": a checksum on a " + h.type() + " part");
        continue;  // tiled or deep: not a rad file's part, nothing to verify
      }
      const Imath::Box2i dw = h.dataWindow();
      const long long w = (long long)dw.max.x - dw.min.x + 1,
                      hh = (long long)dw.max.y - dw.min.y + 1;
      std::vector<std::string> names;
      std::vector<Imf::PixelType> types;  // UINT read as UINT: its 4 bytes are what is hashed
      for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
        if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
          throw inputError(path, part + ": subsampled channel " + it.name() + " not supported");
        names.push_back(it.name());
        types.push_back(it.channel().type == Imf::UINT ? Imf::UINT : Imf::FLOAT);
      }
      if (w < 1 || hh < 1 || double(w) * double(hh) * double(names.size()) > 1.0e9)
        throw inputError(path, part + ": invalid data window");
      const size_t nc = names.size();
      std::vector<float> px(size_t(w) * size_t(hh) * nc);
      Imf::FrameBuffer fb;
      const size_t xs = nc * sizeof(float), ys = xs * size_t(w);
      for (size_t c = 0; c < nc; ++c) {
        char* base = reinterpret_cast<char*>(px.data() + c) -
                     std::ptrdiff_t(dw.min.x) * std::ptrdiff_t(xs) -
                     std::ptrdiff_t(dw.min.y) * std::ptrdiff_t(ys);
        fb.insert(names[c], Imf::Slice(types[c], base, xs, ys));
      }
      Imf::InputPart in(file, p);
      in.setFrameBuffer(fb);
      in.readPixels(dw.min.y, dw.max.y);
      if (!stored) continue;
      std::vector<int> order(nc);
      for (size_t c = 0; c < nc; ++c) order[c] = int(c);  // px holds the channels in list order
      requirePixelChecksum(*stored, pixelChecksum(px.data(), int(w), int(hh), int(nc), order), path,
                           part);
      ++checksummed;
    }
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw inputError(path, std::string("not a readable OpenEXR file: ") + e.what());
  }
  return checksummed;
}

std::vector<uint64_t> exrStringAttributeOffsets(const std::vector<char>& bytes, int parts,
                                                const std::string& name) {
  // OpenEXR header layout: magic (4), version (4), then per part attributes "name\0type\0"
  // int32 size, value; an empty name ends a part's header.
  size_t pos = 8;
  auto cString = [&]() {
    const void* end =
        pos < bytes.size() ? std::memchr(bytes.data() + pos, 0, bytes.size() - pos) : nullptr;
    if (!end) throw Error(ExitCode::kInternal, "", "OpenEXR header cut short");
    std::string s(bytes.data() + pos, static_cast<const char*>(end));
    pos += s.size() + 1;
    return s;
  };
  std::vector<uint64_t> offsets;
  for (int p = 0; p < parts; ++p) {
    for (;;) {
      const std::string attribute = cString();
      if (attribute.empty()) break;
      cString();  // type
      if (pos + 4 > bytes.size()) throw Error(ExitCode::kInternal, "", "OpenEXR header cut short");
      const auto* s = reinterpret_cast<const unsigned char*>(bytes.data() + pos);
      const uint32_t size =
          uint32_t(s[0]) | uint32_t(s[1]) << 8 | uint32_t(s[2]) << 16 | uint32_t(s[3]) << 24;
      pos += 4;
      if (size > bytes.size() - pos)
        throw Error(ExitCode::kInternal, "", "OpenEXR header cut short");
      if (attribute == name) offsets.push_back(pos);
      pos += size;
    }
  }
  return offsets;
}

}  // namespace rad
