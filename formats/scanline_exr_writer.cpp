#include "formats/scanline_exr_writer.h"

#include <algorithm>
#include <cstring>

#include "libcommon/core/error.h"

namespace rad {

namespace {

void appendU32(std::string& s, uint32_t v) {
  for (int b = 0; b < 4; ++b) s.push_back(char((v >> (8 * b)) & 0xffu));
}
void appendU64(std::string& s, uint64_t v) {
  for (int b = 0; b < 8; ++b) s.push_back(char((v >> (8 * b)) & 0xffu));
}
void appendF32(std::string& s, float f) {
  uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  appendU32(s, u);
}
void putU32(char* at, uint32_t v) {
  for (int b = 0; b < 4; ++b) at[b] = char((v >> (8 * b)) & 0xffu);
}

ExrAttribute box(const std::string& name, int w, int h) {
  std::string v;
  for (int x : {0, 0, w - 1, h - 1}) appendU32(v, uint32_t(x));
  return {name, "box2i", v};
}

// The attributes OpenEXR gives every part of an uncompressed FLOAT R, G, B scan-line file
// (Imf::Header(w, h) with those channels, and MultiPartOutputFile's chunkCount with parts > 1).
std::vector<ExrAttribute> standardAttributes(int w, int h, bool multiPart) {
  std::string channels;
  for (const char* c : {"B", "G", "R"}) {  // the channel list is sorted by name
    channels += c;
    channels.push_back('\0');
    appendU32(channels, 2);    // FLOAT
    channels.append(4, '\0');  // pLinear, reserved
    appendU32(channels, 1);    // x sampling
    appendU32(channels, 1);    // y sampling
  }
  channels.push_back('\0');
  std::string one, centre;
  appendF32(one, 1.0f);
  appendF32(centre, 0.0f);
  appendF32(centre, 0.0f);
  std::vector<ExrAttribute> a = {{"channels", "chlist", channels},
                                 {"compression", "compression", std::string(1, '\0')},
                                 box("dataWindow", w, h),
                                 box("displayWindow", w, h),
                                 {"lineOrder", "lineOrder", std::string(1, '\0')},
                                 {"pixelAspectRatio", "float", one},
                                 {"screenWindowCenter", "v2f", centre},
                                 {"screenWindowWidth", "float", one}};
  if (multiPart) a.push_back(ExrAttribute::integer("chunkCount", h));
  return a;
}

}  // namespace

ExrAttribute ExrAttribute::integer(const std::string& name, int v) {
  std::string s;
  appendU32(s, uint32_t(v));
  return {name, "int", s};
}

ExrAttribute ExrAttribute::real(const std::string& name, double v) {
  uint64_t u;
  std::memcpy(&u, &v, sizeof u);
  std::string s;
  appendU64(s, u);
  return {name, "double", s};
}

ExrAttribute ExrAttribute::text(const std::string& name, const std::string& v) {
  return {name, "string", v};
}

ScanlineExrWriter::ScanlineExrWriter(ExrFileStream& stream, int width, int height,
                                     const std::vector<std::vector<ExrAttribute>>& extra)
    : stream_(stream), width_(width), height_(height), multiPart_(extra.size() > 1) {
  std::string head = "\x76\x2f\x31\x01";
  appendU32(head, multiPart_ ? 0x1002u : 0x2u);  // version 2; the multi-part bit
  stringValues_.resize(extra.size());
  for (size_t k = 0; k < extra.size(); ++k) {
    std::vector<ExrAttribute> all = standardAttributes(width, height, multiPart_);
    all.insert(all.end(), extra[k].begin(), extra[k].end());
    // OpenEXR writes a header's attributes in the order of their names (strcmp).
    std::sort(all.begin(), all.end(), [](const ExrAttribute& a, const ExrAttribute& b) {
      return std::strcmp(a.name.c_str(), b.name.c_str()) < 0;
    });
    for (const ExrAttribute& a : all) {
      head += a.name;
      head.push_back('\0');
      head += a.type;
      head.push_back('\0');
      appendU32(head, uint32_t(a.value.size()));
      if (a.type == "string") stringValues_[k].emplace_back(a.name, head.size());
      head += a.value;
    }
    head.push_back('\0');
  }
  if (multiPart_) head.push_back('\0');  // the empty header that ends a multi-part list
  tables_ = head.size();
  head.append(extra.size() * size_t(height) * 8, '\0');
  head_.assign(head.begin(), head.end());
  end_ = head_.size();
}

void ScanlineExrWriter::setText(size_t part, const std::string& name, const std::string& value) {
  for (const auto& [n, at] : stringValues_.at(part)) {
    if (n != name) continue;
    uint32_t size = 0;
    for (int b = 0; b < 4; ++b) size |= uint32_t(uint8_t(head_[at - 4 + size_t(b)])) << (8 * b);
    if (size != value.size()) break;
    std::memcpy(head_.data() + at, value.data(), value.size());
    return;
  }
  throw Error(ExitCode::kInternal, "exr", "no string attribute " + name + " of that length");
}

void ScanlineExrWriter::writePart(size_t part, const float* rgb) {
  const size_t prefix = multiPart_ ? 12 : 8, row = size_t(width_) * 12;
  std::vector<char> chunks(size_t(height_) * (prefix + row));
  char* out = chunks.data();
  for (int y = 0; y < height_; ++y) {
    // The chunk table entry: where this scan line's chunk starts.
    const uint64_t at = end_ + uint64_t(out - chunks.data());
    for (int b = 0; b < 8; ++b)
      head_[tables_ + (part * size_t(height_) + size_t(y)) * 8 + size_t(b)] =
          char((at >> (8 * b)) & 0xffu);
    if (multiPart_) {
      putU32(out, uint32_t(part));
      out += 4;
    }
    putU32(out, uint32_t(y));
    putU32(out + 4, uint32_t(row));
    out += 8;
    const float* line = rgb + size_t(y) * size_t(width_) * 3;
    for (int c = 2; c >= 0; --c)  // B, G, R: the channels' sorted order
      for (int x = 0; x < width_; ++x, out += 4) {
        uint32_t u;
        std::memcpy(&u, &line[size_t(x) * 3 + size_t(c)], sizeof u);
        putU32(out, u);
      }
  }
  stream_.seekp(end_);
  stream_.write(chunks.data(), int(chunks.size()));
  end_ += chunks.size();
}

void ScanlineExrWriter::finish() {
  stream_.seekp(0);
  stream_.write(head_.data(), int(head_.size()));
  stream_.seekp(end_);
}

}  // namespace rad
