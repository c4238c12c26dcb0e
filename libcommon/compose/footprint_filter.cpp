// rad-compose's pixel filter over the sample grid. Contracts and the reasons in
// footprint_filter.h.
#include "libcommon/compose/footprint_filter.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "libcommon/core/error.h"
#include "libcommon/gl/item_buffer.h"

namespace rad {
namespace {

// Grid samples k with |k / s| <= radius (a hair of tolerance for radius s landing on an integer).
int reachOf(double radius, int perAxis) {
  return int(std::floor(radius * perAxis + 1e-9));
}

// $\int_a^b f$ by 16-point Gauss-Legendre on each of 4 parts: the filters are smooth within
// their support (box: constant), so this is exact to rounding for every cell.
double integralOf(const PixelFilter& filter, double a, double b) {
  static const double x[8] = {0.0950125098376374, 0.2816035507792589, 0.4580167776572274,
                              0.6178762444026438, 0.7554044083550030, 0.8656312023878318,
                              0.9445750230732326, 0.9894009349916499};
  static const double w[8] = {0.1894506104550685, 0.1826034150449236, 0.1691565193950025,
                              0.1495959888165767, 0.1246289712555339, 0.0951585116824928,
                              0.0622535239386479, 0.0271524594117541};
  const int parts = 4;
  double sum = 0.0;
  for (int p = 0; p < parts; ++p) {
    const double lo = a + (b - a) * p / parts, hi = a + (b - a) * (p + 1) / parts;
    const double mid = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
    for (int i = 0; i < 8; ++i)
      sum += w[i] * half * (filter.weight(mid - half * x[i]) + filter.weight(mid + half * x[i]));
  }
  return sum;
}

}  // namespace

FootprintFilter::FootprintFilter(const PixelSampling& sampling, ImageSize image, bool everySample)
    : grid_(sampling.grid(image)) {
  const PixelFilter& filter = sampling.filter;
  if (filter.isNone())
    throw Error(ExitCode::kInternal, "compose", "a footprint filter needs a pixel filter");
  const int s = grid_.perAxis;
  reach_ = reachOf(filter.radius(), s);
  // W_k, the filter's integral over cell k, and G_k = f'(k/s) / s (the header's "Edge cells"),
  // both over the sum of the W_k. f' by a central difference (a box's is 0 off its ends).
  taps_.resize(size_t(2 * reach_ + 1));
  slopes_.resize(taps_.size());
  const double h = 0.5 / s, e = 1e-4;
  double sum = 0.0;
  for (int k = -reach_; k <= reach_; ++k) {
    const double x = double(k) / s;
    sum += taps_[size_t(k + reach_)] = integralOf(filter, x - h, x + h);
    slopes_[size_t(k + reach_)] =
        (filter.weight(std::min(x + e, x + h)) - filter.weight(std::max(x - e, x - h))) /
        (std::min(x + e, x + h) - std::max(x - e, x - h)) / s;
  }
  for (double& t : taps_) t /= sum;
  for (double& g : slopes_) g /= sum;
  edgeCellOf_.assign(size_t(grid_.size().pixelCount()), -1);
  for (double tl : taps_)
    for (double tk : taps_) taps2_.push_back(tk * tl);
  const double variance = filter.variance();
  neighbour_ = (everySample || variance > 1.0) ? -1.0 : 0.5 * variance;
  uniformReach_ = reachOf(std::max(filter.radius(), 1.0), s);
  interpolate_ = !everySample;
  for (int k = 0; k < s; ++k) {
    const double d = double(k - (s - 1) / 2) / s;  // the sample's offset from its pixel centre
    lagrange_.push_back(0.5 * d * (d - 1.0));
    lagrange_.push_back(1.0 - d * d);
    lagrange_.push_back(0.5 * d * (d + 1.0));
  }
  // The grid's margin holds every sample either scheme reads (sample_grid.h).
  if (grid_.centre(0) - std::max(reach_, uniformReach_) < 0)
    throw Error(ExitCode::kInternal, "compose", "sample grid margin smaller than the filter");
}

void FootprintFilter::plan(const std::vector<uint32_t>& ids, const std::vector<size_t>& edges,
                           const std::vector<char>& fullItem) {
  const ImageSize g = grid_.size();
  const int w = grid_.image.width, h = grid_.image.height, s = grid_.perAxis;
  if (ids.size() != size_t(g.pixelCount()))
    throw Error(ExitCode::kInternal, "compose", "item buffer is not the sample grid's size");
  if (neighbour_ < 0.0) {
    full_.assign(size_t(w) * h, 1);
  } else {
    // A window without an edge sample has no two neighbouring samples that differ: one item.
    // So the pixels within uniformReach_ of an edge sample, and those whose centre is on an item
    // that needs full sampling, are full; the rest are uniform.
    full_.assign(size_t(w) * h, 0);
    for (size_t e : edges) {
      int c0, c1, r0, r1;
      pixelSpan(int(e % size_t(g.width)), uniformReach_, w, c0, c1);
      pixelSpan(int(e / size_t(g.width)), uniformReach_, h, r0, r1);
      for (int row = r0; row <= r1; ++row)
        std::fill_n(full_.begin() + ptrdiff_t(size_t(row) * w + size_t(std::max(c0, 0))),
                    std::max(0, c1 - c0 + 1), uint8_t(1));
    }
    for (int row = 0; row < h; ++row)
      for (int col = 0; col < w; ++col) {
        const uint32_t id = ids[size_t(grid_.centre(row)) * g.width + size_t(grid_.centre(col))];
        if (id >= fullItem.size() || fullItem[id]) full_[size_t(row) * w + col] = 1;
      }
  }
  needed_.assign(ids.size(), 0);
  // Grid pixels whose 3 x 3 centres show one untextured item (interpolated()).
  const int pw = w + 2 * grid_.margin, ph = h + 2 * grid_.margin;
  smoothCentres_.assign(size_t(pw) * ph, 0);
  if (interpolate_)
    tbb::parallel_for(tbb::blocked_range<int>(1, ph - 1), [&](const tbb::blocked_range<int>& r) {
      for (int py = r.begin(); py < r.end(); ++py)
        for (int px = 1; px + 1 < pw; ++px) {
          const uint32_t id = ids[size_t(grid_.centre(py - grid_.margin)) * g.width +
                                  size_t(grid_.centre(px - grid_.margin))];
          bool one = id != kNoItem && id < fullItem.size() && !fullItem[id];
          for (int dy = -1; one && dy <= 1; ++dy)
            for (int dx = -1; one && dx <= 1; ++dx)
              one = ids[size_t(grid_.centre(py + dy - grid_.margin)) * g.width +
                        size_t(grid_.centre(px + dx - grid_.margin))] == id;
          smoothCentres_[size_t(py) * pw + px] = one;
        }
    });
  // The samples the pixels read: the centres of the pixels and their neighbours (the shortcut's),
  // and every sample of a fully sampled pixel's window (rows in parallel would race on shared
  // samples: marking is cheap next to shading, so it stays sequential).
  const int gw = g.width;
  // Every centre of the grid, when samples may be interpolated from them.
  if (neighbour_ >= 0.0 || interpolate_)
    for (int row = -grid_.margin; row < h + grid_.margin; ++row)
      for (int col = -grid_.margin; col < w + grid_.margin; ++col)
        needed_[size_t(grid_.centre(row)) * gw + size_t(grid_.centre(col))] = 1;
  offCentre_.assign(smoothCentres_.size(), 0);
  for (int row = 0; row < h; ++row)
    for (int col = 0; col < w; ++col) {
      if (!full_[size_t(row) * w + col]) continue;
      const int cx = grid_.centre(col), cy = grid_.centre(row);
      for (int j = cy - reach_; j <= cy + reach_; ++j)
        std::fill_n(needed_.begin() + ptrdiff_t(size_t(j) * gw + size_t(cx - reach_)),
                    2 * reach_ + 1, uint8_t(1));
      // The grid pixels the window touches (it may hold only their centres: marked anyway).
      for (int py = (cy - reach_) / s; py <= (cy + reach_) / s; ++py)
        std::fill_n(offCentre_.begin() + ptrdiff_t(size_t(py) * pw + size_t((cx - reach_) / s)),
                    (cx + reach_) / s - (cx - reach_) / s + 1, uint8_t(1));
    }
}

uint8_t FootprintFilter::filterPixel(const float* sampleRgb, const uint8_t* sampleTag, int col,
                                     int row, float* rgb) const {
  double sum[3] = {0.0, 0.0, 0.0};
  uint8_t tag = 0;
  if (full_[size_t(row) * grid_.image.width + col]) {
    // forEachSampleOf's full window, unrolled: the taps' products from taps2_, row by row.
    const size_t gw = size_t(grid_.size().width), n = size_t(2 * reach_ + 1);
    const size_t first =
        size_t(grid_.centre(row) - reach_) * gw + size_t(grid_.centre(col) - reach_);
    const double* w = taps2_.data();
    const bool edgeCells =
        !edgeCells_.empty() && edgeWindow_[size_t(row) * grid_.image.width + col];
    for (size_t l = 0; l < n; ++l) {
      const size_t p = first + l * gw;
      const float* L = sampleRgb + 3 * p;
      for (size_t k = 0; k < n; ++k, ++w) {
        sum[0] += *w * double(L[3 * k]);
        sum[1] += *w * double(L[3 * k + 1]);
        sum[2] += *w * double(L[3 * k + 2]);
        tag = std::max(tag, sampleTag[p + k]);
      }
      // The edge cells of this row of the window (the header's "Edge cells").
      if (!edgeCells) continue;
      for (size_t k = 0; k < n; ++k) {
        const int32_t e = edgeCellOf_[p + k];
        if (e < 0) continue;
        const EdgeCell& c = edgeCells_[size_t(e)];
        const double wk = taps_[k], wl = taps_[l];
        const double weight =
            (double(c.coverage) - 1.0) * wk * wl +
            double(c.coverage) * (slopes_[k] * wl * double(c.dx) + wk * slopes_[l] * double(c.dy));
        for (int ch = 0; ch < 3; ++ch) sum[ch] += weight * double(c.step[ch]);
      }
    }
  } else {
    // The 3 x 3 centres, unrolled (forEachSampleOf's shortcut).
    const size_t gw = size_t(grid_.size().width), s = size_t(grid_.perAxis);
    const size_t centre = size_t(grid_.centre(row)) * gw + size_t(grid_.centre(col));
    const double w[3] = {neighbour_, 1.0 - 2.0 * neighbour_, neighbour_};
    for (int dy = 0; dy < 3; ++dy)
      for (int dx = 0; dx < 3; ++dx) {
        const size_t p = centre + (size_t(dy) * gw + size_t(dx)) * s - (gw + 1) * s;
        const double weight = w[dx] * w[dy];
        const float* L = sampleRgb + 3 * p;
        sum[0] += weight * double(L[0]);
        sum[1] += weight * double(L[1]);
        sum[2] += weight * double(L[2]);
        tag = std::max(tag, sampleTag[p]);
      }
  }
  for (int c = 0; c < 3; ++c) rgb[c] = float(std::max(sum[c], 0.0));
  return tag;
}

void FootprintFilter::pixelSpan(int i, int reach, int n, int& first, int& last) const {
  // The pixels c with |i - centre(c)| <= reach: s (c + m) + mid in [i - reach, i + reach].
  const int s = grid_.perAxis, mid = (s - 1) / 2, m = grid_.margin;
  const int lo = i - reach - mid, hi = i + reach - mid;
  first = std::max(0, (lo + s - 1 + s * 1024) / s - 1024 - m);  // ceil(lo / s) - m
  last = std::min(n - 1, (hi + s * 1024) / s - 1024 - m);       // floor(hi / s) - m
}

void FootprintFilter::setEdgeCells(std::vector<EdgeCell> cells) {
  for (const EdgeCell& c : edgeCells_) edgeCellOf_[c.sample] = -1;
  edgeCells_ = std::move(cells);
  const int w = grid_.image.width, h = grid_.image.height, gw = grid_.size().width;
  edgeWindow_.assign(size_t(w) * h, 0);
  for (size_t i = 0; i < edgeCells_.size(); ++i) {
    const size_t p = edgeCells_[i].sample;
    if (p >= edgeCellOf_.size() || edgeCellOf_[p] >= 0)
      throw Error(ExitCode::kInternal, "compose", "edge cell outside the grid or given twice");
    edgeCellOf_[p] = int32_t(i);
    int c0, c1, r0, r1;
    pixelSpan(int(p % size_t(gw)), reach_, w, c0, c1);
    pixelSpan(int(p / size_t(gw)), reach_, h, r0, r1);
    for (int row = r0; row <= r1; ++row)
      for (int col = c0; col <= c1; ++col) edgeWindow_[size_t(row) * w + col] = 1;
  }
}

void FootprintFilter::interpolate(int i, int j, const float* sampleRgb, float* rgb) const {
  const int s = grid_.perAxis, px = i / s, py = j / s, gw = grid_.size().width;
  const double* wx = &lagrange_[size_t(3 * (i % s))];
  const double* wy = &lagrange_[size_t(3 * (j % s))];
  double sum[3] = {0.0, 0.0, 0.0};
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const double w = wx[dx + 1] * wy[dy + 1];
      const float* L = sampleRgb + 3 * (size_t((py + dy) * s + (s - 1) / 2) * gw +
                                        size_t((px + dx) * s + (s - 1) / 2));
      for (int c = 0; c < 3; ++c) sum[c] += w * double(L[c]);
    }
  for (int c = 0; c < 3; ++c) rgb[c] = float(std::max(sum[c], 0.0));
}

}  // namespace rad
