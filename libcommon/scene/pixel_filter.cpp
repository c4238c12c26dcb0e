// Pixel filters as Blender Cycles defines them (intern/cycles/scene/film.cpp). Contracts in
// pixel_filter.h.
#include "libcommon/scene/pixel_filter.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "libcommon/core/error.h"

namespace rad {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Resolution of the tabulated half inverse CDF and of the integration it is built from: well
// below a thousandth of a pixel at any width the options allow.
constexpr int kInverseTableSize = 4096;
constexpr int kIntegrationSteps = 1 << 16;

// Cycles' filter_func_* of offset v in a table of width W (film.cpp's filter_table widens the
// gaussian's to 3 w and the Blackman-Harris' to 2 w).
double cyclesGaussian(double v, double tableWidth) {
  v *= 6.0 / tableWidth;
  return std::exp(-2.0 * v * v);
}
double cyclesBlackmanHarris(double v, double tableWidth) {
  const double x = 2.0 * kPi * (v / tableWidth + 0.5);
  return 0.35875 - 0.48829 * std::cos(x) + 0.14128 * std::cos(2.0 * x) -
         0.01168 * std::cos(3.0 * x);
}

}  // namespace

const EnumNames<PixelFilterType>& pixelFilterNames() {
  static const EnumNames<PixelFilterType> names(
      {{PixelFilterType::kNone, "none"},
       {PixelFilterType::kBox, "box"},
       {PixelFilterType::kGaussian, "gaussian"},
       {PixelFilterType::kBlackmanHarris, "blackman-harris"}});
  return names;
}

double PixelFilter::radius() const {
  switch (type) {
    case PixelFilterType::kNone:
      return 0.0;
    case PixelFilterType::kBox:
      return 0.5 * width;
    case PixelFilterType::kGaussian:
      return 1.5 * width;
    case PixelFilterType::kBlackmanHarris:
      return width;
  }
  return 0.0;
}

double PixelFilter::weight(double v) const {
  if (!(std::abs(v) <= radius())) return 0.0;
  switch (type) {
    case PixelFilterType::kNone:
      return v == 0.0 ? 1.0 : 0.0;
    case PixelFilterType::kBox:
      return 1.0;
    case PixelFilterType::kGaussian:
      return cyclesGaussian(v, 3.0 * width);
    case PixelFilterType::kBlackmanHarris:
      return cyclesBlackmanHarris(v, 2.0 * width);
  }
  return 0.0;
}

double PixelFilter::variance() const {
  if (isNone()) return 0.0;
  const double r = radius(), h = r / kIntegrationSteps;
  double sum = 0.0, moment = 0.0;
  for (int i = 0; i < kIntegrationSteps; ++i) {  // midpoint rule over [0, r]; f is even
    const double v = (i + 0.5) * h, f = weight(v);
    sum += f;
    moment += v * v * f;
  }
  return moment / sum;
}

std::string PixelFilter::toString() const {
  std::ostringstream out;
  out << pixelFilterNames().name(type);
  if (!isNone()) out << " " << width;
  return out.str();
}

void PixelFilter::validate() const {
  if (!(std::isfinite(width) && width >= 0.01 && width <= 16.0)) {
    std::ostringstream out;
    out << "--filter-width " << width << ": expected a width in [0.01, 16] pixels";
    throw Error(ExitCode::kUsage, "", out.str());
  }
}

PixelFilterSampler::PixelFilterSampler(const PixelFilter& filter) : filter_(filter) {
  if (filter.isNone() || filter.type == PixelFilterType::kBox) return;
  // Cumulative distribution of f over [0, r] (trapezoids), normalised, then inverted at
  // kInverseTableSize evenly spaced probabilities.
  const double r = filter.radius(), h = r / kIntegrationSteps;
  std::vector<double> cdf(kIntegrationSteps + 1, 0.0);
  double previous = filter.weight(0.0);
  for (int i = 1; i <= kIntegrationSteps; ++i) {
    const double f = filter.weight(i * h);
    cdf[size_t(i)] = cdf[size_t(i - 1)] + 0.5 * (previous + f) * h;
    previous = f;
  }
  const double total = cdf.back();
  inverse_.resize(kInverseTableSize);
  size_t k = 0;
  for (int i = 0; i < kInverseTableSize; ++i) {
    const double q = total * double(i) / (kInverseTableSize - 1);
    while (k + 1 < cdf.size() - 1 && cdf[k + 1] < q) ++k;
    const double span = cdf[k + 1] - cdf[k];
    const double t = span > 0.0 ? std::clamp((q - cdf[k]) / span, 0.0, 1.0) : 0.0;
    inverse_[size_t(i)] = (double(k) + t) * h;
  }
}

double PixelFilterSampler::offset(double u) const {
  if (filter_.isNone()) return 0.0;
  if (filter_.type == PixelFilterType::kBox) return (u - 0.5) * filter_.width;
  // The half [0, r] from |2u - 1|, mirrored: the filter is even.
  const double q = std::clamp(std::abs(2.0 * u - 1.0), 0.0, 1.0) * (kInverseTableSize - 1);
  const size_t i = std::min(size_t(q), size_t(kInverseTableSize - 2));
  const double t = q - double(i);
  const double v = (1.0 - t) * inverse_[i] + t * inverse_[i + 1];
  return u < 0.5 ? -v : v;
}

}  // namespace rad
