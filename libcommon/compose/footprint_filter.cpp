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

}  // namespace

FootprintFilter::FootprintFilter(const PixelSampling& sampling, ImageSize image, bool everySample)
    : grid_(sampling.grid(image)) {
  const PixelFilter& filter = sampling.filter;
  if (filter.isNone())
    throw Error(ExitCode::kInternal, "compose", "a footprint filter needs a pixel filter");
  const int s = grid_.perAxis;
  reach_ = reachOf(filter.radius(), s);
  taps_.resize(size_t(2 * reach_ + 1));
  double sum = 0.0;
  for (int k = -reach_; k <= reach_; ++k)
    sum += taps_[size_t(k + reach_)] = filter.weight(double(k) / s);
  for (double& t : taps_) t /= sum;
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
  const int mid = (s - 1) / 2, m = grid_.margin;
  if (ids.size() != size_t(g.pixelCount()))
    throw Error(ExitCode::kInternal, "compose", "item buffer is not the sample grid's size");
  if (neighbour_ < 0.0) {
    full_.assign(size_t(w) * h, 1);
  } else {
    // A window without an edge sample has no two neighbouring samples that differ: one item.
    // So the pixels within uniformReach_ of an edge sample, and those whose centre is on an item
    // that needs full sampling, are full; the rest are uniform.
    full_.assign(size_t(w) * h, 0);
    // The pixels c with |i - centre(c)| <= reach: s (c + m) + mid in [i - reach, i + reach].
    auto span = [&](int i, int n, int& first, int& last) {
      const int lo = i - uniformReach_ - mid, hi = i + uniformReach_ - mid;
      first = std::max(0, (lo + s - 1 + s * 1024) / s - 1024 - m);  // ceil(lo / s) - m
      last = std::min(n - 1, (hi + s * 1024) / s - 1024 - m);       // floor(hi / s) - m
    };
    for (size_t e : edges) {
      int c0, c1, r0, r1;
      span(int(e % size_t(g.width)), w, c0, c1);
      span(int(e / size_t(g.width)), h, r0, r1);
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
    for (size_t l = 0; l < n; ++l) {
      const size_t p = first + l * gw;
      const float* L = sampleRgb + 3 * p;
      for (size_t k = 0; k < n; ++k, ++w) {
        sum[0] += *w * double(L[3 * k]);
        sum[1] += *w * double(L[3 * k + 1]);
        sum[2] += *w * double(L[3 * k + 2]);
        tag = std::max(tag, sampleTag[p + k]);
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
