// Item buffers as OpenEXR files (docs/design.md §5 `itembuffers/NNNN.exr`): what rad-intervals
// saw at one frame, for inspection with rad-inspect, exrheader or oiiotool.
//
// One scanline part, data window (0,0)-(width-1,height-1), row 0 = top of the image (EXR's
// INCREASING_Y, same as camera_projection.h), ZIP compression:
//   channel "id" UINT:  item id (rad-intervals: dense patch node index + 1; 0 = nothing)
//   channel "Z"  FLOAT: eye-space depth in metres (+inf where id is 0)
// Attributes: rad.format "item-buffer 2.0", rad.pixelChecksum (formats/pixel_checksum.h: over
// Z then id, the channel-list order, each value's 4 little-endian bytes), rad.frame (int),
// rad.time (double, seconds), rad.provenance (the writer's provenance JSON) when given.
// Spec and version history: formats/texture_intervals.md "Item buffers".
#pragma once

#include <cstdint>
#include <string>

#include "libcommon/gl/item_buffer.h"

namespace rad {

// 2.0: rad.pixelChecksum added and required (1.0 files are refused: re-run rad-intervals).
constexpr int kItemBufferExrMajor = 2;
constexpr int kItemBufferExrMinor = 0;

// Written atomically (AtomicFile). Throws rad::outputError(path, ...) on failure.
void writeItemBufferExr(const std::string& path, const ItemBuffer& buffer, int frame, double time,
                        const std::string& provenanceJson = "");
// Throws rad::inputError(path, ...) when the file is not an item buffer, is an older version,
// or its pixels do not match its rad.pixelChecksum.
ItemBuffer readItemBufferExr(const std::string& path);
// The rad.time attribute of an item buffer (seconds): when the frame's patches were placed.
// Throws rad::inputError(path, ...) when the file is not an item buffer or has no rad.time.
double readItemBufferTime(const std::string& path);
// The rad.pixelChecksum of an item buffer's pixels.
uint64_t itemBufferChecksum(const ItemBuffer& buffer);

}  // namespace rad
