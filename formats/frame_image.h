// frames/NNNN.exr and frames/NNNN.png: rad-compose's final frames (docs/design.md §5).
//
// EXR: one scanline part, channels R, G, B of linear exitant radiance W/(m^2 sr), FLOAT (or HALF
// with --half; values above 65504 are clamped there), row 0 = top; uncompressed unless
// --compression says otherwise (ZIP saves little of noise-free float radiance, for much of
// rad-compose's time).
// String/int/double attributes: rad.format "frame 2.2", rad.pixelChecksum
// (formats/pixel_checksum.h), rad.frame, rad.time, rad.units, rad.exposureEV (what the PNG used),
// rad.coveredPixels, rad.moviePixels, rad.fallbackPixels and rad.provenance
// (Provenance::toJson().dump()). Readable with exrheader / oiiotool / rad-inspect.
//
// PNG: 8-bit sRGB of the radiance scaled by 2^exposureEV (frame_composer.h toSrgb8), written
// with libpng; the provenance goes into its "Description" text chunk (zTXt).
//
// Both writes are atomic (formats/atomic_file.h) and deterministic (no time stamps). A sequence
// writer may defer their fsyncs (FrameImageInfo::durability) and sync the directory once.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "formats/atomic_file.h"
#include "libcommon/compose/frame_composer.h"

namespace rad {

constexpr int kFrameImageMajor = 2;
constexpr int kFrameImageMinor = 2;

struct FrameImageInfo {
  int frame = 0;
  double exposureEV = 0.0;
  std::string provenanceJson;
  // kDeferred: the caller calls syncFileSystemOf() once after the last frame (composeSequence
  // does), not an fsync per frame, which costs rad-compose wall time.
  AtomicFile::Durability durability = AtomicFile::Durability::kEachFile;
};

// Throws rad::outputError(path, ...) when it cannot be written.
// EXR compressions rad-compose offers: none (default), rle, zip, piz. Usage Error otherwise.
int frameCompressionOf(const std::string& name);
void writeFrameExr(const std::string& path, const ComposedFrame& frame, const FrameImageInfo& info,
                   bool half, int compression = 0);
void writeFramePng(const std::string& path, const ComposedFrame& frame, const FrameImageInfo& info);

// What a frame EXR holds (for tests and tools): pixels as float RGB, row 0 = top, and its
// string, int and double attributes printed as strings. Throws rad::inputError(path, ...).
struct FrameExr {
  int width = 0, height = 0;
  bool half = false;
  std::vector<float> rgb;
  std::map<std::string, std::string> attributes;
};
FrameExr readFrameExr(const std::string& path);

// Path of frame f in dir with extension ext (".exr", ".png"): dir/0012.exr.
std::string framePath(const std::string& dir, int frame, const std::string& ext);

}  // namespace rad
