// libcommon/image_difference: the error and flicker figures of rad-diff on synthetic images
// whose answers are known exactly.
#include "libcommon/reference/image_difference.h"
#include "libcommon/reference/sequence_difference.h"

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

// docs/design.md §10's case: walls of radiance 1 (grey), a 4x4 light of radiance 200 in a 20x20
// frame, and a test whose walls are 9 % too dark and whose light is right. The relative L2,
// normalised by the reference RMS that the light dominates, reads about 0.2 %; the figure over
// the non-emitters reads 9 % and the bias -9 %, exactly.
FloatImage wallsAndLight(float wall, float light) {
  FloatImage im(20, 20, {"R", "G", "B"});
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 20; ++x)
      for (int c = 0; c < 3; ++c) im.at(x, y, c) = (x >= 8 && x < 12 && y < 4) ? light : wall;
  return im;
}

TEST(ImageDifference, NonEmitterFigureSeesTheDarkWallsThatRelativeL2Hides) {
  FloatImage ref = wallsAndLight(1.0f, 200.0f), test = wallsAndLight(0.91f, 200.0f);
  const double walls = 400 - 16, dark = 1.0 - double(0.91f);
  DifferenceStats all = compareImages(test, ref);
  EXPECT_NEAR(all.relativeL2(), dark * std::sqrt(walls / (walls + 16 * 200.0 * 200.0)), 1e-12);
  EXPECT_LT(all.relativeL2(), 0.003);

  ErrorFigures e = measureError(test, ref, nullptr, EmitterRule{});
  EXPECT_DOUBLE_EQ(e.emitterThreshold, 10.0);  // 10 x the median lit luminance (1)
  EXPECT_EQ(e.surfaces.pixels, 400 - 16);
  EXPECT_EQ(e.surfaces.samples, 3 * (400 - 16));
  EXPECT_EQ(e.emitters.pixels, 16);
  EXPECT_NEAR(e.surfaces.meanReference(), 1.0, 1e-15);
  EXPECT_NEAR(e.surfaces.rmseOverMean(), dark, 1e-12);
  EXPECT_NEAR(e.surfaces.bias(), -dark, 1e-12);
  EXPECT_EQ(e.surfaces.noiseOverMean(), 0.0);  // one reference: no noise estimate
  EXPECT_EQ(e.emitters.rmseOverMean(), 0.0);   // the light itself is right

  // An emitter that is wrong is reported apart, and does not move the surfaces' figure.
  FloatImage brightLight = wallsAndLight(0.91f, 220.0f);
  ErrorFigures b = measureError(brightLight, ref, nullptr, EmitterRule{});
  EXPECT_NEAR(b.emitters.rmseOverMean(), 0.1, 1e-12);
  EXPECT_NEAR(b.emitters.bias(), 0.1, 1e-12);
  EXPECT_NEAR(b.surfaces.rmseOverMean(), dark, 1e-12);

  // An absolute threshold above the light counts every pixel as a surface.
  ErrorFigures none = measureError(test, ref, nullptr, EmitterRule{1000.0});
  EXPECT_EQ(none.emitters.pixels, 0);
  EXPECT_EQ(none.surfaces.pixels, 400);
  const double meanAll = (walls + 16 * 200.0) / 400.0;
  EXPECT_NEAR(none.surfaces.bias(), -dark * walls / 400.0 / meanAll, 1e-12);
}

TEST(ImageDifference, EmitterThresholdRule) {
  // Rec. 709 luminance decides, not the channel mean: a pure-blue pixel of 100 has Y = 7.22.
  FloatImage ref(10, 1, {"R", "G", "B"});
  for (int x = 0; x < 10; ++x)
    for (int c = 0; c < 3; ++c) ref.at(x, 0, c) = 1.0f;
  ref.at(9, 0, 0) = ref.at(9, 0, 1) = 0.0f;
  ref.at(9, 0, 2) = 100.0f;
  EXPECT_EQ(measureError(ref, ref, nullptr, EmitterRule{}).emitters.pixels, 0);
  ref.at(9, 0, 1) = 100.0f;  // Y = 78.74
  EXPECT_EQ(measureError(ref, ref, nullptr, EmitterRule{}).emitters.pixels, 1);
  EXPECT_EQ(luminanceWeights({"B", "G", "R"}), (std::vector<double>{0.0722, 0.7152, 0.2126}));
  EXPECT_EQ(luminanceWeights({"R", "B"}), (std::vector<double>{0.5, 0.5}));

  // Black background pixels do not pull the median (and the threshold) to zero.
  FloatImage sparse(10, 1, {"R"});
  sparse.pixels = {0, 0, 0, 0, 0, 0, 0, 2, 2, 50};
  EXPECT_DOUBLE_EQ(emitterThreshold(sparse, EmitterRule{}), 20.0);
  // A black frame has no emitter; a uniform one (the furnace) neither.
  EXPECT_TRUE(std::isinf(emitterThreshold(FloatImage(4, 4, {"R"}), EmitterRule{})));
  FloatImage uniform(4, 4, {"R"});
  for (float& v : uniform.pixels) v = 500.0f;
  EXPECT_EQ(measureError(uniform, uniform, nullptr, EmitterRule{}).emitters.pixels, 0);
}

