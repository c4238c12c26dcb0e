// libcommon/reference/structured_error: the structured error of docs/design.md §10.4 on synthetic
// images whose answer is known: a blotch's amplitude, the references' floor, and an edge's or an
// emitter's error kept out.
#include "libcommon/reference/structured_error.h"

#include <cmath>

#include <gtest/gtest.h>

namespace rad {
namespace {

constexpr int W = 40, H = 40;

FrameSurfaces oneSurface(const std::function<int(int, int)>& patch) {
  FrameSurfaces f;
  f.width = W;
  f.height = H;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) f.patchOfPixel.push_back(patch(x, y));
  f.sameSurface = [](int a, int b) { return a == b; };
  f.emits = [](int) { return false; };
  f.nameOf = [](int p) { return std::to_string(p); };
  return f;
}

// Grey everywhere, plus `amplitude` in the square [x0, x0 + size) x [y0, y0 + size).
FloatImage greyWithBlotch(float grey, float amplitude, int x0, int y0, int size) {
  FloatImage im(W, H, {"R", "G", "B"});
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const bool in = x >= x0 && x < x0 + size && y >= y0 && y < y0 + size;
      for (int c = 0; c < 3; ++c) im.at(x, y, c) = grey + (in ? amplitude : 0.0f);
    }
  return im;
}

const std::vector<uint8_t> kNoEmitter(size_t(W) * H, 0);

// A 20 x 20 blotch of +4 % on a uniform surface: the 14 x 14 pixels whose 7 x 7 box lies
// inside it read exactly 0.04, none reads more, and they are more than 5 % of the 1600 pixels,
// so the 95th percentile is the blotch's amplitude.
TEST(StructuredError, ABlotchReadsItsAmplitude) {
  const EdgePixels edges = findEdgePixels(oneSurface([](int, int) { return 0; }));
  const FloatImage ref = greyWithBlotch(0.5f, 0.0f, 0, 0, 0);
  const FloatImage test = greyWithBlotch(0.5f, 0.02f, 10, 10, 20);
  FloatImage smoothed;
  const StructuredError s =
      measureStructuredError(test, ref, nullptr, kNoEmitter, edges, &smoothed);
  EXPECT_EQ(s.pixels, W * H);
  EXPECT_NEAR(s.meanReference, 0.5, 1e-7);
  EXPECT_NEAR(s.p95, 0.04, 1e-6);
  EXPECT_FALSE(s.hasFloor);
  EXPECT_NEAR(smoothed.at(20, 20, 0), 0.04f, 1e-6);
  EXPECT_NEAR(smoothed.at(10, 20, 0), 0.04f * 4 / 7, 1e-6);  // the box half over the blotch
  EXPECT_EQ(smoothed.at(2, 2, 0), 0.0f);
  // A blotch too small to fill 5 % of the pixels: 3 x 3 pixels, which 81 boxes of the 1600
  // overlap. The 1520th smallest value is the smallest of those 81, a box that overlaps the
  // blotch on one corner pixel: 1/49 of the amplitude.
  const StructuredError small = measureStructuredError(greyWithBlotch(0.5f, 0.02f, 10, 10, 3), ref,
                                                       nullptr, kNoEmitter, edges);
  EXPECT_NEAR(small.p95, 0.04 / 49, 1e-7);
}

// With a second reference: the test is measured against (ref + ref2) / 2 and the floor is the
// same figure of (ref - ref2) / 2: references of 0.5 -+ 0.01 over a 20 x 20 square read a
// floor of 0.02, a test equal to their mean reads 0.
TEST(StructuredError, TheFloorIsHalfTheReferencesDifference) {
  const EdgePixels edges = findEdgePixels(oneSurface([](int, int) { return 0; }));
  const FloatImage ref1 = greyWithBlotch(0.5f, 0.01f, 5, 5, 20);
  const FloatImage ref2 = greyWithBlotch(0.5f, -0.01f, 5, 5, 20);
  const FloatImage test = greyWithBlotch(0.5f, 0.0f, 0, 0, 0);
  const StructuredError s = measureStructuredError(test, ref1, &ref2, kNoEmitter, edges);
  EXPECT_TRUE(s.hasFloor);
  EXPECT_NEAR(s.floorP95, 0.02, 1e-6);
  EXPECT_NEAR(s.p95, 0.0, 1e-7);
}

// An error on the edge pixels alone reads 0: they are out of every box, and pixels within 3 of
// them are out of the percentile. An error on emitter pixels is out likewise.
TEST(StructuredError, EdgesAndEmittersDoNotLeakIntoTheSurfaces) {
  // Patch 0 left of x = 20, patch 1 right of it: columns 19 and 20 are edges.
  const EdgePixels edges = findEdgePixels(oneSurface([](int x, int) { return x < 20 ? 0 : 1; }));
  const FloatImage ref = greyWithBlotch(0.5f, 0.0f, 0, 0, 0);
  FloatImage test = ref;
  for (int y = 0; y < H; ++y)
    for (int x = 19; x <= 20; ++x)
      for (int c = 0; c < 3; ++c) test.at(x, y, c) = 5.0f;
  StructuredError s = measureStructuredError(test, ref, nullptr, kNoEmitter, edges);
  EXPECT_EQ(s.p95, 0.0);
  EXPECT_EQ(s.pixels, 34 * 40);  // columns 17-22 are within 2 of an edge pixel
  // An emitter (a 4 x 4 lamp at 100) in patch 0: its pixels are out of the boxes too.
  std::vector<uint8_t> emitter(size_t(W) * H, 0);
  FloatImage lamp = greyWithBlotch(0.5f, 99.5f, 4, 4, 4);
  for (int y = 4; y < 8; ++y)
    for (int x = 4; x < 8; ++x) emitter[size_t(y) * W + size_t(x)] = 1;
  s = measureStructuredError(lamp, ref, nullptr, emitter, edges);
  EXPECT_EQ(s.p95, 0.0);
  // Without the emitter flags the lamp's error spreads over its neighbours.
  EXPECT_GT(measureStructuredError(lamp, ref, nullptr, kNoEmitter, edges).p95, 0.0);
}

// A frame with no pixel 3 px clear of an edge has no figure (NaN), not a figure of 0.
TEST(StructuredError, NoPixelClearOfEdgesIsNoFigure) {
  const EdgePixels edges =
      findEdgePixels(oneSurface([](int x, int y) { return (x / 3 + y / 3) % 2; }));
  const FloatImage ref = greyWithBlotch(0.5f, 0.0f, 0, 0, 0);
  const StructuredError s = measureStructuredError(ref, ref, nullptr, kNoEmitter, edges);
  EXPECT_EQ(s.pixels, 0);
  EXPECT_TRUE(std::isnan(s.p95));
}

TEST(StructuredError, NearestRankPercentile) {
  std::vector<double> v = {5, 1, 4, 2, 3};
  EXPECT_EQ(nearestRankPercentile(v, 0.95), 5.0);  // ceil(4.75) = 5th smallest
  EXPECT_EQ(nearestRankPercentile(v, 0.5), 3.0);   // ceil(2.5) = 3rd smallest
  std::vector<double> none;
  EXPECT_EQ(nearestRankPercentile(none, 0.95), 0.0);
}

}  // namespace
}  // namespace rad
