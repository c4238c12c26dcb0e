// An uncompressed scan-line OpenEXR file of FLOAT R, G, B parts, written byte for byte as
// OpenEXR's MultiPartOutputFile writes it (one part: a single-part file), without building an
// Imf::Header per part. Why: rad-movies writes tens of thousands of small parts (one a key), and
// OpenEXR's per-part headers (attribute maps copied, sanity-checked, serialised) and per-part
// frame buffers cost more than the pixels' bytes. Layout: the OpenEXR file format (magic,
// version, headers with sorted attributes, one chunk table a part, one chunk a scan line).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "formats/exr_image.h"

namespace rad {

// One header attribute, its value already in the file's bytes (little-endian).
struct ExrAttribute {
  std::string name, type, value;
  static ExrAttribute integer(const std::string& name, int v);
  static ExrAttribute real(const std::string& name, double v);  // type "double"
  static ExrAttribute text(const std::string& name, const std::string& v);
};

class ScanlineExrWriter {
 public:
  // `extra[k]`: part k's attributes besides the standard ones (channels R, G, B FLOAT; no
  // compression; data and display windows (0,0)-(w-1,h-1); increasing Y; pixel aspect 1; the
  // screen window; with more than one part, chunkCount). A multi-part file's parts need "name"
  // and "type" ("scanlineimage") among them.
  // Writes nothing yet: the headers go to the file's start at finish(), with any value set by
  // setText() and the chunk tables filled in; the chunks are written as the parts come.
  ScanlineExrWriter(ExrFileStream& stream, int width, int height,
                    const std::vector<std::vector<ExrAttribute>>& extra);
  // Replaces the value of part k's string attribute `name` by one of the same length (a checksum
  // known only once the part's pixels are). Throws rad::Error (internal) otherwise.
  void setText(size_t part, const std::string& name, const std::string& value);
  // Part k's pixels: width * height interleaved R, G, B floats, scan line 0 first; parts in any
  // order, each once.
  void writePart(size_t part, const float* rgb);
  // Writes the headers and chunk tables (every part written).
  void finish();

 private:
  ExrFileStream& stream_;
  int width_, height_;
  bool multiPart_;
  std::vector<char> head_;  // magic, version, headers, then the chunk tables (zeros until set)
  std::vector<std::vector<std::pair<std::string, size_t>>> stringValues_;  // by part: offsets
  size_t tables_ = 0;                                                      // in head_
  uint64_t end_ = 0;  // file offset where the next part's chunks go
};

}  // namespace rad
