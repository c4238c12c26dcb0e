// Frame images: OpenEXR (linear radiance) and PNG (sRGB). Spec in frame_image.h.
#include "formats/frame_image.h"

#include "formats/exr_image.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <png.h>

#include "formats/atomic_file.h"
#include "formats/checksum.h"
#include "formats/exr_header_scan.h"
#include "formats/pixel_checksum.h"
#include "libcommon/core/error.h"

namespace rad {

std::string framePath(const std::string& dir, int frame, const std::string& ext) {
  char name[32];
  std::snprintf(name, sizeof name, "/%04d", frame);
  return dir + name + ext;
}

int frameCompressionOf(const std::string& name) {
  if (name == "none") return int(Imf::NO_COMPRESSION);
  if (name == "rle") return int(Imf::RLE_COMPRESSION);
  if (name == "zip") return int(Imf::ZIP_COMPRESSION);
  if (name == "piz") return int(Imf::PIZ_COMPRESSION);
  throw Error(ExitCode::kUsage, "--compression",
              "expected none, rle, zip or piz, got '" + name + "'");
}

void writeFrameExr(const std::string& path, const ComposedFrame& frame, const FrameImageInfo& info,
                   bool half, int compression) {
  const int w = frame.size.width, h = frame.size.height;
  if (w < 1 || h < 1 || frame.rgb.size() != size_t(w) * h * 3)
    throw Error(ExitCode::kInternal, path, "frame has the wrong size");
  Imf::Header header(w, h);
  header.compression() = Imf::Compression(compression);
  header.lineOrder() = Imf::INCREASING_Y;
  const Imf::PixelType type = half ? Imf::HALF : Imf::FLOAT;
  for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(type));
  header.insert("rad.format", Imf::StringAttribute("frame " + std::to_string(kFrameImageMajor) +
                                                   "." + std::to_string(kFrameImageMinor)));
  header.insert("rad.frame", Imf::IntAttribute(info.frame));
  header.insert("rad.time", Imf::DoubleAttribute(frame.time));
  header.insert("rad.units", Imf::StringAttribute("radiance W/(m^2 sr)"));
  header.insert("rad.exposureEV", Imf::DoubleAttribute(info.exposureEV));
  header.insert("rad.coveredPixels", Imf::IntAttribute(int(frame.coveredPixels)));
  header.insert("rad.moviePixels", Imf::IntAttribute(int(frame.moviePixels)));
  header.insert("rad.fallbackPixels", Imf::IntAttribute(int(frame.fallbackPixels)));
  if (!info.provenanceJson.empty())
    header.insert("rad.provenance", Imf::StringAttribute(info.provenanceJson));

  std::vector<Imath::half> halves;
  const char* base = reinterpret_cast<const char*>(frame.rgb.data());
  size_t elem = sizeof(float);
  uint64_t checksum = 0;
  if (half) {
    // Half overflows at 65504: clamp rather than write inf (docs/design.md §5).
    halves.resize(frame.rgb.size());
    std::vector<float> stored(frame.rgb.size());  // what a reader decodes
    for (size_t i = 0; i < frame.rgb.size(); ++i) {
      halves[i] = Imath::half(std::min(frame.rgb[i], 65504.0f));
      stored[i] = float(halves[i]);
    }
    base = reinterpret_cast<const char*>(halves.data());
    elem = sizeof(Imath::half);
    checksum = rgbPixelChecksum(stored.data(), w, h);
  } else {
    checksum = rgbPixelChecksum(frame.rgb.data(), w, h);
  }
  header.insert(kPixelChecksumAttribute, Imf::StringAttribute(formatFnv1a64(checksum)));
  // Through ExrFileStream: an uncompressed file is one chunk per scanline, and OpenEXR writes
  // each with its own system call (240 per frame at 352x240).
  AtomicFile file(path, info.durability);
  ExrFileStream stream(file.tempPath(), path);
  try {
    Imf::OutputFile out(stream, header);
    Imf::FrameBuffer fb;
    const size_t xs = 3 * elem, ys = size_t(w) * xs;
    fb.insert("R", Imf::Slice(type, const_cast<char*>(base), xs, ys));
    fb.insert("G", Imf::Slice(type, const_cast<char*>(base + elem), xs, ys));
    fb.insert("B", Imf::Slice(type, const_cast<char*>(base + 2 * elem), xs, ys));
    out.setFrameBuffer(fb);
    out.writePixels(h);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw outputError(path, e.what());
  }
  stream.close();
  file.commit();
}

namespace {
// libpng reports errors by longjmp; the message is kept for the one-line error.
void pngError(png_structp png, png_const_charp message) {
  auto* where = static_cast<std::string*>(png_get_error_ptr(png));
  if (where) *where = message ? message : "libpng error";
  png_longjmp(png, 1);
}
void pngWarning(png_structp, png_const_charp) {}
}  // namespace

