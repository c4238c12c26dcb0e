// docs/design.md §10.3: edge pixels from an item buffer's surfaces.
#include "libcommon/reference/edge_pixels.h"

#include <algorithm>

namespace rad {

const char* pixelRegionName(int region) {
  switch (region) {
    case kEdgeRegion:
      return "edge";
    case kInteriorRegion:
      return "interior";
    default:
      return "background";
  }
}

EdgePixels findEdgePixels(const FrameSurfaces& s) {
  EdgePixels e;
  e.width = s.width;
  e.height = s.height;
  const size_t n = size_t(s.width) * size_t(s.height);
  e.edge.assign(n, 0);
  e.background.assign(n, 0);
  auto differ = [&](int a, int b) {
    if (a == b) return false;
    if (a < 0 || b < 0) return true;
    return !s.sameSurface(a, b);
  };
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x) {
      const int a = s.patchAt(x, y);
      const size_t p = size_t(y) * size_t(s.width) + size_t(x);
      e.background[p] = a < 0;
      bool edge = false;
      for (int dy = -1; dy <= 1 && !edge; ++dy)
        for (int dx = -1; dx <= 1 && !edge; ++dx) {
          const int u = x + dx, v = y + dy;
          if ((dx == 0 && dy == 0) || u < 0 || v < 0 || u >= s.width || v >= s.height) continue;
          edge = differ(a, s.patchAt(u, v));
        }
      e.edge[p] = edge;
    }
  return e;
}

PixelGroups EdgePixels::regions() const {
  PixelGroups g;
  g.count = kPixelRegionCount;
  g.ofPixel.resize(edge.size());
  for (size_t p = 0; p < edge.size(); ++p)
    g.ofPixel[p] = edge[p] ? kEdgeRegion : background[p] ? kBackgroundRegion : kInteriorRegion;
  return g;
}

std::vector<uint8_t> EdgePixels::clearOfEdges(int clearance) const {
  // Separable: the largest edge flag over each row's window, then over each column's.
  const int r = std::max(clearance - 1, 0);
  std::vector<uint8_t> rows(edge.size(), 0), clear(edge.size(), 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      uint8_t m = 0;
      for (int u = std::max(x - r, 0); u <= std::min(x + r, width - 1); ++u)
        m |= edge[size_t(y) * size_t(width) + size_t(u)];
      rows[size_t(y) * size_t(width) + size_t(x)] = m;
    }
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      uint8_t m = 0;
      for (int v = std::max(y - r, 0); v <= std::min(y + r, height - 1); ++v)
        m |= rows[size_t(v) * size_t(width) + size_t(x)];
      clear[size_t(y) * size_t(width) + size_t(x)] = !m;
    }
  return clear;
}

}  // namespace rad
