// libcommon/reference/edge_pixels: which pixels are at a geometric edge, the regions they make,
// and the pixels clear of edges.
#include "libcommon/reference/edge_pixels.h"

#include <gtest/gtest.h>

namespace rad {
namespace {

// A W x H frame from a function of the pixel giving its patch (-1: background); patches 0 and
// 1 are one surface when `seam` (and never with 2).
FrameSurfaces surfaces(int W, int H, const std::function<int(int, int)>& patch, bool seam) {
  FrameSurfaces f;
  f.width = W;
  f.height = H;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) f.patchOfPixel.push_back(patch(x, y));
  f.sameSurface = [seam](int a, int b) { return a == b || (seam && a + b == 1); };
  f.emits = [](int) { return false; };
  f.nameOf = [](int p) { return std::to_string(p); };
  return f;
}

long long count(const std::vector<uint8_t>& flags) {
  long long n = 0;
  for (uint8_t f : flags) n += f;
  return n;
}

TEST(EdgePixels, PixelsBesideAnotherSurfaceOrTheBackgroundAreEdges) {
  // 12 x 10: columns 0-5 patch 0, 6-11 patch 1; a background square at x 8-9, y 4-5.
  auto patch = [](int x, int y) {
    return x >= 8 && x <= 9 && y >= 4 && y <= 5 ? -1 : x < 6 ? 0 : 1;
  };
  const EdgePixels distinct = findEdgePixels(surfaces(12, 10, patch, false));
  // The two columns either side of x = 5.5 (20 px), and the 4 x 4 ring around and on the
  // square (16 px: 4 background, 12 around it), none in common.
  EXPECT_EQ(count(distinct.edge), 20 + 16);
  EXPECT_TRUE(distinct.isEdge(5, 0));
  EXPECT_TRUE(distinct.isEdge(6, 9));
  EXPECT_FALSE(distinct.isEdge(4, 0));
  EXPECT_TRUE(distinct.isEdge(8, 4));    // background beside a surface
  EXPECT_TRUE(distinct.isEdge(10, 6));   // diagonal neighbour of the square
  EXPECT_FALSE(distinct.isEdge(11, 0));  // the image's border is no edge
  // A seam between patches of one surface is no edge: only the square's ring is left.
  const EdgePixels seam = findEdgePixels(surfaces(12, 10, patch, true));
  EXPECT_EQ(count(seam.edge), 16);
  EXPECT_FALSE(seam.isEdge(5, 0));
  // Regions: every pixel in exactly one; the background here is all edge.
  const PixelGroups regions = distinct.regions();
  long long n[kPixelRegionCount] = {0, 0, 0};
  for (int g : regions.ofPixel) ++n[g];
  EXPECT_EQ(n[kEdgeRegion], 36);
  EXPECT_EQ(n[kInteriorRegion], 120 - 36);
  EXPECT_EQ(n[kBackgroundRegion], 0);
}

TEST(EdgePixels, BackgroundAwayFromSurfacesIsItsOwnRegion) {
  // 10 x 10: patch 0 in x < 3, background elsewhere: columns 2 and 3 are edges.
  const EdgePixels e = findEdgePixels(surfaces(
      10, 10, [](int x, int) { return x < 3 ? 0 : -1; }, false));
  const PixelGroups regions = e.regions();
  long long n[kPixelRegionCount] = {0, 0, 0};
  for (int g : regions.ofPixel) ++n[g];
  EXPECT_EQ(n[kEdgeRegion], 20);
  EXPECT_EQ(n[kInteriorRegion], 20);
  EXPECT_EQ(n[kBackgroundRegion], 60);
}

TEST(EdgePixels, ClearOfEdgesKeepsTheClearanceInEveryDirection) {
  // One edge pixel's worth: patch 1 at (10, 10) alone in patch 0, so (9..11, 9..11) are edges.
  const EdgePixels e = findEdgePixels(surfaces(
      21, 21, [](int x, int y) { return x == 10 && y == 10 ? 1 : 0; }, false));
  EXPECT_EQ(count(e.edge), 9);
  const std::vector<uint8_t> clear = e.clearOfEdges(3);
  // Not clear: Chebyshev distance <= 2 from the 3 x 3 block, i.e. the 7 x 7 block 7..13.
  EXPECT_EQ(count(clear), 21 * 21 - 49);
  EXPECT_FALSE(clear[13 * 21 + 13]);
  EXPECT_TRUE(clear[14 * 21 + 13]);
  EXPECT_TRUE(clear[6 * 21 + 6]);
  EXPECT_EQ(count(e.clearOfEdges(1)), 21 * 21 - 9);
}

}  // namespace
}  // namespace rad
