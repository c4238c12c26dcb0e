// Single-part float OpenEXR images (frames of rad-reference and rad-compose, inputs of
// rad-diff). Scanline, ZIP, FLOAT channels; row 0 of the FloatImage is the top of the data
// window (EXR y grows downwards, so no flip).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <OpenEXR/ImfIO.h>

#include "libcommon/core/float_image.h"

namespace rad {

// Reads the named channels of the first part (any pixel type, converted to float). Every
// channel is read, and checked against the part's rad.pixelChecksum when it has one (required
// for rad frames 2.x; formats/pixel_checksum.h); every other part of a multi-part file is read
// and checked against its own (verifyExrPartPixels). The headers are bounded by the file's size
// first (scanExrFile). Throws rad::inputError(path, ...) if the file is unreadable, corrupted
// or lacks a channel (the message lists the channels it has).
FloatImage readExrImage(const std::string& path,
                        const std::vector<std::string>& channels = {"R", "G", "B"});

// Writes image atomically (AtomicFile) as FLOAT channels with the given string attributes
// (e.g. "rad.provenance") and rad.pixelChecksum. Throws rad::outputError(path, ...) on failure.
void writeExrImage(const std::string& path, const FloatImage& image,
                   const std::map<std::string, std::string>& stringAttributes = {});

// An OpenEXR output stream onto a new file that collects writes in memory and hands them over in
// large writes. Uncompressed files are one chunk per scanline and OpenEXR writes each chunk (and
// seeks for each chunk table) separately: a system call per scanline, for every movie a stage
// writes. The buffer is flushed at 1 MiB, so memory stays bounded whatever the file's size. Errors
// are rad::outputError(name, ...).
class ExrFileStream : public Imf::OStream {
 public:
  // Creates (truncates) `path`; `name` is the path errors report (the final one, not a
  // temporary's).
  ExrFileStream(const std::string& path, const std::string& name);
  ~ExrFileStream() override;
  ExrFileStream(const ExrFileStream&) = delete;
  ExrFileStream& operator=(const ExrFileStream&) = delete;
  void write(const char c[], int n) override;
  uint64_t tellp() override { return pos_; }
  void seekp(uint64_t pos) override { pos_ = pos; }
  // Writes what is buffered and closes the file (call it after OpenEXR's file object is gone).
  void close();
  // The file's bytes [offset, offset + n) as written so far (fewer at its end), and an
  // overwrite of bytes already written: for attributes a writer fills in after the pixels
  // (TextureMovieWriter's rad.pixelChecksum). Both write what is buffered first.
  std::vector<char> readBack(uint64_t offset, size_t n);
  void overwrite(uint64_t offset, const std::string& bytes);

 private:
  void flush();
  std::string name_;
  int fd_ = -1;
  std::vector<char> buffer_;
  uint64_t start_ = 0, pos_ = 0;  // file offset of buffer_[0]; the stream's position
};

}  // namespace rad
