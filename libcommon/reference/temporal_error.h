// Temporal error of a frame sequence (docs/design.md §10.6): how far the test's change from
// frame n to n + 1 is from the reference's, per pixel. Under a moving camera nearly every pixel
// changes, so the flicker of FlickerStats (change where the reference is static) sees almost
// nothing; an aliased edge that crawls instead changes differently from the filtered truth, and
// this figure sees it. With two references of independent noise the references' own change
// noise is removed as in the error figure of §10.1:
//   d_i = (t_{n+1} - t_n) - (r_{i,n+1} - r_{i,n}),
//   e^2 = (mean(d_1^2) + mean(d_2^2)) / 2 - mean((Δr_1 - Δr_2)^2) / 2,
// reported as e / mean(r) over the pixels that are emitters in neither frame, and over edge and
// interior pixels apart (a pixel is an edge pixel of the pair when it is one in either frame).
#pragma once

#include <cstdint>
#include <vector>

#include "libcommon/core/float_image.h"

namespace rad {

// Pooled sums over one set of pixels of every frame pair (channels pooled).
struct TemporalSums {
  long long samples = 0;
  bool twoReferences = false;
  double sumReference = 0.0;     // \sum (r_n + r_{n+1}) / 2 (first reference)
  double sumSquared1 = 0.0;      // \sum d_1^2
  double sumSquared2 = 0.0;      // \sum d_2^2 (two references)
  double sumNoiseSquared = 0.0;  // \sum (Δr_1 - Δr_2)^2 (two references)

  // e / mean(r) with the references' noise removed (two references), else the raw figure; 0
  // when nothing was compared.
  double rmseOverMean() const;
  // The same without the noise removed (against the first reference).
  double rawRmseOverMean() const;
};

// One frame of a pair: its images (reference2 empty without a second reference) and, per
// pixel row-major, whether it is an emitter and whether it is an edge pixel (edge empty: no
// item buffer, every pixel counts as interior).
struct TemporalFrame {
  const FloatImage* test = nullptr;
  const FloatImage* reference = nullptr;
  const FloatImage* reference2 = nullptr;  // null: one reference
  const std::vector<uint8_t>* emitter = nullptr;
  const std::vector<uint8_t>* edge = nullptr;  // null: no geometry
};

struct TemporalError {
  long long framePairs = 0;
  bool haveEdges = false;  // some pair had edge pixels from an item buffer
  TemporalSums all, edge, interior;

  // Adds the pair (previous, current): frames n and n + 1, all images of one shape.
  void addPair(const TemporalFrame& previous, const TemporalFrame& current);
};

}  // namespace rad
