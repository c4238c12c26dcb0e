// Punctual lamps on the light seam (libcommon/scene/punctual_light_emitter.h) and their
// irradiance on a radiosity element (libcommon/radiosity/lamp_irradiance.h): closed forms.
#include "libcommon/scene/punctual_light_emitter.h"

#include <cmath>

#include <gtest/gtest.h>

#include "libcommon/radiosity/lamp_irradiance.h"

namespace rad {
namespace {

constexpr double kPi = 3.14159265358979323846;
const std::array<glm::dvec3, 2> kBounds{glm::dvec3(-1.0), glm::dvec3(1.0)};

PunctualLight lamp(PunctualLightType type, double intensity) {
  PunctualLight l;
  l.type = type;
  l.intensity = glm::dvec3(intensity, 0.5 * intensity, 0.25 * intensity);
  l.innerConeAngle = 0.3;
  l.outerConeAngle = 0.6;
  return l;
}

// A point lamp of I at height h over a plane: E = I cos / d^2, power 4 pi I.
TEST(PunctualLightEmitter, PointLampIsInverseSquareCosine) {
  const PlacedPunctualLight p(lamp(PunctualLightType::kPoint, 10.0), glm::dvec3(0, 2, 0),
                              glm::dvec3(0, -1, 0), kBounds);
  const glm::dvec3 x(1.5, 0, 0), up(0, 1, 0);
  const double d2 = 1.5 * 1.5 + 4.0, cosine = 2.0 / std::sqrt(d2);
  EXPECT_NEAR(p.irradiance(x, up).x, 10.0 * cosine / d2, 1e-12);
  EXPECT_NEAR(p.irradiance(x, up).z, 2.5 * cosine / d2, 1e-12);
  EXPECT_EQ(p.irradiance(x, -up), glm::dvec3(0.0));  // facing away
  EXPECT_NEAR(p.power().x, 4.0 * kPi * 10.0, 1e-9);
  EXPECT_EQ(p.area(), 0.0);
  EXPECT_EQ(p.shadowTarget(x), glm::dvec3(0, 2, 0));
}

// The extension's smooth falloff: 1 inside the inner cone, 0 past the outer, t^2 between.
TEST(PunctualLightEmitter, SpotFalloffFollowsTheExtension) {
  const PlacedPunctualLight p(lamp(PunctualLightType::kSpot, 1.0), glm::dvec3(0.0),
                              glm::dvec3(0, -1, 0), kBounds);
  EXPECT_EQ(p.profile(std::cos(0.2)), 1.0);
  EXPECT_EQ(p.profile(std::cos(0.7)), 0.0);
  const double c = std::cos(0.45), t = (c - std::cos(0.6)) / (std::cos(0.3) - std::cos(0.6));
  EXPECT_NEAR(p.profile(c), t * t, 1e-12);
  // Power: 2 pi I times the profile integrated over the cosine.
  double integral = 1.0 - std::cos(0.3);
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const double a = 0.3 + (i + 0.5) * 0.3 / n;
    integral += p.profile(std::cos(a)) * std::sin(a) * 0.3 / n;
  }
  EXPECT_NEAR(p.power().x, 2.0 * kPi * integral, 1e-5 * p.power().x);
}

// Cycles' spot (a Blender export's): cos x smoothstep over blend x (1 - cos outer).
TEST(PunctualLightEmitter, CyclesSpotProfile) {
  PunctualLight l = lamp(PunctualLightType::kSpot, 1.0);
  l.profile = SpotProfile::kCycles;
  const PlacedPunctualLight p(l, glm::dvec3(0.0), glm::dvec3(0, -1, 0), kBounds);
  const double co = std::cos(0.6), smooth = (1.0 - co) * (1.0 - 0.3 / 0.6);
  EXPECT_NEAR(p.profile(1.0), 1.0, 1e-15);
  EXPECT_NEAR(p.profile(std::cos(0.2)), std::cos(0.2), 1e-15);
  const double c = co + 0.5 * smooth;
  EXPECT_NEAR(p.profile(c), c * 0.5, 1e-12);  // smoothstep(1/2) = 1/2
  EXPECT_EQ(p.profile(std::cos(0.61)), 0.0);
}

// A sun: E cos theta everywhere, parallel shadow rays reaching past the scene.
TEST(PunctualLightEmitter, SunIsParallel) {
  const glm::dvec3 dir = glm::normalize(glm::dvec3(1, -2, 0));
  const PlacedPunctualLight p(lamp(PunctualLightType::kDirectional, 3.0), glm::dvec3(0.0), dir,
                              kBounds);
  EXPECT_NEAR(p.irradiance(glm::dvec3(0.3, -1, 0.2), glm::dvec3(0, 1, 0)).x, 3.0 * 2 / std::sqrt(5),
              1e-12);
  const glm::dvec3 x(0.5, -1, 0), target = p.shadowTarget(x);
  EXPECT_NEAR(glm::length(glm::cross(target - x, dir)), 0.0, 1e-12);
  EXPECT_GE(glm::length(target - x), glm::length(kBounds[1] - kBounds[0]) * (1.0 - 1e-12));
}

// The range window: the extension's clamp(1 - (d / range)^4, 0, 1)^2.
TEST(PunctualLightEmitter, RangeWindow) {
  PunctualLight l = lamp(PunctualLightType::kPoint, 1.0);
  l.range = 2.0;
  const PlacedPunctualLight p(l, glm::dvec3(0, 1, 0), glm::dvec3(0, -1, 0), kBounds);
  const double w = 1.0 - std::pow(1.0 / 2.0, 4);
  EXPECT_NEAR(p.irradiance(glm::dvec3(0.0), glm::dvec3(0, 1, 0)).x, w * w, 1e-12);
  EXPECT_EQ(p.irradiance(glm::dvec3(3, 0, 0), glm::dvec3(0, 1, 0)).x, 0.0);
}

// A square of side 2a at height h under a point: Omega = 4 asin(a^2 / (a^2 + h^2)).
TEST(LampIrradiance, SolidAngleOfASquare) {
  Polygon sq;
  sq.count = 4;
  sq.v = {glm::dvec3(-1, 0, -1), glm::dvec3(-1, 0, 1), glm::dvec3(1, 0, 1), glm::dvec3(1, 0, -1)};
  EXPECT_NEAR(frontSolidAngle(sq, glm::dvec3(0, 0.5, 0)), 4.0 * std::asin(1.0 / 1.25), 1e-12);
  EXPECT_EQ(frontSolidAngle(sq, glm::dvec3(0, -0.5, 0)), 0.0);  // behind
}

// An element's mean E from an unoccluded point lamp is exact (I Omega / A), whatever its
// samples; a sun's is E cos theta.
TEST(LampIrradiance, UnoccludedMeanIsExact) {
  Polygon sq;
  sq.count = 4;
  sq.v = {glm::dvec3(0, 0, 0), glm::dvec3(0, 0, 1), glm::dvec3(2, 0, 1), glm::dvec3(2, 0, 0)};
  const PlacedPunctualLight p(lamp(PunctualLightType::kPoint, 10.0), glm::dvec3(0.3, 0.4, 0.2),
                              glm::dvec3(0, -1, 0), kBounds);
  const LampValue v = lampIrradiance(p, sq, sq.normal(), nullptr, 0);
  // Midpoint rule on a fine grid.
  double sum = 0.0;
  const int n = 2000;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      sum += p.irradiance(glm::dvec3(2.0 * (i + 0.5) / n, 0, (j + 0.5) / n), sq.normal()).x;
  EXPECT_NEAR(v.mean.x, sum / (double(n) * n), 2e-4 * v.mean.x);
  EXPECT_GT(v.spread, 0.0);
  const glm::dvec3 dir = glm::normalize(glm::dvec3(1, -1, 0));
  const PlacedPunctualLight sun(lamp(PunctualLightType::kDirectional, 2.0), glm::dvec3(0.0), dir,
                                kBounds);
  const LampValue s = lampIrradiance(sun, sq, sq.normal(), nullptr, 0);
  EXPECT_NEAR(s.mean.x, 2.0 / std::sqrt(2.0), 1e-12);
  EXPECT_EQ(s.spread, 0.0);
}

}  // namespace
}  // namespace rad
