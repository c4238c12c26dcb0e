// Where the chunks of a scan-line OpenEXR file lie (from OpenEXR's core API), for the tests
// that corrupt pixel data, chunk tables or chunk headers on purpose.
#pragma once

#include <gtest/gtest.h>

#include <OpenEXR/openexr.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace rad::test {

// Where a scan-line file's chunks lie, from OpenEXR's core API.
struct Layout {
  std::vector<std::pair<uint64_t, uint64_t>> pixelData;  // (offset, size) of each chunk's data
  uint64_t tablesBegin = 0, chunksBegin = 0;             // chunk tables, then the chunks
};

inline Layout layoutOf(const std::string& file) {
  exr_context_t ctx = nullptr;
  EXPECT_EQ(exr_start_read(&ctx, file.c_str(), nullptr), EXR_ERR_SUCCESS);
  int parts = 0;
  exr_get_count(ctx, &parts);
  Layout l;
  size_t chunks = 0;
  uint64_t first = UINT64_MAX;
  for (int p = 0; p < parts; ++p) {
    exr_attr_box2i_t dw;
    int32_t lines = 0;
    exr_get_data_window(ctx, p, &dw);
    exr_get_scanlines_per_chunk(ctx, p, &lines);
    for (int y = dw.min.y; y <= dw.max.y; y += lines) {
      exr_chunk_info_t c;
      EXPECT_EQ(exr_read_scanline_chunk_info(ctx, p, y, &c), EXR_ERR_SUCCESS);
      l.pixelData.push_back({c.data_offset, c.packed_size});
      first = std::min(first, c.data_offset);
      ++chunks;
    }
  }
  exr_finish(&ctx);
  // A chunk starts with its y and data size (int32 each), after its part number in a
  // multi-part file; the chunk tables (8 bytes per chunk) end where the first chunk starts.
  l.chunksBegin = first - (parts > 1 ? 12 : 8);
  l.tablesBegin = l.chunksBegin - 8 * chunks;
  return l;
}

}  // namespace rad::test
