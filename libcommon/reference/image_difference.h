// Image and frame-sequence error figures (DESIGN.md §8): error against a converged path-traced
// reference (RMSE, relative L2, max abs difference, PSNR) and temporal flicker (mean |Δ|
// between consecutive frames where nothing changes). No file I/O: callers load the images
// (formats/exr_image.h).
#pragma once

#include <functional>
#include <limits>
#include <utility>
#include <vector>

#include "libcommon/core/float_image.h"

namespace rad {

// Pooled difference statistics over any number of (test, reference) sample pairs. A pair in
// which either value is not finite is counted in nonFinite and left out of every figure.
struct DifferenceStats {
  long long samples = 0;    // finite pairs compared
  long long nonFinite = 0;  // pairs skipped because a value was NaN or Inf
  double sumSquaredError = 0.0;
  double sumSquaredReference = 0.0;
  double maxAbsDifference = 0.0;
  double referencePeak = -std::numeric_limits<double>::infinity();  // max reference value

  void add(const float* test, const float* reference, std::size_t count);
  void merge(const DifferenceStats& other);

  // sqrt(sum (a-b)^2 / N); 0 when nothing was compared.
  double rmse() const;
  // ||a - b|| / ||b||; 0 if a == b, +inf if b == 0 and a != b.
  double relativeL2() const;
  // 10 log10(peak^2 / MSE) with peak = max reference value; +inf when MSE == 0, NaN when the
  // peak is not positive (no meaningful peak).
  double psnr() const;
};

// Temporal flicker of a test sequence: mean |test(n+1) - test(n)| over the samples of pixels
// whose reference does not change between n and n+1 (every channel |ref(n+1) - ref(n)| <=
// staticTolerance). Zero for a flicker-free renderer.
struct FlickerStats {
  long long staticPixels = 0;  // pixel x frame-pair count that entered the mean
  long long framePairs = 0;    // consecutive frame pairs looked at
  double sumAbsChange = 0.0;   // sum over the samples of those pixels
  long long samples = 0;       // staticPixels x channels
  double maxAbsChange = 0.0;

  // Adds one consecutive pair. All four images must have the same size and channel count.
  void addPair(const FloatImage& testPrevious, const FloatImage& test,
               const FloatImage& referencePrevious, const FloatImage& reference,
               double staticTolerance);
  // Mean |Δ| per sample; 0 when no static pixel was found.
  double mean() const { return samples > 0 ? sumAbsChange / double(samples) : 0.0; }
};

// Throws rad::inputError(testWhere, "size WxH differs from the reference's WxH") when the
// sizes differ, or a similar message when the channel counts differ.
void requireSameShape(const FloatImage& test, const FloatImage& reference,
                      const std::string& testWhere);

// Throws as requireSameShape.
DifferenceStats compareImages(const FloatImage& test, const FloatImage& reference,
                              const std::string& testWhere = "test image");

struct FrameDifference {
  int frame = 0;
  DifferenceStats stats;
};

struct SequenceDifference {
  std::vector<FrameDifference> frames;  // in the order given
  DifferenceStats total;                // pooled over all frames
  FlickerStats flicker;                 // over pairs of consecutive frame numbers
};

// Compares a sequence frame by frame. `load(frame)` returns {test, reference} for one frame
// number (only two frames are held at a time, so memory is flat in sequence length).
// `frames` must be ascending; flicker uses the pairs (n, n+1) that are both listed.
SequenceDifference compareSequence(
    const std::vector<int>& frames,
    const std::function<std::pair<FloatImage, FloatImage>(int frame)>& load,
    double staticTolerance = 0.0);

}  // namespace rad
