// The pixel filters against Blender Cycles' definitions (intern/cycles/scene/film.cpp), their
// normalisation and variance, the importance sampler's distribution, and the sample grid
// (libcommon/scene/pixel_filter.h, sample_grid.h).
#include "libcommon/scene/pixel_filter.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "libcommon/scene/sample_grid.h"

namespace rad {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Cycles' film.cpp, as written there (in double): filter_func_gaussian and
// filter_func_blackman_harris of offset v and table width W; filter_table passes W = 3 w for the
// gaussian and W = 2 w for Blackman-Harris, and tabulates [-W/2, W/2].
double cyclesGaussian(double v, double width) {
  v *= 6.0 / width;
  return std::exp(-2.0 * v * v);
}
double cyclesBlackmanHarris(double v, double width) {
  v = 2.0 * kPi * (v / width + 0.5);
  return 0.35875 - 0.48829 * std::cos(v) + 0.14128 * std::cos(2.0 * v) -
         0.01168 * std::cos(3.0 * v);
}

// \int f over its support (midpoint rule, fine).
double integral(const PixelFilter& f) {
  const int n = 200000;
  const double r = f.radius(), h = 2.0 * r / n;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) sum += f.weight(-r + (i + 0.5) * h) * h;
  return sum;
}

TEST(PixelFilter, WeightsAreCyclesFilterFunctionsOverCyclesTableWidths) {
  for (double w : {0.5, 1.0, 1.5, 2.5}) {
    const PixelFilter box{PixelFilterType::kBox, w};
    const PixelFilter gauss{PixelFilterType::kGaussian, w};
    const PixelFilter bh{PixelFilterType::kBlackmanHarris, w};
    EXPECT_DOUBLE_EQ(box.radius(), w / 2);
    EXPECT_DOUBLE_EQ(gauss.radius(), 3.0 * w / 2);
    EXPECT_DOUBLE_EQ(bh.radius(), w);
    for (double t = -1.0; t <= 1.0; t += 0.05) {
      EXPECT_EQ(box.weight(t * box.radius()), 1.0) << w << " " << t;
      EXPECT_NEAR(gauss.weight(t * gauss.radius()), cyclesGaussian(t * gauss.radius(), 3.0 * w),
                  1e-15);
      EXPECT_NEAR(bh.weight(t * bh.radius()), cyclesBlackmanHarris(t * bh.radius(), 2.0 * w),
                  1e-15);
    }
    // Nothing outside the support Cycles tabulates.
    for (const PixelFilter& f : {box, gauss, bh}) {
      EXPECT_EQ(f.weight(f.radius() * 1.0001), 0.0);
      EXPECT_EQ(f.weight(-f.radius() * 1.0001), 0.0);
    }
    // The normalisations, in closed form: box w; Blackman-Harris a0 x 2w (its cosines integrate
    // to 0 over whole periods); the gaussian exp(-8 v^2 / w^2) over +-1.5 w:
    // w sqrt(pi / 8) erf(1.5 sqrt 8).
    EXPECT_NEAR(integral(box), w, 1e-9);
    EXPECT_NEAR(integral(bh), 0.35875 * 2.0 * w, 1e-9);
    EXPECT_NEAR(integral(gauss), w * std::sqrt(kPi / 8.0) * std::erf(1.5 * std::sqrt(8.0)), 1e-9);
  }
  // Blender's default: peak 1 at the centre, ~0 (6e-5) at the support's ends.
  const PixelFilter blender;
  EXPECT_EQ(blender.type, PixelFilterType::kBlackmanHarris);
  EXPECT_EQ(blender.width, 1.5);
  EXPECT_NEAR(blender.weight(0.0), 1.0, 1e-12);
  EXPECT_NEAR(blender.weight(1.5), 6e-5, 1e-5);
}

TEST(PixelFilter, VarianceIsTheFiltersSecondMoment) {
  // Box: w^2 / 12. Gaussian: (w / 4)^2, a hair less for the truncation at 3 sd.
  EXPECT_NEAR((PixelFilter{PixelFilterType::kBox, 2.0}.variance()), 4.0 / 12.0, 1e-8);
  EXPECT_NEAR((PixelFilter{PixelFilterType::kGaussian, 2.0}.variance()), 0.25, 0.25 * 0.02);
  EXPECT_LT((PixelFilter{PixelFilterType::kGaussian, 2.0}.variance()), 0.25);
  // Blackman-Harris over [-w, w]: the numerical second moment.
  const PixelFilter bh;
  double s0 = 0.0, s2 = 0.0;
  for (int i = 0; i < 100000; ++i) {
    const double v = -1.5 + (i + 0.5) * 3.0 / 100000;
    s0 += bh.weight(v);
    s2 += v * v * bh.weight(v);
  }
  EXPECT_NEAR(bh.variance(), s2 / s0, 1e-7);
  EXPECT_EQ(PixelFilter::pixelCentre().variance(), 0.0);
}