// A mask replaces the rule: its first channel > 0.5 marks emitters, whatever their luminance.
TEST(ImageDifference, EmitterMaskReplacesTheRule) {
  FloatImage ref = wallsAndLight(1.0f, 200.0f), test = wallsAndLight(0.91f, 200.0f);
  FloatImage mask(20, 20, {"Y", "Z"});
  for (int x = 0; x < 20; ++x) mask.at(x, 19, 0) = 1.0f;  // the bottom row, not the light
  for (int x = 0; x < 20; ++x) mask.at(x, 18, 1) = 1.0f;  // second channel: ignored
  ErrorFigures e = measureError(test, ref, nullptr, EmitterRule{}, "t", "r2", &mask, "m.exr");
  EXPECT_EQ(e.emitters.pixels, 20);
  EXPECT_EQ(e.surfaces.pixels, 380);
  EXPECT_TRUE(std::isnan(e.emitterThreshold));
  EXPECT_NEAR(e.emitters.bias(), -(1.0 - double(0.91f)), 1e-12);
  FloatImage small(4, 4, {"Y"});
  try {
    measureError(test, ref, nullptr, EmitterRule{}, "t", "r2", &small, "m.exr");
    FAIL() << "no error";
  } catch (const Error& err) {
    EXPECT_EQ(std::string(err.what()), "m.exr: size 4x4 differs from the reference's 20x20");
  }
}

// Deterministic noise, uniform in [-a, a] (a 64-bit LCG; the same on every platform).
struct Lcg {
  unsigned long long state;
  float next(float a) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return a * (2.0f * float(double(state >> 11) / double(1ULL << 53)) - 1.0f);
  }
};

// Two references of the same truth with independent noise of standard deviation ~0.115 and a
// test 5 % too dark: the raw figure reads about 12 %, the noise-removed one recovers 5 %.
TEST(ImageDifference, SecondReferenceRemovesTheReferencesNoise) {
  const int w = 128, h = 128;
  FloatImage truth(w, h, {"R", "G", "B"});
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) truth.at(x, y, c) = 1.0f;
  FloatImage ref1 = truth, ref2 = truth, test = truth;
  Lcg n1{1}, n2{2};
  const float a = 0.2f;  // uniform in [-a, a]: sigma = a / sqrt(3)
  for (std::size_t i = 0; i < truth.pixels.size(); ++i) {
    ref1.pixels[i] += n1.next(a);
    ref2.pixels[i] += n2.next(a);
    test.pixels[i] *= 0.95f;
  }
  ErrorFigures e = measureError(test, ref1, &ref2, EmitterRule{});
  EXPECT_EQ(e.emitters.pixels, 0);
  const double sigma = a / std::sqrt(3.0);
  EXPECT_NEAR(e.surfaces.noiseOverMean(), sigma, 0.003);
  EXPECT_NEAR(e.surfaces.rmseOverMean(), 0.05, 0.0015);
  EXPECT_NEAR(e.surfaces.bias(), -0.05, 0.002);
  EXPECT_NEAR(e.surfaces.rawRmseOverMean(), std::sqrt(0.05 * 0.05 + sigma * sigma), 0.003);
  EXPECT_GT(e.surfaces.rawRmseOverMean(), 0.1);  // what one noisy reference would report
  ErrorFigures one = measureError(test, ref1, nullptr, EmitterRule{});
  EXPECT_GT(one.surfaces.rmseOverMean(), 0.1);

  // A second reference of another size names itself.
  try {
    measureError(test, ref1, &truth, EmitterRule{}, "t.exr", "r2.exr");
    FloatImage small(4, 4, {"R", "G", "B"});
    measureError(test, ref1, &small, EmitterRule{}, "t.exr", "r2.exr");
    FAIL() << "no error";
  } catch (const Error& err) {
    EXPECT_EQ(std::string(err.what()), "r2.exr: size 4x4 differs from the reference's 128x128");
  }
}

// Sequence totals are pooled sums: two frames with different error and mean give the figure
// of all their samples together, not the mean of the two per-frame ratios.
TEST(ImageDifference, SequenceTotalsArePooledNotAveraged) {
  auto frame = [](float value) {
    FloatImage im(2, 2, {"R"});
    for (float& v : im.pixels) v = value;
    return im;
  };
  SequenceDifference seq = compareSequence({0, 1}, [&](int f) {
    return f == 0 ? std::make_pair(frame(1.1f), frame(1.0f))
                  : std::make_pair(frame(3.0f), frame(2.0f));
  });
  ASSERT_EQ(seq.frames.size(), 2u);
  EXPECT_NEAR(seq.frames[0].error.surfaces.bias(), double(1.1f) - 1.0, 1e-7);
  EXPECT_NEAR(seq.frames[1].error.surfaces.bias(), 0.5, 1e-12);
  EXPECT_NEAR(seq.totalError.surfaces.bias(), (double(1.1f) - 1.0 + 1.0) / 3.0, 1e-7);
  EXPECT_EQ(seq.totalError.surfaces.pixels, 8);
}

}  // namespace
}  // namespace rad
