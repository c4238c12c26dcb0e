// docs/design.md §10.4: the smoothed error away from edges and its references' floor.
#include "libcommon/reference/structured_error.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rad {

double nearestRankPercentile(std::vector<double>& values, double q) {
  if (values.empty()) return 0.0;
  const double rank = std::ceil(q * double(values.size()));
  const size_t k = size_t(std::clamp(rank, 1.0, double(values.size()))) - 1;
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(k), values.end());
  return values[k];
}

namespace {

// Per-pixel luminance error images, and which pixels the box averages over.
struct LuminanceErrors {
  std::vector<double> test, floor;  // floor: empty without a second reference
  std::vector<uint8_t> measurable;
  double meanReference = 0.0;
};

LuminanceErrors luminanceErrors(const FloatImage& test, const FloatImage& reference,
                                const FloatImage* reference2, const std::vector<uint8_t>& emitter,
                                const EdgePixels& edges) {
  const std::vector<double> w = luminanceWeights(reference.channels);
  const size_t nc = size_t(reference.channelCount());
  const size_t n = size_t(reference.width) * size_t(reference.height);
  LuminanceErrors e;
  e.test.assign(n, 0.0);
  if (reference2) e.floor.assign(n, 0.0);
  e.measurable.assign(n, 0);
  double sumReference = 0.0;
  long long surfacePixels = 0;
  for (size_t p = 0; p < n; ++p) {
    double t = 0.0, r1 = 0.0, r2 = 0.0;
    bool finite = true;
    for (size_t c = 0; c < nc; ++c) {
      const float a = test.pixels[p * nc + c], b = reference.pixels[p * nc + c];
      const float b2 = reference2 ? reference2->pixels[p * nc + c] : b;
      finite = finite && std::isfinite(a) && std::isfinite(b) && std::isfinite(b2);
      t += w[c] * double(a);
      r1 += w[c] * double(b);
      r2 += w[c] * double(b2);
    }
    if (!finite || emitter[p]) continue;
    const double r = reference2 ? 0.5 * (r1 + r2) : r1;
    sumReference += r;
    ++surfacePixels;
    e.test[p] = t - r;
    if (reference2) e.floor[p] = 0.5 * (r1 - r2);
    e.measurable[p] = !edges.edge[p] && !edges.background[p];
  }
  e.meanReference = surfacePixels > 0 ? sumReference / double(surfacePixels) : 0.0;
  return e;
}

// The normalised box average of `error` over the measurable pixels around (x, y).
double boxAverage(const std::vector<double>& error, const std::vector<uint8_t>& measurable,
                  int width, int height, int x, int y) {
  constexpr int r = kStructuredBox / 2;
  double sum = 0.0;
  int count = 0;
  for (int v = std::max(y - r, 0); v <= std::min(y + r, height - 1); ++v)
    for (int u = std::max(x - r, 0); u <= std::min(x + r, width - 1); ++u) {
      const size_t q = size_t(v) * size_t(width) + size_t(u);
      if (!measurable[q]) continue;
      sum += error[q];
      ++count;
    }
  return count > 0 ? sum / double(count) : 0.0;
}

}  // namespace

StructuredError measureStructuredError(const FloatImage& test, const FloatImage& reference,
                                       const FloatImage* reference2,
                                       const std::vector<uint8_t>& emitter, const EdgePixels& edges,
                                       FloatImage* smoothed) {
  const int W = reference.width, H = reference.height;
  const LuminanceErrors e = luminanceErrors(test, reference, reference2, emitter, edges);
  const std::vector<uint8_t> clear = edges.clearOfEdges(kStructuredEdgeClearance);
  if (smoothed) *smoothed = FloatImage(W, H, {"Y"});
  StructuredError s;
  s.meanReference = e.meanReference;
  s.hasFloor = reference2 != nullptr;
  std::vector<double> values, floors;
  // Relative to the mean; as PixelSetStats' ratios, +inf for an error over a mean <= 0.
  auto relative = [&](double v) {
    if (v == 0.0) return 0.0;
    return e.meanReference > 0.0 ? v / e.meanReference : std::numeric_limits<double>::infinity();
  };
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const size_t p = size_t(y) * size_t(W) + size_t(x);
      if (!e.measurable[p] || !clear[p]) continue;
      const double v = boxAverage(e.test, e.measurable, W, H, x, y);
      values.push_back(relative(std::abs(v)));
      if (smoothed) smoothed->pixels[p] = float(v >= 0.0 ? relative(v) : -relative(-v));
      if (reference2)
        floors.push_back(relative(std::abs(boxAverage(e.floor, e.measurable, W, H, x, y))));
    }
  s.pixels = (long long)values.size();
  if (values.empty()) {  // no pixel clear of edges: no figure, rather than a figure of 0
    s.p95 = s.floorP95 = std::numeric_limits<double>::quiet_NaN();
    return s;
  }
  s.p95 = nearestRankPercentile(values, kStructuredPercentile);
  s.floorP95 = nearestRankPercentile(floors, kStructuredPercentile);
  return s;
}

}  // namespace rad
