// The bounds every rad EXR reader checks before OpenEXR sees a file (issue 18, hostile input).
//
// OpenEXR allocates what a header declares: a string attribute's size, a data window's line offset
// table and decode buffers, a preview's pixels. A file of a few hundred bytes declaring a 1.9 GB
// string made the frame readers allocate it before refusing it. scanExrHeaders walks the headers
// from the file's bytes, bounds-checked, and refuses (rad::inputError naming the file) what no file
// of that size can back:
//
//   - a magic number other than 20000630, a version other than 2, unknown version flags;
//   - a name or type that is empty or unterminated within 256 bytes, or cut by the end of file;
//   - an attribute whose declared size is negative or exceeds the bytes left in the file; a
//     fixed-size type (box2i, int, tiledesc, ...) of another size, a channel list, preview or
//     string vector whose contents do not end exactly at the attribute's end (OpenEXR reads
//     what the value says, not the declared size, so the two walks would part ways), and counts
//     inside values (a preview's pixels, a string's length) that exceed the attribute;
//   - a part without channels, compression or dataWindow, an empty data window, an unknown
//     compression;
//   - a part whose decoded size (data window pixels x bytes per pixel of its channels, with
//     their sampling), or whose decode buffer for one chunk (lines per chunk, or one tile),
//     exceeds exrMaxRatio(compression) x file size + 1 MiB (exrDecodedLimit);
//   - chunk offset tables (8 bytes per chunk: the chunks the data window needs, or the part's
//     chunkCount if larger) that do not fit between the end of the headers and the end of file.
//
// Everything else (a channel's pixel type, pixel data, offsets) is left to OpenEXR, whose
// allocations are then bounded by the file's size.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace rad {

// One part as the scan saw it.
struct ExrScannedPart {
  std::string type;  // "scanlineimage", "tiledimage", "deepscanline", "deeptile"
  int compression = 0;
  int64_t width = 0, height = 0;
  int channels = 0;
  uint64_t decodedBytes = 0;  // data window x bytes per pixel (deep parts: 0)
  uint64_t chunks = 0;        // the offset table's entries
};

struct ExrHeaderScan {
  std::vector<ExrScannedPart> parts;
  uint64_t headerBytes = 0;  // magic, version and headers: where the offset tables start
  uint64_t fileBytes = 0;
  // FNV-1a 64 (formats/checksum.h) of the bytes [0, headerBytes): every attribute of every part.
  // For a rad file whose parts carry rad.pixelChecksum it names the content without reading the
  // pixels (rad-compose's movies input, formats/frame_image.md).
  uint64_t headerHash = 0;
};

// The most a part's decoded bytes may exceed its file's size by, per OpenEXR compression
// (Imf::Compression's numbering), and the limit it gives for a file of `fileBytes`.
uint64_t exrMaxRatio(int compression);
uint64_t exrDecodedLimit(int compression, uint64_t fileBytes);

// Scans `size` bytes, the whole file. Throws rad::inputError(name, "...") on what is listed
// above; a file cut within its headers is "OpenEXR header cut short at byte N".
ExrHeaderScan scanExrHeaders(const uint8_t* bytes, size_t size, const std::string& name);

// Opens `path` and scans its headers, reading only as much of it as they take. Throws
// rad::inputError(path, ...) as above, or if the file cannot be opened or is not a regular file.
ExrHeaderScan scanExrFile(const std::string& path);

}  // namespace rad
