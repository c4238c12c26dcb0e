// Image error figures (docs/design.md §8, §10): error against a converged path-traced reference
// and temporal flicker (mean |Δ| between consecutive frames where nothing changes). Sequences:
// sequence_difference.h. No file I/O: callers load the images (formats/exr_image.h).
//
// The figure that judges a renderer is ErrorFigures (docs/design.md §10): RMSE / mean and bias over
// the pixels that are not emitters, with the references' own noise removed when a second
// reference is given. DifferenceStats (RMSE, relative L2, max, PSNR over every sample) is kept
// for what it is good at (two renders of the same method, a stored frame), but its relative L2
// is normalised by the reference's RMS, which a visible light dominates: a frame with a light
// 200 times brighter than the walls reads "1 %" while the walls are 9 % too dark.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
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

// ---- The error figure of docs/design.md §10
// -------------------------------------------------------

// Luminance weights for an image's channels: Rec. 709, $Y = 0.2126 R + 0.7152 G + 0.0722 B$,
// when channels named R, G and B are all present (other channels weigh 0); otherwise every
// channel weighs 1 / channelCount (the mean of the channels, e.g. for `--channels R,B`).
std::vector<double> luminanceWeights(const std::vector<std::string>& channels);

// Which reference pixels are emitters (a visible light), left out of the error figure and
// reported apart. A pixel is an emitter when its reference luminance Y exceeds the threshold.
//
// Default (threshold unset): $t = 10 \cdot \mathrm{median}\{Y_p : Y_p > 0\}$ per frame. Why the
// median and not the mean: the mean is pulled up by the very emitters it is meant to find (a
// light over 10 % of the frame at 200 times the walls lifts the mean to 21 times the walls, and
// "10 x mean" would miss it), while the median does not move for emitters covering less than
// half the lit pixels. Zero pixels (background, no hit) are left out so that a mostly black
// frame does not put the threshold at 0. Why 10: a diffuse wall lit by a light of radiance
// $L_e$ has at most $\rho L_e$ from direct light, and in practice stays within a few times the
// typical wall, while a visible light is far above it. In the stored Cornell frame
// (tests/data/pipeline/cornell-moving-88x60-0004.exr) the median is 0.054, the threshold 0.54,
// every pixel off the light below 0.3 and the light 17: the rule finds exactly its 24 pixels.
// A uniform frame (the furnace) has no emitter by this rule.
struct EmitterRule {
  static constexpr double kMedianFactor = 10.0;
  std::optional<double> threshold;  // absolute luminance (the image's units); unset: default
  // "Y > 10 x median luminance of the lit reference pixels" or "Y > 2.5"
  std::string toString() const;
};

// The threshold the rule gives for one reference frame: +inf when no pixel is lit (no emitter).
double emitterThreshold(const FloatImage& reference, const EmitterRule& rule);

// Which pixels of a frame are emitters, as measureError decides: by `emitterMask` (first
// channel > 0.5) when given, else by the rule applied to the reference, (ref + ref2) / 2 with a
// second reference so that both references' pixels fall on the same side. `reference2` and
// `emitterMask` may be null; shapes as measureError checks them.
struct EmitterPixels {
  std::vector<uint8_t> isEmitter;                              // row-major, 1: emitter
  double threshold = std::numeric_limits<double>::infinity();  // the rule's; NaN with a mask
};
EmitterPixels findEmitterPixels(const FloatImage& reference, const FloatImage* reference2,
                                const EmitterRule& rule, const FloatImage* emitterMask);

// Pooled sums over a set of pixels (channels pooled, every sample counted once) from which the
// figures are formed. With one reference $r = r_1$; with two, $r = (r_1 + r_2) / 2$ is the
// reference of mean and bias. Sums, so frames merge into an exact pooled total (not a mean of
// per-frame ratios).
struct PixelSetStats {
  long long pixels = 0, samples = 0;
  bool twoReferences = false;
  double sumReference = 0.0;       // \sum r
  double sumError = 0.0;           // \sum (t - r)
  double sumSquaredError1 = 0.0;   // \sum (t - r_1)^2
  double sumSquaredError2 = 0.0;   // \sum (t - r_2)^2      (two references)
  double sumSquaredBetween = 0.0;  // \sum (r_1 - r_2)^2    (two references)

  void merge(const PixelSetStats& other);
  double meanReference() const;  // \bar r = \sum r / N; 0 when empty
  // Raw: $\sqrt{(\mathrm{MSE}(t, r_1) + \mathrm{MSE}(t, r_2)) / 2}$ (one reference: its RMSE).
  double rawRmse() const;
  // The references' noise: $\sigma^2 = \mathrm{mean}((r_1 - r_2)^2) / 2$; 0 with one reference.
  double noise() const;
  // $\sqrt{\max(0, \mathrm{raw}^2 - \sigma^2)}$: as $E\,(t - r_i)^2 = d^2 + \sigma^2$ and
  // $E\,(r_1 - r_2)^2 = 2\sigma^2$ for independent reference noise (docs/design.md §10).
  double rmse() const;
  // The figures divided by $\bar r$: 0 when the error is 0 (or nothing was compared); +inf
  // (bias: -inf or +inf) when $\bar r \le 0$ and the error is not 0.
  double rmseOverMean() const;
  double rawRmseOverMean() const;
  double noiseOverMean() const;
  double bias() const;  // $\mathrm{mean}(t - r) / \bar r$
};

// docs/design.md §10 over one frame or a pooled sequence: non-emitter pixels (`surfaces`, the
// figure) and emitter pixels (`emitters`, reported apart). A pixel with a non-finite value in
// any channel of any image is in neither (DifferenceStats counts it in nonFinite).
struct ErrorFigures {
  PixelSetStats surfaces, emitters;
  // Per pixel group (PixelGroups, e.g. the material seen in an item buffer): its non-emitter
  // pixels, so that a bias can be traced to the surfaces that have it. Empty without groups.
  std::vector<PixelSetStats> groups;
  // The same per region (edge_pixels.h: edge, interior, background; docs/design.md §10.3), the
  // figure apart where the image crosses a geometric edge. Empty without regions.
  std::vector<PixelSetStats> regions;
  double emitterThreshold = std::numeric_limits<double>::infinity();  // one frame's; see rule
  void merge(const ErrorFigures& other);
};

// Which group each pixel is in (row-major, -1: none) and how many groups there are.
struct PixelGroups {
  std::vector<int> ofPixel;
  int count = 0;
};

// `reference2` may be null (one reference). `emitterMask` may be null (the rule decides);
// otherwise its first channel > 0.5 marks a pixel as an emitter and the rule is not used
// (emitterThreshold is then NaN): a mask from the scene (an emitter AOV) is the exact answer
// that the luminance rule guesses. All images must have the same size, test and references
// the same channels (throws as requireSameShape, naming testWhere, reference2Where or
// maskWhere). `groups` and `regions` may be null; each fills its vector of ErrorFigures.
ErrorFigures measureError(const FloatImage& test, const FloatImage& reference,
                          const FloatImage* reference2, const EmitterRule& rule,
                          const std::string& testWhere = "test image",
                          const std::string& reference2Where = "second reference",
                          const FloatImage* emitterMask = nullptr,
                          const std::string& maskWhere = "emitter mask",
                          const PixelGroups* groups = nullptr,
                          const PixelGroups* regions = nullptr);

}  // namespace rad
