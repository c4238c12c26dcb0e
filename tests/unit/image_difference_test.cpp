// libcommon/image_difference: the error and flicker figures of rad-diff on synthetic images
// whose answers are known exactly.
#include "libcommon/reference/image_difference.h"

#include <cmath>

#include <gtest/gtest.h>

#include "libcommon/core/error.h"

namespace rad {
namespace {

FloatImage ramp(int w, int h, float scale) {
  FloatImage im(w, h, {"R", "G", "B"});
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) im.at(x, y, c) = scale * float(1 + x + 2 * y + c);
  return im;
}

TEST(ImageDifference, IdenticalImagesHaveZeroErrorAndInfinitePsnr) {
  FloatImage a = ramp(7, 5, 0.25f);
  DifferenceStats s = compareImages(a, a);
  EXPECT_EQ(s.samples, 7 * 5 * 3);
  EXPECT_EQ(s.rmse(), 0.0);
  EXPECT_EQ(s.relativeL2(), 0.0);
  EXPECT_EQ(s.maxAbsDifference, 0.0);
  EXPECT_TRUE(std::isinf(s.psnr()) && s.psnr() > 0);
}

TEST(ImageDifference, ConstantOffsetGivesExactFigures) {
  FloatImage ref = ramp(8, 4, 0.5f), test = ref;
  for (float& v : test.pixels) v += 0.125f;  // exact in float for these values
  DifferenceStats s = compareImages(test, ref);
  EXPECT_DOUBLE_EQ(s.rmse(), 0.125);
  EXPECT_DOUBLE_EQ(s.maxAbsDifference, 0.125);
  double sumSq = 0.0, peak = 0.0;
  for (float v : ref.pixels) sumSq += double(v) * v, peak = std::max(peak, double(v));
  EXPECT_DOUBLE_EQ(s.referencePeak, peak);
  EXPECT_NEAR(s.relativeL2(), 0.125 * std::sqrt(double(ref.pixels.size()) / sumSq), 1e-15);
  EXPECT_NEAR(s.psnr(), 20.0 * std::log10(peak / 0.125), 1e-12);
}

TEST(ImageDifference, NonFiniteSamplesAreCountedAndSkipped) {
  FloatImage ref = ramp(2, 2, 1.0f), test = ref;
  test.pixels[0] = std::nanf("");
  test.pixels[1] += 2.0f;
  DifferenceStats s = compareImages(test, ref);
  EXPECT_EQ(s.nonFinite, 1);
  EXPECT_EQ(s.samples, 11);
  EXPECT_DOUBLE_EQ(s.rmse(), std::sqrt(4.0 / 11.0));
  EXPECT_DOUBLE_EQ(s.maxAbsDifference, 2.0);
}

TEST(ImageDifference, ZeroReferenceGivesInfiniteRelativeError) {
  FloatImage ref(3, 3, {"R"}), test(3, 3, {"R"});
  test.pixels[4] = 1.0f;
  DifferenceStats s = compareImages(test, ref);
  EXPECT_TRUE(std::isinf(s.relativeL2()));
  EXPECT_TRUE(std::isnan(s.psnr()));  // no positive peak
}

TEST(ImageDifference, SizeMismatchIsAnInputError) {
  try {
    compareImages(ramp(4, 4, 1.0f), ramp(4, 5, 1.0f), "t.exr");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kBadInput);
    EXPECT_EQ(std::string(e.what()), "t.exr: size 4x4 differs from the reference's 4x5");
  }
  FloatImage oneChannel(4, 4, {"R"});
  EXPECT_THROW(compareImages(oneChannel, ramp(4, 4, 1.0f)), Error);
}

// Synthetic sequence: the reference is static on the left half and changes on the right half
// every frame; the test adds a +-d alternating flicker on every pixel. Only the left half
// counts, and there the mean |Δ| is exactly 2d.
TEST(ImageDifference, FlickerCountsOnlyPixelsWhereTheReferenceIsStatic) {
  const int w = 6, h = 4, frames = 5;
  const float d = 0.0625f;
  auto reference = [&](int f) {
    FloatImage im = ramp(w, h, 1.0f);
    for (int y = 0; y < h; ++y)
      for (int x = w / 2; x < w; ++x)
        for (int c = 0; c < 3; ++c) im.at(x, y, c) += float(f);
    return im;
  };
  auto test = [&](int f) {
    FloatImage im = reference(f);
    for (float& v : im.pixels) v += (f % 2 ? d : -d);
    return im;
  };
  std::vector<int> numbers = {0, 1, 2, 3, 4};
  SequenceDifference seq =
      compareSequence(numbers, [&](int f) { return std::make_pair(test(f), reference(f)); });
  ASSERT_EQ(seq.frames.size(), size_t(frames));
  EXPECT_EQ(seq.flicker.framePairs, frames - 1);
  EXPECT_EQ(seq.flicker.staticPixels, (frames - 1) * (w / 2) * h);
  EXPECT_DOUBLE_EQ(seq.flicker.mean(), 2.0 * d);
  EXPECT_DOUBLE_EQ(seq.flicker.maxAbsChange, 2.0 * d);
  EXPECT_DOUBLE_EQ(seq.total.rmse(), d);
  for (const FrameDifference& fd : seq.frames) EXPECT_DOUBLE_EQ(fd.stats.rmse(), d);

  // A flicker-free test (equal to the reference) has zero flicker.
  SequenceDifference same =
      compareSequence(numbers, [&](int f) { return std::make_pair(reference(f), reference(f)); });
  EXPECT_EQ(same.flicker.mean(), 0.0);
  EXPECT_EQ(same.flicker.staticPixels, seq.flicker.staticPixels);

  // A tolerance of 1 makes the moving half static too (it moves by exactly 1 per frame).
  SequenceDifference tolerant = compareSequence(
      numbers, [&](int f) { return std::make_pair(test(f), reference(f)); }, 1.0);
  EXPECT_EQ(tolerant.flicker.staticPixels, (frames - 1) * w * h);

  // Gaps: frames 0, 2, 3 give one consecutive pair only.
  SequenceDifference gaps =
      compareSequence({0, 2, 3}, [&](int f) { return std::make_pair(test(f), reference(f)); });
  EXPECT_EQ(gaps.flicker.framePairs, 1);
}

}  // namespace
}  // namespace rad
