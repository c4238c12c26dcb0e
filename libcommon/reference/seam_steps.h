// Seams (docs/design.md §10.5): the luminance step across the boundary of two top-level patches
// that are one smooth surface (coplanar, one material: FrameSurfaces::sameSurface). Radiance is
// continuous there, so a step the reference does not have is the renderer's: per-patch
// solutions, interpolation or texel borders that disagree along a shared edge (issue 56).
//
// A seam pair is two pixels side by side (horizontal or vertical neighbours) that show two
// different top-level patches a < b of one surface, neither an emitter (by the figure's rule or
// the patch's material), an edge pixel (EdgePixels) or non-finite. Its step is Y(pixel on a) -
// Y(pixel on b): the two pixels half a pixel either side of the boundary, where a pixel-centre
// image and a filtered one both see each side. The pairs of one patch pair are one seam, and
// its step is the mean step over its pairs relative to its local mean, the mean over its pairs
// of (Y_a + Y_b) / 2 of the reference:
//   $\mathrm{step} = \sum (Y_a - Y_b) / \sum (Y_a + Y_b) / 2$.
// The test's and the reference's steps (reference = (ref + ref2) / 2 with a second reference)
// share the reference's local mean. The excess is step(test) - step(reference): the reference's
// step is the true one (a gradient across the seam is in both). With a second reference the
// floor of a seam is half the difference of the two references' steps, which has the noise of
// the reference's step.
#pragma once

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "libcommon/core/float_image.h"
#include "libcommon/reference/edge_pixels.h"
#include "libcommon/reference/frame_surfaces.h"

namespace rad {

// Fewest pairs a seam needs to enter the summary: with a reference's per-pixel noise sigma, a
// seam's reference step has noise about sigma / sqrt(pairs), so a short seam is mostly noise.
constexpr long long kSeamMinPairs = 32;

// Sums over one seam's pairs (luminance), so frames merge into exact pooled totals.
struct SeamSums {
  long long pairs = 0;
  double testA = 0.0, testB = 0.0;              // test on each side
  double reference1A = 0.0, reference1B = 0.0;  // first reference
  double reference2A = 0.0, reference2B = 0.0;  // second (= first without one)
  int frame = 0, x = -1, y = -1;                // a pixel on side a, first seen

  void merge(const SeamSums& other);
  double localMean() const;      // \sum (Y_a + Y_b) / (2 pairs), reference
  double testStep() const;       // relative to localMean; 0 when empty, +-inf when mean <= 0
  double referenceStep() const;  // likewise
  double excess() const { return testStep() - referenceStep(); }
  double floor() const;  // half the difference of the two references' steps
};

struct SeamSteps {
  bool twoReferences = false;
  std::map<std::pair<int, int>, SeamSums> seams;  // by top-level patch pair (a < b)
  void merge(const SeamSteps& other);
};

// Over the seams with at least minPairs pairs: mean and largest |step| of the test and of the
// reference, mean and largest |excess|, and the largest floor (two references).
struct SeamSummary {
  long long minPairs = kSeamMinPairs;
  long long seamsFound = 0, seamsMeasured = 0;
  long long pairs = 0;  // over the measured seams
  double meanAbsTestStep = 0.0, maxAbsTestStep = 0.0;
  double meanAbsReferenceStep = 0.0, maxAbsReferenceStep = 0.0;
  double meanAbsExcess = 0.0, maxAbsExcess = 0.0;
  double maxFloor = 0.0;
  std::vector<std::pair<int, int>> byExcess;  // the measured seams, largest |excess| first
};
SeamSummary summariseSeams(const SeamSteps& steps, long long minPairs = kSeamMinPairs);

// One frame's seams. `emitter` per pixel as findEmitterPixels decides; `reference2` may be
// null; images of the surfaces' size (the caller checks).
SeamSteps measureSeams(const FloatImage& test, const FloatImage& reference,
                       const FloatImage* reference2, const std::vector<uint8_t>& emitter,
                       const FrameSurfaces& surfaces, const EdgePixels& edges, int frame = 0);

}  // namespace rad