// libpng rather than OpenImageIO: linking OIIO made rad-compose load its whole dependency tree
// (GDAL, OpenVDB, FFmpeg, ...) into resident memory before the first frame.
void writeFramePng(const std::string& path, const ComposedFrame& frame,
                   const FrameImageInfo& info) {
  const int w = frame.size.width, h = frame.size.height;
  if (w < 1 || h < 1 || frame.rgb.size() != size_t(w) * h * 3)
    throw Error(ExitCode::kInternal, path, "frame has the wrong size");
  std::vector<uint8_t> pixels = toSrgb8(frame.rgb, info.exposureEV);
  std::ostringstream description;
  description << "rad frame " << info.frame << ", exposure " << info.exposureEV << " EV";
  if (!info.provenanceJson.empty()) description << "; provenance " << info.provenanceJson;
  std::string descriptionText = description.str(), software = "rad-compose";
  std::vector<png_bytep> rows(static_cast<size_t>(h), nullptr);
  for (int y = 0; y < h; ++y) rows[size_t(y)] = pixels.data() + size_t(y) * size_t(w) * 3;
  std::string message;

  AtomicFile file(path, info.durability);
  FILE* fp = std::fopen(file.tempPath().c_str(), "wb");
  if (!fp) throw outputError(path, "cannot create");
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &message, pngError, pngWarning);
  png_infop pinfo = png ? png_create_info_struct(png) : nullptr;
  if (!png || !pinfo) {
    png_destroy_write_struct(&png, nullptr);
    std::fclose(fp);
    throw Error(ExitCode::kEnvironment, path, "libpng: out of memory");
  }
  // Only C objects and objects made before it live across this setjmp.
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &pinfo);
    std::fclose(fp);
    throw outputError(path, "libpng: " + message);
  }
  png_init_io(png, fp);
  png_set_IHDR(png, pinfo, png_uint_32(w), png_uint_32(h), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_sRGB_gAMA_and_cHRM(png, pinfo, PNG_sRGB_INTENT_PERCEPTUAL);
  // zlib's fastest level: the same pixels, deflated at a fraction of the default level's cost, for
  // somewhat larger PNGs (small beside the EXRs either way).
  png_set_compression_level(png, 1);
  png_text text[2] = {};
  text[0].compression = PNG_TEXT_COMPRESSION_zTXt;  // the provenance JSON compresses well
  text[0].key = const_cast<char*>("Description");
  text[0].text = descriptionText.data();
  text[1].compression = PNG_TEXT_COMPRESSION_NONE;
  text[1].key = const_cast<char*>("Software");
  text[1].text = software.data();
  png_set_text(png, pinfo, text, 2);
  png_set_rows(png, pinfo, rows.data());
  png_write_png(png, pinfo, PNG_TRANSFORM_IDENTITY, nullptr);
  png_destroy_write_struct(&png, &pinfo);
  if (std::fclose(fp) != 0) throw outputError(path, "cannot write");
  file.commit();
}

FrameExr readFrameExr(const std::string& path) {
  FrameExr f;
  scanExrFile(path);  // sizes the header declares, bounded by the file's before OpenEXR reads
  try {
    Imf::InputFile in(path.c_str());
    const Imf::Header& h = in.header();
    const Imath::Box2i dw = h.dataWindow();
    f.width = dw.max.x - dw.min.x + 1;
    f.height = dw.max.y - dw.min.y + 1;
    if (dw.min.x != 0 || dw.min.y != 0 || f.width < 1 || f.height < 1 || f.width > 65536 ||
        f.height > 65536)
      throw inputError(path, "invalid data window");
    for (const char* c : {"R", "G", "B"})
      if (!h.channels().findChannel(c)) throw inputError(path, std::string("no channel ") + c);
    f.half = h.channels().findChannel("R")->type == Imf::HALF;
    for (auto it = h.begin(); it != h.end(); ++it) {
      const Imf::Attribute& a = it.attribute();
      if (auto* s = dynamic_cast<const Imf::StringAttribute*>(&a))
        f.attributes[it.name()] = s->value();
      else if (auto* i = dynamic_cast<const Imf::IntAttribute*>(&a))
        f.attributes[it.name()] = std::to_string(i->value());
      else if (auto* d = dynamic_cast<const Imf::DoubleAttribute*>(&a)) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.17g", d->value());
        f.attributes[it.name()] = buf;
      }
    }
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw inputError(path, e.what());
  }
  f.rgb = readExrImage(path, {"R", "G", "B"}).pixels;
  return f;
}

}  // namespace rad
