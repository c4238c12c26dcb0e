// rad-compose's pixel filter over the sample grid (docs/design.md §6.4; pixel_filter.h,
// sample_grid.h): which samples of a frame to shade, and each pixel's value from them.
//
// A pixel's value is the filter over the grid samples within its support, each sample standing
// for its cell (the square of side 1/s px around it) and weighted by the filter's integral over
// that cell,
//   $L_p = \sum_{k,l} W_k W_l L(c_x + k, c_y + l)$, $W_k = \int_{(k-1/2)/s}^{(k+1/2)/s} f /
//   \sum_j \int_{cell j} f$,
// |k|, |l| <= radius s, c the pixel centre's sample; background samples count with L = 0, as a
// black world does in Cycles. That is "full sampling": s^2 shaded samples a pixel.
//
// Edge cells. A sample's value stands for its whole cell, so an edge is placed to 1/s px, and
// the pixels beside an edge of high contrast (a lamp's outline: a hundred times the ceiling) are
// off by up to a sixth of the step (the quadrature's error, not the shading's). Where an edge
// crosses a sample's cell, the composer gives the cell as an EdgeCell: the fraction c of it that
// shows the sample's own surface a, that part's centroid δ, and the step L_a - L_b to the other
// side's radiance. The cell then weighs L_b by its whole weight and the step by the filter's
// integral over a's part, to first order in δ:
//   $\int_{a} f(x) f(y) \approx c (W_k W_l + G_k W_l δ_x + W_k G_l δ_y)$, $G_k = f'(k/s) / s /
//   \sum_j \int_{cell j} f$,
// which places the edge exactly for a straight edge up to the filter's curvature over a cell;
// no sample is added, so rad-intervals' coverage of the grid still holds.
//
// Most pixels see one untextured surface over their whole footprint, where the radiance is a
// smooth field (a texture movie's bilinear irradiance times a constant reflectance). There, to
// second order, the filter only adds $\frac{\sigma^2}{2} \nabla^2 L$ to the centre value, σ² the
// filter's variance per axis (PixelFilter::variance), and so does the 3 x 3 kernel of the pixel
// centres with weights (a, 1 - 2a, a) per axis, a = σ²/2. Such a pixel ("uniform": every grid
// sample within max(radius, 1) px of its centre sees the same top-level patch, untextured, or
// every one the background) takes
// that kernel over its own and its 8 neighbours' centres: one shaded sample a pixel instead of
// s^2 (a footprint all background is 0 either way). The "item ids" plan() reads may be surfaces
// rather than patches: rad-compose gives the smooth surfaces (smooth_surfaces.h), so coplanar
// patches of one material count as one. Every other pixel (edges, textured
// materials) takes full sampling. The
// shortcut is off when σ² > 1 (the kernel would need a negative weight) or when asked
// (everySample).
//
// In a fully sampled pixel's window, a sample whose own pixel and its 8 neighbours have their
// centres on the sample's untextured surface lies at least a pixel inside that surface: it is
// interpolated from those 9 centres, biquadratically (Lagrange weights per axis at its offset
// d from its pixel centre: d(d-1)/2, 1-d^2, d(d+1)/2), exact for a quadratic field like the
// shortcut, instead of shaded. The samples near an edge are shaded: their own pixel's
// neighbourhood crosses it. everySample shades every sample. Which pixels are uniform and
// which samples are interpolated depends on the item buffer alone: deterministic.
#pragma once

#include <cstdint>
#include <vector>

#include "libcommon/scene/sample_grid.h"

namespace rad {

// One sample's cell crossed by an edge (the header's "Edge cells").
struct EdgeCell {
  size_t sample = 0;           // grid index
  float step[3] = {0, 0, 0};   // L_a - L_b: the sample's radiance minus the other side's
  float coverage = 1.0f;       // c: the fraction of the cell on the sample's side, [0, 1]
  float dx = 0.0f, dy = 0.0f;  // δ: that part's centroid from the sample, pixels
};

class FootprintFilter {
 public:
  // `sampling` must not be filter none (the pixel centres need no filter).
  FootprintFilter(const PixelSampling& sampling, ImageSize image, bool everySample);

  const SampleGrid& grid() const { return grid_; }

