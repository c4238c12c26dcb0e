#include "libcommon/reference/image_difference.h"

#include <algorithm>
#include <cmath>

#include "libcommon/core/error.h"

namespace rad {

void DifferenceStats::add(const float* test, const float* reference, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) {
    const double a = test[i], b = reference[i];
    if (!std::isfinite(a) || !std::isfinite(b)) {
      ++nonFinite;
      continue;
    }
    const double d = a - b;
    ++samples;
    sumSquaredError += d * d;
    sumSquaredReference += b * b;
    maxAbsDifference = std::max(maxAbsDifference, std::abs(d));
    referencePeak = std::max(referencePeak, b);
  }
}

void DifferenceStats::merge(const DifferenceStats& o) {
  samples += o.samples;
  nonFinite += o.nonFinite;
  sumSquaredError += o.sumSquaredError;
  sumSquaredReference += o.sumSquaredReference;
  maxAbsDifference = std::max(maxAbsDifference, o.maxAbsDifference);
  referencePeak = std::max(referencePeak, o.referencePeak);
}

double DifferenceStats::rmse() const {
  return samples > 0 ? std::sqrt(sumSquaredError / double(samples)) : 0.0;
}

double DifferenceStats::relativeL2() const {
  if (sumSquaredError == 0.0) return 0.0;
  if (sumSquaredReference == 0.0) return std::numeric_limits<double>::infinity();
  return std::sqrt(sumSquaredError / sumSquaredReference);
}

double DifferenceStats::psnr() const {
  if (!(referencePeak > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  if (sumSquaredError == 0.0) return std::numeric_limits<double>::infinity();
  const double mse = sumSquaredError / double(samples);
  return 10.0 * std::log10(referencePeak * referencePeak / mse);
}

void requireSameShape(const FloatImage& a, const FloatImage& b, const std::string& where) {
  if (a.width != b.width || a.height != b.height)
    throw inputError(where, "size " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                                " differs from the reference's " + std::to_string(b.width) + "x" +
                                std::to_string(b.height));
  if (a.channelCount() != b.channelCount())
    throw inputError(where, std::to_string(a.channelCount()) + " channels; the reference has " +
                                std::to_string(b.channelCount()));
}

void FlickerStats::addPair(const FloatImage& testPrevious, const FloatImage& test,
                           const FloatImage& referencePrevious, const FloatImage& reference,
                           double staticTolerance) {
  requireSameShape(testPrevious, reference, "flicker: previous test frame");
  requireSameShape(test, reference, "flicker: test frame");
  requireSameShape(referencePrevious, reference, "flicker: previous reference frame");
  ++framePairs;
  const std::size_t nc = std::size_t(reference.channelCount());
  const std::size_t pixels = std::size_t(reference.width) * std::size_t(reference.height);
  for (std::size_t p = 0; p < pixels; ++p) {
    const std::size_t base = p * nc;
    bool isStatic = true;
    for (std::size_t c = 0; c < nc && isStatic; ++c) {
      const double r0 = referencePrevious.pixels[base + c], r1 = reference.pixels[base + c];
      // NaN compares false, so a non-finite reference pixel never counts as static.
      isStatic = std::abs(r1 - r0) <= staticTolerance;
    }
    if (!isStatic) continue;
    bool finite = true;
    for (std::size_t c = 0; c < nc; ++c)
      finite = finite && std::isfinite(test.pixels[base + c]) &&
               std::isfinite(testPrevious.pixels[base + c]);
    if (!finite) continue;
    ++staticPixels;
    for (std::size_t c = 0; c < nc; ++c) {
      const double d =
          std::abs(double(test.pixels[base + c]) - double(testPrevious.pixels[base + c]));
      sumAbsChange += d;
      maxAbsChange = std::max(maxAbsChange, d);
      ++samples;
    }
  }
}

DifferenceStats compareImages(const FloatImage& test, const FloatImage& reference,
                              const std::string& testWhere) {
  requireSameShape(test, reference, testWhere);
  DifferenceStats s;
  s.add(test.pixels.data(), reference.pixels.data(), test.pixels.size());
  return s;
}

SequenceDifference compareSequence(
    const std::vector<int>& frames,
    const std::function<std::pair<FloatImage, FloatImage>(int frame)>& load,
    double staticTolerance) {
  SequenceDifference result;
  FloatImage previousTest, previousReference;
  int previousFrame = 0;
  bool havePrevious = false;
  for (int frame : frames) {
    auto [test, reference] = load(frame);
    FrameDifference fd;
    fd.frame = frame;
    fd.stats = compareImages(test, reference, "frame " + std::to_string(frame));
    result.total.merge(fd.stats);
    result.frames.push_back(fd);
    if (havePrevious && frame == previousFrame + 1)
      result.flicker.addPair(previousTest, test, previousReference, reference, staticTolerance);
    previousTest = std::move(test);
    previousReference = std::move(reference);
    previousFrame = frame;
    havePrevious = true;
  }
  return result;
}

}  // namespace rad
