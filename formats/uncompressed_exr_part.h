// One part of an uncompressed scan-line OpenEXR file of FLOAT B, G, R channels (a texture
// movie's key, texture_movie.md), read with two preads and no OpenEXR decoder. Why: rad-compose
// reads thousands of keys a run, and OpenEXR's core reader fetches and decodes each scan line
// as its own chunk (a chunk-table lookup, a read and a decode call a line), which cost more
// than the pixels' bytes.
#pragma once

#include <cstdint>
#include <vector>

namespace rad {

// Where part `part`'s chunk table lies: the table of every part before it has `height` entries
// (one chunk a scan line), after the headers' `headerBytes`.
inline uint64_t uncompressedPartTableAt(uint64_t headerBytes, int part, int height) {
  return headerBytes + uint64_t(part) * uint64_t(height) * 8;
}

// Reads part `part` (width x height, its chunk table at `tableAt`) of the file open as `fd` into
// `rgb` (interleaved R, G, B, scan line 0 first). The chunks must follow one another in line
// order, each with the leader OpenEXR writes (the part number when `multiPart`, the line, the
// byte count 12 x width): every leader is checked. Returns false, `rgb` unspecified, for any
// other layout or a failed read; the caller then reads the part through OpenEXR, which reports
// what is wrong. The values are those OpenEXR decodes (the callers verify the part's checksum).
bool readUncompressedRgbPart(int fd, uint64_t tableAt, bool multiPart, int part, int width,
                             int height, std::vector<float>& rgb);

}  // namespace rad
