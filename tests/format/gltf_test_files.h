// Small glTF scenes and images written at test time (no binary files in git): a lit triangle
// with an optional base-colour texture, PNG and JPEG encoders, and a PNG whose header claims any
// size (an all-zero image deflates to about 1/1000 of its pixels).
#pragma once

#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>
#include <stb/stb_image_write.h>

#include "libcommon/core/error.h"

namespace rad::test {

// A triangle: 3 float VEC3 positions (36 bytes) + 3 unsigned short indices and padding (8).
inline std::string triangleBin() {
  const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const uint16_t idx[4] = {0, 1, 2, 0};
  std::string bin(reinterpret_cast<const char*>(pos), sizeof pos);
  bin.append(reinterpret_cast<const char*>(idx), sizeof idx);
  return bin;  // 44 bytes
}

// One emissive triangle (material 0, baseColorFactor 0.5 0.25 0.125) with TEXCOORD_0, its
// base-colour texture at `imageUri` when not empty; buffer "tri.bin" of 68 bytes (positions,
// indices, uvs); a perspective camera of `yfov`.
inline std::string texturedTriangleGltf(const std::string& imageUri, double yfov = 0.8,
                                        const std::string& binUri = "tri.bin") {
  const std::string texture = imageUri.empty() ? "" : R"(, "baseColorTexture": {"index": 0})";
  const std::string images =
      imageUri.empty()
          ? ""
          : R"(, "textures": [{"source": 0}], "images": [{"uri": ")" + imageUri + R"("}])";
  return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
    "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0.3, 0.3, 2]}],
    "cameras": [{"type": "perspective", "perspective": {"yfov": )" +
         numberText(yfov) + R"(, "znear": 0.01}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 2}, "indices": 1,
                                "material": 0}]}],
    "materials": [{"doubleSided": true, "emissiveFactor": [1, 1, 1],
                   "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 0.125, 1])" +
         texture + R"(}}],
    "buffers": [{"uri": ")" +
         binUri + R"(", "byteLength": 68}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                    {"buffer": 0, "byteOffset": 36, "byteLength": 8},
                    {"buffer": 0, "byteOffset": 44, "byteLength": 24}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 3,
                   "min": [0,0,0], "max": [1,1,0]},
                  {"bufferView": 1, "componentType": 5123, "type": "SCALAR", "count": 3},
                  {"bufferView": 2, "componentType": 5126, "type": "VEC2", "count": 3}])" +
         images + "}";
}

inline std::string texturedTriangleBin() {
  const float uv[6] = {0, 0, 1, 0, 0, 1};
  return triangleBin() + std::string(reinterpret_cast<const char*>(uv), sizeof uv);  // 68
}

inline void writeFile(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

inline void appendStbBytes(void* context, void* data, int size) {
  static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size));
}

// A w x h RGB image of a gradient, as PNG or JPEG bytes.
inline std::string encodedImage(int w, int h, bool jpeg) {
  std::vector<unsigned char> rgb(size_t(w) * size_t(h) * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<unsigned char>((i * 37) % 251);
  std::string out;
  if (jpeg)
    stbi_write_jpg_to_func(&appendStbBytes, &out, w, h, 3, rgb.data(), 90);
  else
    stbi_write_png_to_func(&appendStbBytes, &out, w, h, 3, rgb.data(), w * 3);
  return out;
}

inline void appendBigEndian(std::string& s, uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) s += char((v >> shift) & 0xFF);
}

inline void appendPngChunk(std::string& png, const char* type, const std::string& data) {
  appendBigEndian(png, uint32_t(data.size()));
  std::string body = std::string(type, 4) + data;
  png += body;
  appendBigEndian(
      png, uint32_t(crc32(0, reinterpret_cast<const Bytef*>(body.data()), uInt(body.size()))));
}

// A real, complete w x h 8-bit grey PNG of zeros, deflated row by row (12,000^2: ~140 KB).
inline std::string zeroPng(uint32_t w, uint32_t h) {
  std::string ihdr;
  appendBigEndian(ihdr, w);
  appendBigEndian(ihdr, h);
  ihdr += std::string("\x08\x00\x00\x00\x00", 5);  // 8 bit, grey, deflate, filter 0, no interlace
  z_stream z{};
  deflateInit(&z, 9);
  std::vector<unsigned char> row(size_t(w) + 1, 0), out(1 << 16);
  std::string idat;
  for (uint32_t y = 0; y <= h; ++y) {
    z.next_in = row.data();
    z.avail_in = y < h ? uInt(row.size()) : 0;
    const int flush = y < h ? Z_NO_FLUSH : Z_FINISH;
    do {
      z.next_out = out.data();
      z.avail_out = uInt(out.size());
      deflate(&z, flush);
      idat.append(reinterpret_cast<const char*>(out.data()), out.size() - z.avail_out);
    } while (z.avail_out == 0);
  }
  deflateEnd(&z);
  std::string png("\x89PNG\r\n\x1a\n", 8);
  appendPngChunk(png, "IHDR", ihdr);
  appendPngChunk(png, "IDAT", idat);
  appendPngChunk(png, "IEND", "");
  return png;
}

// A fresh folder a test, named after the fixture's `prefix` and the test, holding the textured
// triangle's buffer (tri.bin); removed afterwards.
class TexturedTriangleFolder : public ::testing::Test {
 protected:
  explicit TexturedTriangleFolder(std::string prefix) : prefix_(std::move(prefix)) {}
  void SetUp() override {
    dir = std::filesystem::temp_directory_path() /
          (prefix_ + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    writeFile(at("tri.bin"), texturedTriangleBin());
  }
  void TearDown() override { std::filesystem::remove_all(dir); }
  std::string at(const std::string& name) const { return (dir / name).string(); }
  std::filesystem::path dir;

 private:
  std::string prefix_;
};

}  // namespace rad::test
