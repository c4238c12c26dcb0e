// The pixel filter: how the radiance around a pixel centre is weighted into the pixel's value
// (docs/design.md §6.4, §6.6). One definition for rad-compose, which filters a regular grid of
// sub-pixel samples with it (sample_grid.h), and rad-reference, which importance-samples it, so
// that a frame and its reference are the same functional of the scene's radiance.
//
// The filters are Blender Cycles' (intern/cycles/scene/film.cpp: filter_func_box,
// filter_func_gaussian, filter_func_blackman_harris and filter_table), so a frame is comparable
// with what a Blender user sees at the same settings. Cycles' filter is separable, f(dx) f(dy),
// with dx, dy the offsets from the pixel centre in pixels; for a filter width w:
//   box:             f(v) = 1 on [-w/2, w/2];
//   gaussian:        Cycles evaluates exp(-2 (6 v / W)^2) over a table of width W = 3 w, so
//                    f(v) = exp(-8 v^2 / w^2) (standard deviation w / 4) on [-3w/2, 3w/2];
//   blackman-harris: over a table of width W = 2 w,
//                    f(v) = 0.35875 - 0.48829 cos(x) + 0.14128 cos(2x) - 0.01168 cos(3x),
//                    x = 2 pi (v / W + 1/2), on [-w, w].
// Blender's default is blackman-harris of width 1.5 px. `none` is no filter: the value at the
// pixel centre alone (one sample through the centre), the point sampling rad-compose did before
// it filtered.
//
// Cycles draws each sample's offset from the filter (the inverse of its cumulative
// distribution, tabulated) and weights every sample 1; PixelFilterSampler does the same.
#pragma once

#include <string>
#include <vector>

#include "libcommon/core/parameter_table.h"

namespace rad {

enum class PixelFilterType { kNone, kBox, kGaussian, kBlackmanHarris };

// The names the options take: none, box, gaussian, blackman-harris.
const EnumNames<PixelFilterType>& pixelFilterNames();

struct PixelFilter {
  PixelFilterType type = PixelFilterType::kBlackmanHarris;
  double width = 1.5;  // pixels, > 0 (not used by kNone)

  static PixelFilter pixelCentre() { return {PixelFilterType::kNone, 1.0}; }
  bool isNone() const { return type == PixelFilterType::kNone; }
  // Half-width of the support in pixels: w/2 (box), 3w/2 (gaussian), w (blackman-harris), 0
  // (none).
  double radius() const;
  // f(v) of the header at offset v pixels from the centre; 0 outside [-radius, radius]. Not
  // normalised (f(0) = 1 for every type). kNone: 1 at v = 0, else 0.
  double weight(double v) const;
  // $\int v^2 f(v) dv / \int f(v) dv$ in pixels^2: the blur a filter applies to a smooth
  // field, to second order ($\bar L = L + \frac{\sigma^2}{2} \nabla^2 L$ per axis). 0 for kNone.
  double variance() const;
  // "blackman-harris 1.5", "none".
  std::string toString() const;
  // Throws rad::Error(kUsage, "--filter-width ...") unless width is finite and in [0.01, 16].
  void validate() const;
};

// Offsets drawn from a filter: offset(u) for u uniform in [0, 1) has density f(v) / \int f, so
// the mean of L(centre + offset(u1), offset(u2)) over samples is the filtered pixel value with
// each sample weighted 1. The inverse cumulative distribution is tabulated finely (a symmetric
// table over [0, radius], as Cycles' util_cdf_inverted with make_symmetric) and interpolated
// linearly; box is inverted exactly. kNone: offset 0. Deterministic, thread-safe once built.
class PixelFilterSampler {
 public:
  explicit PixelFilterSampler(const PixelFilter& filter);
  double offset(double u) const;

 private:
  PixelFilter filter_;
  std::vector<double> inverse_;  // |v| at cumulative probability i / (n - 1) of the half
};

}  // namespace rad
