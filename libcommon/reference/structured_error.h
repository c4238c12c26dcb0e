// The structured error of docs/design.md §10.4: the error that shows as facets, seams and
// blotches, apart from a reference's per-pixel noise and from geometric edges.
//
// Per pixel, e = Y(test) - Y(reference), Y the luminance (luminanceWeights); with a second
// reference, reference = (ref + ref2) / 2. The error is smoothed over a 7 x 7 box by a
// normalised average: s(p) = the mean of e over the box's pixels that are measurable, i.e.
// finite in every image, not an emitter, not background and not an edge pixel (EdgePixels), so
// an edge's error never leaks into the surface beside it and the box shrinks at the image's
// border. The figure is the 95th percentile (nearest rank: the ceil(0.95 n)-th smallest) of
// |s(p)| / mean(Y(reference)) over the measurable pixels at least 3 pixels from every edge pixel
// (EdgePixels::clearOfEdges(3)): the box of such a pixel lies on its own surface. The mean is
// over the non-emitter pixels, as the figure's (§10.1).
//
// Why a box of 7: it divides independent per-pixel noise by 7, while a facet or blotch a few
// pixels wide keeps most of its amplitude. Why the floor with a second reference: a perfect
// test would read |box(truth - (ref + ref2)/2)|, whose noise is that of (ref - ref2) / 2 when the
// references' noise is independent and of equal variance; so the floor is the same figure of
// e = Y(ref) - Y(ref2) halved, and a test within a point of it shows nothing the references do
// not.
#pragma once

#include <cstdint>
#include <vector>

#include "libcommon/core/float_image.h"
#include "libcommon/reference/edge_pixels.h"

namespace rad {

constexpr int kStructuredBox = 7;            // pixels, the side of the smoothing box
constexpr int kStructuredEdgeClearance = 3;  // pixels from every edge pixel
constexpr double kStructuredPercentile = 0.95;

struct StructuredError {
  long long pixels = 0;        // pixels the percentile is over
  double meanReference = 0.0;  // mean luminance of the reference over the non-emitter pixels
  double p95 = 0.0;            // the figure; NaN when no pixel qualifies
  bool hasFloor = false;       // a second reference was given
  double floorP95 = 0.0;       // the references' own floor
};

// `emitter` is per pixel (1: emitter), as findEmitterPixels decides; `reference2` may be null.
// All images of one size, test and references of the same channels (the caller checks, as
// measureError does). With `smoothed`, writes s(p) / mean(Y(reference)) (one channel "Y") at the
// pixels the percentile is over, 0 elsewhere: the smoothed difference image to look at.
StructuredError measureStructuredError(const FloatImage& test, const FloatImage& reference,
                                       const FloatImage* reference2,
                                       const std::vector<uint8_t>& emitter, const EdgePixels& edges,
                                       FloatImage* smoothed = nullptr);

// The nearest-rank percentile of `values` (reordered): the ceil(q n)-th smallest; 0 when empty.
double nearestRankPercentile(std::vector<double>& values, double q);

}  // namespace rad