  // Decides each pixel's scheme from the grid's item ids (kNoItem = background; grid().size()
  // of them), `edges` (every sample whose id differs from a 4-neighbour's, before any change of
  // ids; a changed sample must be one of them) and `fullItem` (per id: 1 where full sampling is
  // required, e.g. a textured material; index 0, the background, 0), and marks the samples to
  // shade (needed()).
  void plan(const std::vector<uint32_t>& ids, const std::vector<size_t>& edges,
            const std::vector<char>& fullItem);
  // Per grid sample: 1 where plan() needs it shaded.
  const std::vector<uint8_t>& needed() const { return needed_; }
  // Per pixel: 1 where the pixel took full sampling.
  const std::vector<uint8_t>& fullPixels() const { return full_; }
  // The edge cells the fully sampled pixels weigh by their coverage (each sample at most once;
  // replaces the previous frame's). Without them every cell holds its sample's value.
  void setEdgeCells(std::vector<EdgeCell> cells);

  // Whether the samples of grid pixel (px, py) (0 <= px < W + 2m: the pixel px - m of the image)
  // that show the item its centre shows are interpolated from the centres around it, rather
  // than shaded (plan() decided; the centres must be shaded first).
  bool smooth(int px, int py) const {
    return smoothCentres_[size_t(py) * (grid_.image.width + 2 * grid_.margin) + px] != 0;
  }
  // Whether grid pixel (px, py) has a needed sample off its centre (a fully sampled pixel's
  // window holds it); else its centre is the only sample of it that may be needed.
  bool offCentreNeeded(int px, int py) const {
    return offCentre_[size_t(py) * (grid_.image.width + 2 * grid_.margin) + px] != 0;
  }
  // The value of grid sample (i, j) of a smooth pixel, from the shaded centres' radiance, into
  // rgb[0..2].
  void interpolate(int i, int j, const float* sampleRgb, float* rgb) const;

  // Pixel (col, row)'s value from the shaded samples' radiance (3 floats a grid sample; only
  // needed() ones are read) into rgb[0..2], in double, rounded once. Returns the largest of
  // `sampleTag` (one a grid sample) over the samples read.
  uint8_t filterPixel(const float* sampleRgb, const uint8_t* sampleTag, int col, int row,
                      float* rgb) const;
  // The grid samples pixel (col, row)'s value reads, as (index, weight > 0) pairs: the cells'
  // weights, without the edge cells' terms (setEdgeCells).
  template <class F>
  void forEachSampleOf(int col, int row, F f) const;

 private:
  SampleGrid grid_;
  std::vector<double> taps_;    // full sampling: W_k for k = -K..K (sum 1)
  std::vector<double> slopes_;  // G_k (the header's "Edge cells")
  std::vector<double> taps2_;   // taps_[k] taps_[l], row l major
  std::vector<EdgeCell> edgeCells_;
  std::vector<int32_t> edgeCellOf_;  // per grid sample: index in edgeCells_, or -1
  std::vector<uint8_t> edgeWindow_;  // per pixel: its full window holds an edge cell
  // The image pixels c (clamped to [0, n)) whose centre's grid index is within `reach` of grid
  // index i, along one axis.
  void pixelSpan(int i, int reach, int n, int& first, int& last) const;
  int reach_ = 0;                 // K
  double neighbour_ = 0.0;        // a of the 3 x 3 kernel; < 0: no shortcut
  int uniformReach_ = 0;          // grid samples max(radius, 1) px from a centre
  bool interpolate_ = true;       // !everySample
  std::vector<double> lagrange_;  // per sub-pixel offset k: 3 weights (centres -1, 0, +1)
  std::vector<uint8_t> needed_, full_;
  std::vector<uint8_t> smoothCentres_;
  std::vector<uint8_t> offCentre_;  // per grid pixel: offCentreNeeded()
};

template <class F>
void FootprintFilter::forEachSampleOf(int col, int row, F f) const {
  const int gw = grid_.size().width;
  if (full_[size_t(row) * grid_.image.width + col]) {
    const int cx = grid_.centre(col), cy = grid_.centre(row);
    for (int l = -reach_; l <= reach_; ++l)
      for (int k = -reach_; k <= reach_; ++k)
        f(size_t(cy + l) * gw + size_t(cx + k),
          taps_[size_t(k + reach_)] * taps_[size_t(l + reach_)]);
    return;
  }
  const double w[3] = {neighbour_, 1.0 - 2.0 * neighbour_, neighbour_};
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const double weight = w[dx + 1] * w[dy + 1];
      if (weight > 0.0)
        f(size_t(grid_.centre(row + dy)) * gw + size_t(grid_.centre(col + dx)), weight);
    }
}

}  // namespace rad
