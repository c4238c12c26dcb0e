// libcommon/reference/seam_steps: the luminance step across a seam of two coplanar patches of
// one material (docs/design.md §10.5) on synthetic images whose steps are known.
#include "libcommon/reference/seam_steps.h"

#include <gtest/gtest.h>

namespace rad {
namespace {

constexpr int W = 40, H = 40;

// Patch 0 left of x = 20, patch 1 right of it, one surface when `seam`; patch 2 (an emitter
// when `lamp`) in the square 4..7 x 4..7.
FrameSurfaces twoPatches(bool seam, bool lamp = false) {
  FrameSurfaces f;
  f.width = W;
  f.height = H;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      f.patchOfPixel.push_back(x >= 4 && x < 8 && y >= 4 && y < 8 ? 2 : x < 20 ? 0 : 1);
  f.sameSurface = [seam](int a, int b) { return a == b || (seam && a + b == 1); };
  f.emits = [lamp](int p) { return lamp && p == 2; };
  f.nameOf = [](int p) { return std::to_string(p); };
  return f;
}

// `left` left of x = 20 and `right` from it on, in every channel.
FloatImage halves(float left, float right) {
  FloatImage im(W, H, {"R", "G", "B"});
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      for (int c = 0; c < 3; ++c) im.at(x, y, c) = x < 20 ? left : right;
  return im;
}

const std::vector<uint8_t> kNoEmitter(size_t(W) * H, 0);

// The test steps from 1.05 to 0.95 across the seam, the reference from 1.01 to 0.99: steps of
// 0.10 and 0.02 of the local mean 1, an excess of 0.08, over the 40 rows' pairs.
TEST(SeamSteps, AStepOfKnownSizeIsReportedWithThatSize) {
  const FrameSurfaces s = twoPatches(true);
  const EdgePixels edges = findEdgePixels(s);
  const SeamSteps steps =
      measureSeams(halves(1.05f, 0.95f), halves(1.01f, 0.99f), nullptr, kNoEmitter, s, edges);
  ASSERT_EQ(steps.seams.size(), 1u);
  const SeamSums& seam = steps.seams.at({0, 1});
  EXPECT_EQ(seam.pairs, H);
  EXPECT_EQ(seam.x, 19);
  EXPECT_EQ(seam.y, 0);
  EXPECT_NEAR(seam.localMean(), 1.0, 1e-6);
  EXPECT_NEAR(seam.testStep(), 0.10, 1e-6);
  EXPECT_NEAR(seam.referenceStep(), 0.02, 1e-6);
  EXPECT_NEAR(seam.excess(), 0.08, 1e-6);
  const SeamSummary summary = summariseSeams(steps);
  EXPECT_EQ(summary.seamsFound, 1);
  EXPECT_EQ(summary.seamsMeasured, 1);
  EXPECT_NEAR(summary.maxAbsTestStep, 0.10, 1e-6);
  EXPECT_NEAR(summary.meanAbsReferenceStep, 0.02, 1e-6);
  EXPECT_NEAR(summary.maxAbsExcess, 0.08, 1e-6);
  // Fewer pairs than the minimum: found, not measured.
  EXPECT_EQ(summariseSeams(steps, H + 1).seamsMeasured, 0);
  // The side with the lower patch id is side a, whichever way the image runs.
  const SeamSteps flipped =
      measureSeams(halves(0.95f, 1.05f), halves(1.0f, 1.0f), nullptr, kNoEmitter, s, edges);
  EXPECT_NEAR(flipped.seams.at({0, 1}).testStep(), -0.10, 1e-6);
}

// Two references: the reference's step is that of their mean, and the floor is half the
// difference of their steps.
TEST(SeamSteps, TheFloorIsHalfTheReferencesStepDifference) {
  const FrameSurfaces s = twoPatches(true);
  const EdgePixels edges = findEdgePixels(s);
  const FloatImage ref1 = halves(1.02f, 0.98f), ref2 = halves(1.0f, 1.0f);
  const SeamSteps steps = measureSeams(halves(1.0f, 1.0f), ref1, &ref2, kNoEmitter, s, edges);
  const SeamSums& seam = steps.seams.at({0, 1});
  EXPECT_NEAR(seam.referenceStep(), 0.02, 1e-6);
  EXPECT_NEAR(seam.floor(), 0.02, 1e-6);
  EXPECT_NEAR(seam.excess(), -0.02, 1e-6);
  EXPECT_NEAR(summariseSeams(steps).maxFloor, 0.02, 1e-6);
}

// Patches that are not one surface meet at an edge, not a seam; emitters and pixels at an
// edge (here the lamp's outline) make no pairs.
TEST(SeamSteps, EdgesAndEmittersAreNoSeams) {
  const FrameSurfaces distinct = twoPatches(false);
  EXPECT_TRUE(measureSeams(halves(1.05f, 0.95f), halves(1.0f, 1.0f), nullptr, kNoEmitter, distinct,
                           findEdgePixels(distinct))
                  .seams.empty());
  const FrameSurfaces lamp = twoPatches(true, true);
  const SeamSteps steps = measureSeams(halves(1.05f, 0.95f), halves(1.0f, 1.0f), nullptr,
                                       kNoEmitter, lamp, findEdgePixels(lamp));
  ASSERT_EQ(steps.seams.size(), 1u);  // no seam with the lamp (patch 2)
  EXPECT_EQ(steps.seams.at({0, 1}).pairs, H);
  // A pixel flagged as an emitter by the figure's rule makes no pair either.
  std::vector<uint8_t> emitter = kNoEmitter;
  emitter[size_t(10) * W + 19] = 1;
  const SeamSteps fewer = measureSeams(halves(1.05f, 0.95f), halves(1.0f, 1.0f), nullptr, emitter,
                                       lamp, findEdgePixels(lamp));
  EXPECT_EQ(fewer.seams.at({0, 1}).pairs, H - 1);
}

// Frames merge into pooled sums: two frames of 40 pairs each give the step of all 80 pairs.
TEST(SeamSteps, FramesMergeIntoPooledSums) {
  const FrameSurfaces s = twoPatches(true);
  const EdgePixels edges = findEdgePixels(s);
  SeamSteps total;
  total.merge(measureSeams(halves(1.1f, 0.9f), halves(1, 1), nullptr, kNoEmitter, s, edges, 3));
  total.merge(measureSeams(halves(1.0f, 1.0f), halves(1, 1), nullptr, kNoEmitter, s, edges, 4));
  const SeamSums& seam = total.seams.at({0, 1});
  EXPECT_EQ(seam.pairs, 2 * H);
  EXPECT_EQ(seam.frame, 3);
  EXPECT_NEAR(seam.testStep(), 0.1, 1e-6);
}

}  // namespace
}  // namespace rad
