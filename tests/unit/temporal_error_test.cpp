// libcommon/reference/temporal_error: the temporal error of docs/design.md §10.6 on synthetic
// sequences whose answer is known: an edge that moves with the truth reads 0, one that jumps a
// whole pixel where the truth moves a fraction reads its step at edge pixels only, and the
// references' own noise is removed.
#include "libcommon/reference/temporal_error.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace rad {
namespace {

constexpr int W = 32, H = 8;

// 1 left of `edge` (in pixels, the fraction covering the pixel it crosses), 0.2 right of it:
// a box-filtered vertical edge between two flat surfaces.
FloatImage edgeAt(double edge, double noise = 0.0, unsigned seed = 0) {
  FloatImage im(W, H, {"R", "G", "B"});
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, noise);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const double cover = std::clamp(edge - x, 0.0, 1.0);
      for (int c = 0; c < 3; ++c)
        im.at(x, y, c) = float(0.2 + 0.8 * cover + (noise > 0 ? n(rng) : 0.0));
    }
  return im;
}

std::vector<uint8_t> edgeColumns(double edge) {
  std::vector<uint8_t> e(size_t(W) * H, 0);
  const int x = int(std::floor(edge));
  for (int y = 0; y < H; ++y)
    for (int dx = -1; dx <= 1; ++dx)
      if (x + dx >= 0 && x + dx < W) e[size_t(y) * W + size_t(x + dx)] = 1;
  return e;
}

const std::vector<uint8_t> kNoEmitter(size_t(W) * H, 0);

TEST(TemporalError, AnEdgeMovingWithTheTruthReadsZero) {
  const FloatImage r0 = edgeAt(10.3), r1 = edgeAt(10.6);
  const std::vector<uint8_t> e0 = edgeColumns(10.3), e1 = edgeColumns(10.6);
  TemporalError t;
  t.addPair({&r0, &r0, nullptr, &kNoEmitter, &e0}, {&r1, &r1, nullptr, &kNoEmitter, &e1});
  EXPECT_EQ(t.framePairs, 1);
  EXPECT_TRUE(t.haveEdges);
  EXPECT_DOUBLE_EQ(t.all.rmseOverMean(), 0.0);
  EXPECT_GT(t.edge.samples, 0);
  EXPECT_GT(t.interior.samples, 0);
}

TEST(TemporalError, ACrawlingEdgeReadsItsStepAtEdgePixelsOnly) {
  // The truth moves 0.3 px; the test (pixel centres) jumps from 10 to 11 covered pixels.
  const FloatImage r0 = edgeAt(10.4), r1 = edgeAt(10.7);
  const FloatImage t0 = edgeAt(10.0), t1 = edgeAt(11.0);
  const std::vector<uint8_t> e0 = edgeColumns(10.4), e1 = edgeColumns(10.7);
  TemporalError t;
  t.addPair({&t0, &r0, nullptr, &kNoEmitter, &e0}, {&t1, &r1, nullptr, &kNoEmitter, &e1});
  // Column 10: Δt = 0.8, Δr = 0.8 * 0.3: d = 0.56 on one column of the three edge columns.
  const double meanEdge = t.edge.sumReference / double(t.edge.samples);
  EXPECT_NEAR(t.edge.rmseOverMean(), std::sqrt(0.56 * 0.56 / 3.0) / meanEdge,
              1e-6);  // float images
  EXPECT_DOUBLE_EQ(t.interior.rmseOverMean(), 0.0);
  EXPECT_GT(t.all.rmseOverMean(), 0.0);
}

TEST(TemporalError, TheReferencesNoiseIsRemoved) {
  // The test is the truth; both references are the truth plus independent noise of 0.05.
  const FloatImage truth0 = edgeAt(10.4), truth1 = edgeAt(10.7);
  const FloatImage a0 = edgeAt(10.4, 0.05, 1), a1 = edgeAt(10.7, 0.05, 2);
  const FloatImage b0 = edgeAt(10.4, 0.05, 3), b1 = edgeAt(10.7, 0.05, 4);
  TemporalError t;
  t.addPair({&truth0, &a0, &b0, &kNoEmitter, nullptr}, {&truth1, &a1, &b1, &kNoEmitter, nullptr});
  EXPECT_FALSE(t.haveEdges);
  EXPECT_GT(t.all.rawRmseOverMean(), 0.1);  // sqrt(2) * 0.05 over a mean of about 0.5
  EXPECT_LT(t.all.rmseOverMean(), 0.03);    // the noise's share removed
}

TEST(TemporalError, EmittersInEitherFrameAreLeftOut) {
  const FloatImage r0 = edgeAt(10.4), r1 = edgeAt(10.7);
  const FloatImage t0 = edgeAt(10.0), t1 = edgeAt(11.0);
  std::vector<uint8_t> emitter(size_t(W) * H, 0);
  for (int y = 0; y < H; ++y) emitter[size_t(y) * W + 10] = 1;  // the column that crawls
  TemporalError t;
  t.addPair({&t0, &r0, nullptr, &kNoEmitter, nullptr}, {&t1, &r1, nullptr, &emitter, nullptr});
  EXPECT_DOUBLE_EQ(t.all.rmseOverMean(), 0.0);
}

}  // namespace
}  // namespace rad
