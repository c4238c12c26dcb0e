#include "formats/exr_image.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <optional>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <filesystem>

#include "formats/atomic_file.h"
#include "formats/checksum.h"
#include "formats/exr_header_scan.h"
#include "formats/pixel_checksum.h"
#include "libcommon/core/error.h"

namespace rad {

namespace {

// The channel list's order (by name, as OpenEXR sorts it) as indices into `channels`.
std::vector<int> listOrderOf(const std::vector<std::string>& channels) {
  std::vector<int> order(channels.size());
  for (size_t c = 0; c < order.size(); ++c) order[c] = int(c);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return channels[size_t(a)] < channels[size_t(b)]; });
  return order;
}

}  // namespace

FloatImage readExrImage(const std::string& path, const std::vector<std::string>& channels) {
  if (!std::filesystem::is_regular_file(path))
    throw inputError(
        path, std::filesystem::exists(path) ? "is not a regular file" : "cannot open (missing)");
  scanExrFile(path);  // sizes the header declares, bounded by the file's before OpenEXR reads
  try {
    Imf::MultiPartInputFile file(path.c_str());
    const Imf::Header& header = file.header(0);
    const Imath::Box2i dw = header.dataWindow();
    const long long w = (long long)dw.max.x - dw.min.x + 1, h = (long long)dw.max.y - dw.min.y + 1;
    const Imf::ChannelList& list = header.channels();
    std::vector<std::string> all;  // every channel, in list order: the checksum covers them all
    std::vector<bool> isUint;      // read as UINT (the checksum hashes its bits), then converted
    for (auto it = list.begin(); it != list.end(); ++it) {
      all.push_back(it.name());
      isUint.push_back(it.channel().type == Imf::UINT);
    }
    for (const std::string& c : channels) {
      if (list.findChannel(c.c_str()) == nullptr) {
        std::string have;
        for (const std::string& name : all) have += (have.empty() ? "" : ",") + name;
        throw inputError(path, "no channel '" + c + "' (channels: " + have + ")");
      }
    }
    const std::optional<uint64_t> stored = storedPixelChecksum(header, path, "part 0");
    if (w < 1 || h < 1 || double(w) * double(h) * double(all.size()) > 1.0e9)
      throw inputError(path, "invalid data window");
    FloatImage image(int(w), int(h), all);
    const std::size_t nc = all.size();
    const std::size_t xStride = sizeof(float) * nc, yStride = xStride * std::size_t(w);
    Imf::FrameBuffer fb;
    for (std::size_t c = 0; c < nc; ++c) {
      // Base pointer of pixel (0, 0) of the data window's coordinate system.
      char* base = reinterpret_cast<char*>(image.pixels.data() + c) -
                   std::ptrdiff_t(dw.min.x) * std::ptrdiff_t(xStride) -
                   std::ptrdiff_t(dw.min.y) * std::ptrdiff_t(yStride);
      fb.insert(all[c].c_str(),
                Imf::Slice(isUint[c] ? Imf::UINT : Imf::FLOAT, base, xStride, yStride));
    }
    Imf::InputPart in(file, 0);
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    if (stored)
      requirePixelChecksum(
          *stored,
          pixelChecksum(image.pixels.data(), image.width, image.height, int(nc), listOrderOf(all)),
          path, "part 0");
    for (std::size_t c = 0; c < nc; ++c) {
      if (!isUint[c]) continue;
      for (std::size_t p = c; p < image.pixels.size(); p += nc) {
        uint32_t u;
        std::memcpy(&u, &image.pixels[p], sizeof u);
        image.pixels[p] = float(u);
      }
    }
    // The parts after the first are not returned, but their checksums are verified too: a
    // corrupted file is refused whichever part the damage is in.
    verifyExrPartPixels(file, path, 1);
    if (channels == all) return image;
    FloatImage selected(image.width, image.height, channels);
    for (size_t c = 0; c < channels.size(); ++c) {
      const size_t from = size_t(std::find(all.begin(), all.end(), channels[c]) - all.begin());
      for (size_t p = 0; p < size_t(w) * size_t(h); ++p)
        selected.pixels[p * channels.size() + c] = image.pixels[p * nc + from];
    }
    return selected;
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
    const std::size_t nc = image.channels.size();
    h.insert(kPixelChecksumAttribute, Imf::StringAttribute(formatFnv1a64(pixelChecksum(
                                          image.pixels.data(), image.width, image.height, int(nc),
                                          listOrderOf(image.channels)))));
    Imf::OutputFile out(file.tempPath().c_str(), h);
    Imf::FrameBuffer fb;
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

namespace {
constexpr size_t kExrFlushBytes = size_t(1) << 20;
}  // namespace

ExrFileStream::ExrFileStream(const std::string& path, const std::string& name)
    : Imf::OStream(name.c_str()), name_(name) {
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw outputError(name_, std::string("cannot create: ") + std::strerror(errno));
}

ExrFileStream::~ExrFileStream() {
  if (fd_ >= 0) ::close(fd_);
}

void ExrFileStream::write(const char c[], int n) {
  // A write that does not continue or overlap the buffered run starts a new run.
  if (pos_ < start_ || pos_ > start_ + buffer_.size()) {
    flush();
    start_ = pos_;
  }
  const size_t at = size_t(pos_ - start_), end = at + size_t(n);
  if (end > buffer_.size()) buffer_.resize(end);
  std::memcpy(buffer_.data() + at, c, size_t(n));
  pos_ += uint64_t(n);
  if (buffer_.size() >= kExrFlushBytes) {
    flush();
    start_ = pos_;
  }
}

void ExrFileStream::flush() {
  if (buffer_.empty()) return;
  if (::lseek(fd_, off_t(start_), SEEK_SET) < 0 || !writeAll(fd_, buffer_.data(), buffer_.size()))
    throw outputError(name_, std::string("cannot write: ") + std::strerror(errno));
  buffer_.clear();
}

std::vector<char> ExrFileStream::readBack(uint64_t offset, size_t n) {
  flush();
  start_ = pos_;
  std::vector<char> bytes(n);
  size_t done = 0;
  while (done < n) {
    const ssize_t r = ::pread(fd_, bytes.data() + done, n - done, off_t(offset + done));
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) throw outputError(name_, std::string("cannot read back: ") + std::strerror(errno));
    if (r == 0) break;
    done += size_t(r);
  }
  bytes.resize(done);
  return bytes;
}

void ExrFileStream::overwrite(uint64_t offset, const std::string& bytes) {
  flush();
  start_ = pos_;
  if (::lseek(fd_, off_t(offset), SEEK_SET) < 0 || !writeAll(fd_, bytes.data(), bytes.size()))
    throw outputError(name_, std::string("cannot write: ") + std::strerror(errno));
}

void ExrFileStream::close() {
  flush();
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0)
    throw outputError(name_, std::string("cannot write: ") + std::strerror(errno));
}

}  // namespace rad
