#include "formats/uncompressed_exr_part.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace rad {

namespace {

bool readAll(int fd, void* buffer, size_t n, uint64_t offset) {
  size_t done = 0;
  while (done < n) {
    const ssize_t r =
        ::pread(fd, static_cast<char*>(buffer) + done, n - done, off_t(offset + done));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return false;
    done += size_t(r);
  }
  return true;
}

uint32_t u32At(const unsigned char* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

}  // namespace

bool readUncompressedRgbPart(int fd, uint64_t tableAt, bool multiPart, int part, int width,
                             int height, std::vector<float>& rgb) {
  if (width < 1 || height < 1) return false;
  unsigned char first[8];
  if (!readAll(fd, first, sizeof first, tableAt)) return false;
  uint64_t start = 0;
  for (int b = 7; b >= 0; --b) start = (start << 8) | first[b];
  const size_t leader = multiPart ? 12 : 8, row = size_t(width) * 12;
  const size_t bytes = size_t(height) * (leader + row);
  std::vector<unsigned char> chunks(bytes);
  if (!readAll(fd, chunks.data(), bytes, start)) return false;
  rgb.resize(size_t(width) * size_t(height) * 3);
  for (int y = 0; y < height; ++y) {
    const unsigned char* c = chunks.data() + size_t(y) * (leader + row);
    if (multiPart && u32At(c) != uint32_t(part)) return false;
    c += leader - 8;
    if (u32At(c) != uint32_t(y) || u32At(c + 4) != uint32_t(row)) return false;
    c += 8;
    float* line = rgb.data() + size_t(y) * size_t(width) * 3;
    for (int ch = 2; ch >= 0; --ch)  // B, G, R: the channel list's sorted order
      for (int x = 0; x < width; ++x, c += 4) {
        const uint32_t u = u32At(c);
        std::memcpy(&line[size_t(x) * 3 + size_t(ch)], &u, sizeof u);
      }
  }
  return true;
}

}  // namespace rad
