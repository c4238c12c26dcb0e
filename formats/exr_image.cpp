#include "formats/exr_image.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <filesystem>

#include "formats/atomic_file.h"
#include "libcommon/error.h"

namespace rad {

FloatImage readExrImage(const std::string& path, const std::vector<std::string>& channels) {
  if (!std::filesystem::is_regular_file(path))
    throw inputError(
        path, std::filesystem::exists(path) ? "is not a regular file" : "cannot open (missing)");
  try {
    Imf::InputFile in(path.c_str());
    const Imath::Box2i dw = in.header().dataWindow();
    const int width = dw.max.x - dw.min.x + 1, height = dw.max.y - dw.min.y + 1;
    const Imf::ChannelList& list = in.header().channels();
    for (const std::string& c : channels) {
      if (list.findChannel(c.c_str()) == nullptr) {
        std::string have;
        for (auto it = list.begin(); it != list.end(); ++it)
          have += (have.empty() ? "" : ",") + std::string(it.name());
        throw inputError(path, "no channel '" + c + "' (channels: " + have + ")");
      }
    }
    FloatImage image(width, height, channels);
    const std::size_t nc = channels.size();
    const std::size_t xStride = sizeof(float) * nc, yStride = xStride * std::size_t(width);
    Imf::FrameBuffer fb;
    for (std::size_t c = 0; c < nc; ++c) {
      // Base pointer of pixel (0, 0) of the data window's coordinate system.
      char* base = reinterpret_cast<char*>(image.pixels.data() + c) -
                   std::ptrdiff_t(dw.min.x) * std::ptrdiff_t(xStride) -
                   std::ptrdiff_t(dw.min.y) * std::ptrdiff_t(yStride);
      fb.insert(channels[c].c_str(), Imf::Slice(Imf::FLOAT, base, xStride, yStride));
    }
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    return image;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw inputError(path, std::string("not a readable OpenEXR file: ") + e.what());
  }
}

void writeExrImage(const std::string& path, const FloatImage& image,
                   const std::map<std::string, std::string>& stringAttributes) {
  AtomicFile file(path);
  try {
    Imf::Header h(image.width, image.height);
    h.compression() = Imf::ZIP_COMPRESSION;
    h.lineOrder() = Imf::INCREASING_Y;
    for (const std::string& c : image.channels) h.channels().insert(c, Imf::Channel(Imf::FLOAT));
    for (const auto& [k, v] : stringAttributes) h.insert(k, Imf::StringAttribute(v));
    Imf::OutputFile out(file.tempPath().c_str(), h);
    Imf::FrameBuffer fb;
    const std::size_t nc = image.channels.size();
    const std::size_t xStride = sizeof(float) * nc, yStride = xStride * std::size_t(image.width);
    for (std::size_t c = 0; c < nc; ++c) {
      char* base = const_cast<char*>(reinterpret_cast<const char*>(image.pixels.data() + c));
      fb.insert(image.channels[c].c_str(), Imf::Slice(Imf::FLOAT, base, xStride, yStride));
    }
    out.setFrameBuffer(fb);
    out.writePixels(image.height);
  } catch (const std::exception& e) {
    throw outputError(path, e.what());
  }
  file.commit();
}

}  // namespace rad
