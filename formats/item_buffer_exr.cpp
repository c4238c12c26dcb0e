// Item buffers as OpenEXR (layout in item_buffer_exr.h).
#include "formats/item_buffer_exr.h"

#include <cstdlib>
#include <cstring>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>

#include "formats/atomic_file.h"
#include "formats/checksum.h"
#include "formats/exr_header_scan.h"
#include "formats/pixel_checksum.h"
#include "libcommon/core/error.h"

namespace rad {

uint64_t itemBufferChecksum(const ItemBuffer& b) {
  // Channel-list order Z, id; pixelChecksum hashes each value's 4 bytes, so an id's bits are
  // carried in a float slot unchanged (memcpy, no conversion).
  std::vector<float> words(b.depth.size() * 2);
  for (size_t p = 0; p < b.depth.size(); ++p) {
    words[2 * p] = b.depth[p];
    std::memcpy(&words[2 * p + 1], &b.id[p], sizeof(uint32_t));
  }
  return pixelChecksum(words.data(), b.width, b.height, 2, {0, 1});
}

void writeItemBufferExr(const std::string& path, const ItemBuffer& b, int frame, double time,
                        const std::string& provenanceJson) {
  size_t n = size_t(b.width) * b.height;
  if (b.width < 1 || b.height < 1 || b.id.size() != n || b.depth.size() != n)
    throw Error(ExitCode::kInternal, path, "item buffer arrays do not match its size");
  Imf::Header h(b.width, b.height);
  h.compression() = Imf::ZIP_COMPRESSION;
  h.lineOrder() = Imf::INCREASING_Y;
  h.channels().insert("id", Imf::Channel(Imf::UINT));
  h.channels().insert("Z", Imf::Channel(Imf::FLOAT));
  h.insert("rad.format", Imf::StringAttribute("item-buffer " + std::to_string(kItemBufferExrMajor) +
                                              "." + std::to_string(kItemBufferExrMinor)));
  h.insert("rad.frame", Imf::IntAttribute(frame));
  h.insert("rad.time", Imf::DoubleAttribute(time));
  if (!provenanceJson.empty()) h.insert("rad.provenance", Imf::StringAttribute(provenanceJson));
  h.insert(kPixelChecksumAttribute, Imf::StringAttribute(formatFnv1a64(itemBufferChecksum(b))));
  AtomicFile file(path);
  try {
    Imf::OutputFile out(file.tempPath().c_str(), h);
    Imf::FrameBuffer fb;
    fb.insert("id", Imf::Slice(Imf::UINT, (char*)b.id.data(), sizeof(uint32_t),
                               sizeof(uint32_t) * b.width));
    fb.insert(
        "Z", Imf::Slice(Imf::FLOAT, (char*)b.depth.data(), sizeof(float), sizeof(float) * b.width));
    out.setFrameBuffer(fb);
    out.writePixels(b.height);
  } catch (const std::exception& e) {
    throw outputError(path, e.what());
  }
  file.commit();
}

ItemBuffer readItemBufferExr(const std::string& path) {
  ItemBuffer b;
  scanExrFile(path);  // sizes the header declares, bounded by the file's before OpenEXR reads
  try {
    Imf::InputFile in(path.c_str());
    const Imf::Header& h = in.header();
    const auto* fmt = h.findTypedAttribute<Imf::StringAttribute>("rad.format");
    if (!fmt || fmt->value().rfind("item-buffer ", 0) != 0)
      throw inputError(path, "not an item buffer (no rad.format \"item-buffer\")");
    // Refuses 1.x (no checksum: re-run rad-intervals) and a malformed or missing checksum.
    const std::optional<uint64_t> stored = storedPixelChecksum(h, path, "part 0");
    int major = std::atoi(fmt->value().c_str() + 12);
    if (major != kItemBufferExrMajor)
      throw inputError(path, "item-buffer version " + fmt->value().substr(12) + ", expected " +
                                 std::to_string(kItemBufferExrMajor) + ".x");
    const Imath::Box2i dw = h.dataWindow();
    b.width = dw.max.x - dw.min.x + 1;
    b.height = dw.max.y - dw.min.y + 1;
    if (dw.min.x != 0 || dw.min.y != 0 || b.width < 1 || b.height < 1 || b.width > 16384 ||
        b.height > 16384)
      throw inputError(path, "unexpected data window");
    const Imf::Channel* id = h.channels().findChannel("id");
    const Imf::Channel* z = h.channels().findChannel("Z");
    if (!id || id->type != Imf::UINT || !z || z->type != Imf::FLOAT)
      throw inputError(path, "expected channels id (UINT) and Z (FLOAT)");
    b.id.resize(size_t(b.width) * b.height);
    b.depth.resize(b.id.size());
    Imf::FrameBuffer fb;
    fb.insert("id", Imf::Slice(Imf::UINT, (char*)b.id.data(), sizeof(uint32_t),
                               sizeof(uint32_t) * b.width));
    fb.insert(
        "Z", Imf::Slice(Imf::FLOAT, (char*)b.depth.data(), sizeof(float), sizeof(float) * b.width));
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    if (!stored) throw inputError(path, std::string("part 0: no ") + kPixelChecksumAttribute);
    requirePixelChecksum(*stored, itemBufferChecksum(b), path, "part 0");
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw inputError(path, e.what());
  }
  return b;
}

double readItemBufferTime(const std::string& path) {
  scanExrFile(path);
  try {
    Imf::InputFile in(path.c_str());
    const Imf::Header& h = in.header();
    const auto* fmt = h.findTypedAttribute<Imf::StringAttribute>("rad.format");
    if (!fmt || fmt->value().rfind("item-buffer ", 0) != 0)
      throw inputError(path, "not an item buffer (no rad.format \"item-buffer\")");
    const auto* time = h.findTypedAttribute<Imf::DoubleAttribute>("rad.time");
    if (!time) throw inputError(path, "item buffer without rad.time");
    return time->value();
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw inputError(path, e.what());
  }
}

}  // namespace rad