TEST(PixelFilter, SamplerDrawsOffsetsFromTheFilter) {
  for (const PixelFilter& f :
       {PixelFilter{PixelFilterType::kBox, 1.0}, PixelFilter{PixelFilterType::kGaussian, 1.5},
        PixelFilter{PixelFilterType::kBlackmanHarris, 1.5},
        PixelFilter{PixelFilterType::kBlackmanHarris, 3.0}}) {
    const PixelFilterSampler sampler(f);
    // Stratified u: the offsets' distribution at 21 points against the filter's own CDF.
    const int n = 1 << 18;
    std::vector<double> offsets(n);
    for (int i = 0; i < n; ++i) offsets[size_t(i)] = sampler.offset((i + 0.5) / n);
    const double total = integral(f);
    for (int k = 0; k <= 20; ++k) {
      const double x = -f.radius() + 2.0 * f.radius() * k / 20.0;
      double cdf = 0.0;
      const int m = 20000;
      for (int i = 0; i < m; ++i) {
        const double v = -f.radius() + (x + f.radius()) * (i + 0.5) / m;
        cdf += f.weight(v) * (x + f.radius()) / m;
      }
      cdf /= total;
      double below = 0.0;
      for (double o : offsets) below += o <= x ? 1.0 : 0.0;
      EXPECT_NEAR(below / n, cdf, 2e-4) << f.toString() << " at " << x;
    }
    // Symmetric, inside the support, and the mean of v^2 is the variance.
    double mean = 0.0, second = 0.0;
    for (double o : offsets) {
      EXPECT_LE(std::abs(o), f.radius() + 1e-12);
      mean += o / n;
      second += o * o / n;
    }
    EXPECT_NEAR(mean, 0.0, 1e-9);
    EXPECT_NEAR(second, f.variance(), 2e-4 * f.radius() * f.radius()) << f.toString();
  }
  EXPECT_EQ(PixelFilterSampler(PixelFilter::pixelCentre()).offset(0.3), 0.0);
}

TEST(SampleGrid, OddGridHoldsThePixelCentresExactlyAndItsMarginTheSupport) {
  const ImageSize image{37, 23};
  const PixelSampling sampling{PixelFilter{}, 3};
  const SampleGrid g = sampling.grid(image);
  EXPECT_EQ(g.perAxis, 3);
  EXPECT_EQ(g.margin, 1);  // blackman-harris 1.5: ceil(1.5 - 0.5)
  EXPECT_EQ(g.size().width, 3 * (37 + 2));
  for (int col = -1; col <= 37; ++col) {
    const glm::dvec2 p = g.position(g.centre(col), g.centre(col));
    EXPECT_EQ(p.x, col + 0.5);  // exactly
  }
  // The pixel centres' grid is the identity.
  const SampleGrid centres = PixelSampling::pixelCentres().grid(image);
  EXPECT_TRUE(centres.isPixelCentres());
  EXPECT_EQ(centres.position(4, 7), glm::dvec2(4.5, 7.5));
  // The margin holds every sample of a border pixel's support (and its neighbours' centres).
  for (const PixelFilter& f :
       {PixelFilter{PixelFilterType::kBox, 1.0}, PixelFilter{PixelFilterType::kGaussian, 1.5},
        PixelFilter{PixelFilterType::kBlackmanHarris, 2.7}}) {
    const SampleGrid h = PixelSampling{f, 5}.grid(image);
    EXPECT_LE(h.position(0, 0).x, 0.5 - std::max(1.0, f.radius()) + 0.1) << f.toString();
  }
  // Coverage: a grid covers its odd sub-grids with margins no wider.
  EXPECT_TRUE(PixelSampling::covers(g, centres));
  EXPECT_TRUE(PixelSampling::covers(PixelSampling{PixelFilter{}, 9}.grid(image), g));
  EXPECT_FALSE(PixelSampling::covers(PixelSampling{PixelFilter{}, 5}.grid(image), g));
  EXPECT_FALSE(PixelSampling::covers(
      g, PixelSampling{PixelFilter{PixelFilterType::kGaussian, 1.5}, 3}.grid(image)));
}

}  // namespace
}  // namespace rad
