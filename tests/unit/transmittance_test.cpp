// Transmittance by projective shadows into sample masks (libcommon/movies/transmittance.h) and
// by ray-cast segment tests (ray_cast_masks.h): the projection, the sample pattern, occlusion
// against hand-computed visible fractions and the exact OR merge for both, their agreement, and
// the adaptive choice between them.
#include "libcommon/movies/transmittance.h"

#include <algorithm>
#include <bitset>
#include <cmath>

#include <gtest/gtest.h>

#include "libcommon/core/error.h"
#include "libcommon/movies/movies_options.h"
#include "libcommon/movies/ray_cast_masks.h"
#include "libcommon/radiosity/form_factor.h"
#include "libcommon/scene/patch_hierarchy.h"

namespace rad {
namespace {

Polygon quad(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d) {
  Polygon p;
  p.count = 4;
  p.v = {a, b, c, d};
  return p;
}

// Receiver [-1,1]^2 at z = 0 facing +z; u along +x, v along +y.
Polygon floorReceiver() {
  return quad({-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0});
}
// Square light [-.5,.5]^2 at z = 2 facing -z.
Polygon ceilingLight() {
  return quad({-0.5, -0.5, 2}, {-0.5, 0.5, 2}, {0.5, 0.5, 2}, {0.5, -0.5, 2});
}

std::vector<glm::dvec3> lightSamples(int n, uint32_t seed = 7) {
  std::vector<glm::dvec3> s;
  for (glm::dvec2 a : multiJitteredPoints(n, seed))
    s.push_back(samplePointOnPolygon(ceilingLight(), a));
  return s;
}

std::vector<BlockerTriangle> quadTriangles(const Polygon& p) {
  return {{p.v[0], p.v[1], p.v[2]}, {p.v[0], p.v[2], p.v[3]}};
}

glm::dvec2 uvOf(const glm::dmat4& m, const glm::dvec3& y) {
  glm::dvec4 c = m * glm::dvec4(y, 1.0);
  return {0.5 * (c.x / c.w + 1.0), 0.5 * (c.y / c.w + 1.0)};
}

TEST(Transmittance, ProjectionMapsThePlaneOntoTheTextureSquare) {
  // A non-parallelogram quad, a triangle and a parallelogram: corners land on their (u,v).
  Polygon trapezoid = quad({0, 0, 0}, {3, 0, 0}, {2, 1, 0}, {0.5, 1.5, 0});
  Polygon tri;
  tri.count = 3;
  tri.v = {glm::dvec3(0, 0, 1), glm::dvec3(2, 0, 1), glm::dvec3(0, 3, 1)};
  const glm::dvec3 eye(0.3, 0.4, 5.0);
  const glm::dvec2 quadUv[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const glm::dvec2 triUv[3] = {{0, 0}, {1, 0}, {0, 1}};
  glm::dmat4 m = projectiveShadowMatrix(trapezoid, eye);
  for (int k = 0; k < 4; ++k) {
    glm::dvec2 uv = uvOf(m, trapezoid.v[k]);
    EXPECT_NEAR(uv.x, quadUv[k].x, 1e-12);
    EXPECT_NEAR(uv.y, quadUv[k].y, 1e-12);
  }
  m = projectiveShadowMatrix(tri, eye);
  for (int k = 0; k < 3; ++k) {
    glm::dvec2 uv = uvOf(m, tri.v[k]);
    EXPECT_NEAR(uv.x, triUv[k].x, 1e-12);
    EXPECT_NEAR(uv.y, triUv[k].y, 1e-12);
  }
  // Triangles and parallelograms: the homography is the texture map everywhere, and a point
  // above the plane maps to where the ray from the eye through it meets the plane.
  Polygon para = quad({0, 0, 0}, {2, 0.5, 0}, {2.5, 2, 0}, {0.5, 1.5, 0});
  m = projectiveShadowMatrix(para, eye);
  for (glm::dvec2 uv : {glm::dvec2(0.25, 0.7), glm::dvec2(0.9, 0.1), glm::dvec2(1.3, -0.2)}) {
    glm::dvec3 x = polygonPointAt(para, uv);
    glm::dvec3 y = eye + 0.6 * (x - eye);  // 40 % of the way down from the eye
    glm::dvec2 got = uvOf(m, y);
    EXPECT_NEAR(got.x, uv.x, 1e-12);
    EXPECT_NEAR(got.y, uv.y, 1e-12);
    EXPECT_NEAR(receiverPlaneUv(para, x).x, uv.x, 1e-12);
  }
}

TEST(Transmittance, SampleCountFollowsTheFormFactorAndIsASquare) {
  EXPECT_EQ(transmittanceSampleCount(0.0, 256, 4, 64), 4);
  EXPECT_EQ(transmittanceSampleCount(1.0, 256, 4, 64), 64);
  EXPECT_EQ(transmittanceSampleCount(0.1, 256, 4, 64), 36);  // 25.6 -> 26 -> 6x6
  EXPECT_EQ(transmittanceSampleCount(0.5, 256, 4, 32), 25);  // largest square <= 32
  EXPECT_EQ(transmittanceSampleCount(1e-9, 256, 1, 64), 1);
}

TEST(Transmittance, MultiJitteredPointsAreNRooksInBothAxes) {
  for (int n : {4, 16, 64}) {
    std::vector<glm::dvec2> p = multiJitteredPoints(n, 12345);
    ASSERT_EQ(int(p.size()), n);
    std::vector<int> xs(n, 0), ys(n, 0), cells(n, 0);
    int m = int(std::lround(std::sqrt(n)));
    for (glm::dvec2 q : p) {
      ASSERT_GE(q.x, 0.0);
      ASSERT_LT(q.x, 1.0);
      ASSERT_GE(q.y, 0.0);
      ASSERT_LT(q.y, 1.0);
      xs[int(q.x * n)]++;
      ys[int(q.y * n)]++;
      cells[int(q.y * m) * m + int(q.x * m)]++;
    }
    for (int i = 0; i < n; ++i) {
      EXPECT_EQ(xs[i], 1) << n;
      EXPECT_EQ(ys[i], 1) << n;
      EXPECT_EQ(cells[i], 1) << n;
    }
    EXPECT_EQ(multiJitteredPoints(n, 12345), p) << "deterministic";
    EXPECT_NE(multiJitteredPoints(n, 99), p) << "seeded";
  }
}

TEST(Transmittance, MergeOperatorsOnHalfOccludedLayers) {
  EXPECT_DOUBLE_EQ(mergeTransmittance(MergeMode::kMax, 0.5, 0.5), 0.5);
  EXPECT_DOUBLE_EQ(mergeTransmittance(MergeMode::kSum, 0.5, 0.5), 0.0);
  EXPECT_DOUBLE_EQ(mergeTransmittance(MergeMode::kIndependent, 0.5, 0.5), 0.25);
  EXPECT_DOUBLE_EQ(mergeTransmittance(MergeMode::kSum, 1.0, 0.3), 0.3);
  EXPECT_EQ(mergeModeNames().find("independent"), MergeMode::kIndependent);
  EXPECT_FALSE(mergeModeNames().find("mean").has_value());
  EXPECT_DOUBLE_EQ(transmittanceFromMask(0b0101, 0b1111), 0.5);
  EXPECT_DOUBLE_EQ(transmittanceFromMask(0b1111, 0), 1.0);
}

// A wall point beside a large light sees the light's near half under a larger kernel than its
// far half: with the far half occluded, the texel receives F(x -> near half) / F(x -> light),
// not the half that the popcount of the samples says.
TEST(Transmittance, KernelWeightedTransmittanceIsTheVisibleFormFactorShare) {
  const glm::dvec3 x(0.7, 0.0, 1.6), n(-1.0, 0.0, 0.0);  // on a wall at x = 0.7 facing -x
  const Polygon light = ceilingLight();
  const Polygon nearHalf = quad({0, -0.5, 2}, {0, 0.5, 2}, {0.5, 0.5, 2}, {0.5, -0.5, 2});
  const double exact =
      pointToPolygonFormFactor(x, n, nearHalf) / pointToPolygonFormFactor(x, n, light);
  ASSERT_GT(exact, 0.6);  // far from the popcount's 0.5: the test can tell the two apart
  const std::vector<glm::dvec3> samples = lightSamples(64);
  SampleMask occluded = 0, valid = 0;
  for (size_t s = 0; s < samples.size(); ++s) {
    valid |= SampleMask(1) << s;
    if (samples[s].x < 0.0) occluded |= SampleMask(1) << s;
  }
  EXPECT_NEAR(transmittanceFromMask(occluded, valid), 0.5, 1.0 / 64);
  const double t = kernelWeightedTransmittance(x, n, samples, light.normal(), occluded, valid);
  EXPECT_NEAR(t, exact, 0.02) << "popcount " << transmittanceFromMask(occluded, valid);
  // Fully open and fully occluded stay exact; the shooter's facing does not matter.
  EXPECT_EQ(kernelWeightedTransmittance(x, n, samples, light.normal(), 0, valid), 1.0);
  EXPECT_EQ(kernelWeightedTransmittance(x, n, samples, light.normal(), valid, valid), 0.0);
  EXPECT_EQ(kernelWeightedTransmittance(x, n, samples, -light.normal(), occluded, valid), t);
}

// A shooter whose radiosity is not uniform (a subdivided wall, --bad-links partial): the samples
// also weigh by their leaf's B over the mean, per channel. Here the light's near half (x > 0)
// is 3x brighter in red than the mean and its far half dark in red: the texel, whose kernel
// favours the near half, gets more red than the mean radiosity says, and exactly the near
// half's share when the far half is occluded.
TEST(Transmittance, ShapedTransmittanceWeighsEachSampleByItsLeafsRadiosity) {
  const glm::dvec3 x(0.7, 0.0, 1.6), n(-1.0, 0.0, 0.0);
  const Polygon light = ceilingLight();
  const Polygon nearHalf = quad({0, -0.5, 2}, {0, 0.5, 2}, {0.5, 0.5, 2}, {0.5, -0.5, 2});
  const double whole = pointToPolygonFormFactor(x, n, light);
  const double nearShare = pointToPolygonFormFactor(x, n, nearHalf) / whole;
  const std::vector<glm::dvec3> samples = lightSamples(64);
  SampleMask farHalf = 0, valid = 0;
  std::vector<glm::vec3> uniform(samples.size(), glm::vec3(1.0f)), shape(samples.size());
  for (size_t s = 0; s < samples.size(); ++s) {
    valid |= SampleMask(1) << s;
    const bool nearSide = samples[s].x > 0.0;
    if (!nearSide) farHalf |= SampleMask(1) << s;
    shape[s] = nearSide ? glm::vec3(1.8f, 1.0f, 0.5f) : glm::vec3(0.2f, 1.0f, 1.5f);
  }
  // Uniform shape: the kernel-weighted transmittance, and exactly 1 / 0 fully open / occluded.
  const double t = kernelWeightedTransmittance(x, n, samples, light.normal(), farHalf, valid);
  EXPECT_NEAR(shapedTransmittance(x, n, samples, light.normal(), farHalf, valid, uniform).x, t,
              1e-12);
  EXPECT_NEAR(shapedTransmittance(x, n, samples, light.normal(), 0, valid, uniform).y, 1.0, 1e-12);
  EXPECT_EQ(shapedTransmittance(x, n, samples, light.normal(), valid, valid, shape),
            glm::dvec3(0.0));
  // Uneven: fully open, sum_l beta_l F_l / F per channel (not 1); the far half occluded, the
  // near half's share times its beta.
  const glm::dvec3 open = shapedTransmittance(x, n, samples, light.normal(), 0, valid, shape);
  EXPECT_NEAR(open.x, 1.8 * nearShare + 0.2 * (1.0 - nearShare), 0.03);
  EXPECT_NEAR(open.y, 1.0, 1e-12);
  EXPECT_NEAR(open.z, 0.5 * nearShare + 1.5 * (1.0 - nearShare), 0.03);
  EXPECT_GT(open.x, 1.15) << "the kernel favours the brighter near half";
  const glm::dvec3 shadowed =
      shapedTransmittance(x, n, samples, light.normal(), farHalf, valid, shape);
  EXPECT_NEAR(shadowed.x, 1.8 * nearShare, 0.04);
  EXPECT_NEAR(shadowed.z, 0.5 * nearShare, 0.02);
}

// The occlusion-mask tests run on both methods: OSMesa projective shadows and CPU ray casting.
template <class Renderer>
class MaskRenderers : public ::testing::Test {};
using Renderers = ::testing::Types<TransmittanceRenderer, RayCastMaskRenderer>;
class RendererNames {
 public:
  template <class T>
  static std::string GetName(int) {
    return std::is_same_v<T, TransmittanceRenderer> ? "Projective" : "RayCast";
  }
};
TYPED_TEST_SUITE(MaskRenderers, Renderers, RendererNames);

TYPED_TEST(MaskRenderers, NoBlockersLeaveEverythingLit) {
  TypeParam r;
  std::vector<SampleMask> mask;
  r.render(floorReceiver(), 8, 8, lightSamples(16), {}, mask);
  ASSERT_EQ(mask.size(), 64u);
  for (SampleMask m : mask) EXPECT_EQ(m, 0u);
  EXPECT_EQ(r.passes(), 0);
}

// A half-plane occluder x < 0 at z = 1 between the light (z = 2, x in [-.5,.5]) and the floor:
// the ray from floor point (px, *, 0) to light point (sx, *, 2) crosses z = 1 at (px + sx) / 2,
// so it is blocked when sx < -px and the visible fraction is clamp(0.5 + px, 0, 1).
TYPED_TEST(MaskRenderers, HalfPlaneOccluderMatchesTheAnalyticVisibleFraction) {
  const int n = 64, w = 32, h = 8;
  TypeParam r;
  std::vector<SampleMask> mask;
  Polygon occluder = quad({-10, -10, 1}, {0, -10, 1}, {0, 10, 1}, {-10, 10, 1});
  std::vector<glm::dvec3> samples = lightSamples(n);
  SampleMask valid = frontSampleMask(floorReceiver(), samples);
  EXPECT_EQ(valid, ~SampleMask(0));
  r.render(floorReceiver(), w, h, samples, quadTriangles(occluder), mask);
  EXPECT_EQ(r.passes(), 1);
  EXPECT_EQ(r.samplePasses(), n);
  int penumbra = 0;
  double worst = 0.0;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      double px = -1.0 + 2.0 * (i + 0.5) / w;
      double t = transmittanceFromMask(mask[size_t(j) * w + i], valid);
      double expected = std::clamp(0.5 + px, 0.0, 1.0);
      if (px < -0.5) {
        EXPECT_EQ(t, 0.0) << "umbra texel " << i;
      } else if (px > 0.5) {
        EXPECT_EQ(t, 1.0) << "lit texel " << i;
      } else {
        ++penumbra;
        worst = std::max(worst, std::abs(t - expected));
        EXPECT_LE(std::abs(t - expected), 1.0 / n + 1e-9) << "penumbra texel " << i;
      }
    }
  EXPECT_EQ(penumbra, 16 * h);
  this->RecordProperty("penumbra_max_error", std::to_string(worst));
}

TYPED_TEST(MaskRenderers, BlockersBehindThePlaneOrBeyondTheSampleCastNothing) {
  TypeParam r;
  std::vector<SampleMask> mask;
  // Under the floor, above the light, and lying in the receiver's own plane next to it.
  std::vector<BlockerTriangle> tris;
  for (const Polygon& p : {quad({-3, -3, -0.5}, {3, -3, -0.5}, {3, 3, -0.5}, {-3, 3, -0.5}),
                           quad({-3, -3, 2.5}, {3, -3, 2.5}, {3, 3, 2.5}, {-3, 3, 2.5}),
                           quad({1, -1, 0}, {3, -1, 0}, {3, 1, 0}, {1, 1, 0})}) {
    auto t = quadTriangles(p);
    tris.insert(tris.end(), t.begin(), t.end());
  }
  r.render(floorReceiver(), 16, 16, lightSamples(16), tris, mask);
  for (SampleMask m : mask) EXPECT_EQ(m, 0u);
  // A small square right under the light's centre shadows the middle for every sample.
  Polygon chip =
      quad({-0.05, -0.05, 1.9}, {0.05, -0.05, 1.9}, {0.05, 0.05, 1.9}, {-0.05, 0.05, 1.9});
  r.render(floorReceiver(), 16, 16, lightSamples(16), quadTriangles(chip), mask);
  int touched = 0;
  for (SampleMask m : mask) touched += m != 0;
  EXPECT_GT(touched, 0);
  EXPECT_LT(touched, 256);
}

TYPED_TEST(MaskRenderers, StaticAndDynamicMasksOrToTheMaskOfAllBlockers) {
  TypeParam r;
  const int w = 24, h = 20;
  std::vector<glm::dvec3> samples = lightSamples(64, 3);
  // Two overlapping sets of slanted triangles between light and floor.
  std::vector<BlockerTriangle> a, b;
  for (int i = 0; i < 6; ++i) {
    double x = -0.8 + 0.3 * i, z = 0.4 + 0.2 * (i % 4);
    a.push_back({glm::dvec3(x, -0.7, z), glm::dvec3(x + 0.35, -0.2, z + 0.3),
                 glm::dvec3(x - 0.1, 0.5, z + 0.1)});
    b.push_back({glm::dvec3(-x, 0.8, z + 0.2), glm::dvec3(-x + 0.2, -0.1, z),
                 glm::dvec3(-x - 0.3, 0.1, z + 0.5)});
  }
  std::vector<BlockerTriangle> all = a;
  all.insert(all.end(), b.begin(), b.end());
  std::vector<SampleMask> ma, mb, mall;
  r.render(floorReceiver(), w, h, samples, a, ma);
  r.render(floorReceiver(), w, h, samples, b, mb);
  r.render(floorReceiver(), w, h, samples, all, mall);
  int differing = 0, partial = 0;
  for (size_t x = 0; x < mall.size(); ++x) {
    differing += (ma[x] | mb[x]) != mall[x];
    partial += mall[x] != 0 && mall[x] != ~SampleMask(0);
  }
  EXPECT_EQ(differing, 0);
  EXPECT_GT(partial, 20) << "the test needs penumbrae to mean anything";
  // Deterministic: the same render twice is bit-identical.
  std::vector<SampleMask> again;
  r.render(floorReceiver(), w, h, samples, all, again);
  EXPECT_EQ(again, mall);
}

// Random slanted blockers over a tilted planar quad that is not a parallelogram (the homography's
// texel points) and over a triangle: the ray-cast masks are the projective render's but for
// texel centres within the rasterizer's snapping of a projected edge.
TEST(RayCastMasks, AgreeWithTheProjectiveRender) {
  TransmittanceRenderer gl;
  RayCastMaskRenderer rays;
  Polygon tilted = quad({-1, -1, -0.3}, {1.2, -0.9, -0.27}, {0.8, 1.1, 0.33},
                        {-0.9, 0.7, 0.21});  // planar: z = 0.3 y
  Polygon tri;
  tri.count = 3;
  tri.v = {glm::dvec3(-1, -1, 0), glm::dvec3(1, -1, 0), glm::dvec3(-1, 1, 0)};
  uint32_t state = 12345;
  auto next = [&state] {
    state = state * 1664525u + 1013904223u;
    return double(state >> 8) / double(1u << 24);
  };
  long bits = 0, differing = 0, partialTexels = 0;
  for (const Polygon& receiver : {tilted, tri}) {
    for (int trial = 0; trial < 8; ++trial) {
      std::vector<BlockerTriangle> blockers;
      for (int b = 0; b < 5; ++b) {
        glm::dvec3 c(2.0 * next() - 1.0, 2.0 * next() - 1.0, 0.3 + 1.4 * next());
        blockers.push_back({c + glm::dvec3(-0.4 * next(), -0.4 * next(), 0.2 * next() - 0.1),
                            c + glm::dvec3(0.4 * next(), -0.2 * next(), 0.2 * next() - 0.1),
                            c + glm::dvec3(0.1 * next(), 0.4 * next(), 0.2 * next() - 0.1)});
      }
      std::vector<glm::dvec3> samples = lightSamples(64, uint32_t(trial));
      std::vector<SampleMask> a, b;
      gl.render(receiver, 24, 16, samples, blockers, a);
      rays.render(receiver, 24, 16, samples, blockers, b);
      ASSERT_EQ(a.size(), b.size());
      for (size_t x = 0; x < a.size(); ++x) {
        bits += __builtin_popcountll(a[x] | b[x]);
        differing += __builtin_popcountll(a[x] ^ b[x]);
        partialTexels += b[x] != 0 && b[x] != ~SampleMask(0);
      }
    }
  }
  EXPECT_GT(partialTexels, 500) << "the test needs penumbrae to mean anything";
  EXPECT_GT(bits, 10000);
  EXPECT_LE(double(differing), 2e-3 * double(bits)) << differing << " of " << bits;
  RecordProperty("differing_bits", std::to_string(differing) + " of " + std::to_string(bits));
}

// The adaptive renderer ray casts within its budget and renders beyond it, and never opens
// the projective renderer for masks within the budget.
TEST(RayCastMasks, AdaptiveRendererChoosesByCost) {
  int made = 0;
  AdaptiveMaskRenderer r(16.0 * 16.0 * 16.0, [&made] {
    ++made;
    return std::make_unique<TransmittanceRenderer>();
  });
  Polygon chip =
      quad({-0.05, -0.05, 1.9}, {0.05, -0.05, 1.9}, {0.05, 0.05, 1.9}, {-0.05, 0.05, 1.9});
  std::vector<SampleMask> small, large, reference;
  r.render(floorReceiver(), 16, 16, lightSamples(16), quadTriangles(chip),
           small);  // 16 x 16 texels x 16 samples
  EXPECT_EQ(made, 0);
  EXPECT_EQ(r.rayCastPasses(), 1);
  EXPECT_EQ(r.rendererName(), "ray cast");
  r.render(floorReceiver(), 32, 16, lightSamples(16), quadTriangles(chip), large);  // twice that
  EXPECT_EQ(made, 1);
  EXPECT_EQ(r.rayCastPasses(), 1);
  EXPECT_EQ(r.passes(), 2);
  EXPECT_EQ(r.samplePasses(), 32);
  RayCastMaskRenderer rays;
  rays.render(floorReceiver(), 16, 16, lightSamples(16), quadTriangles(chip), reference);
  EXPECT_EQ(small, reference);
  AdaptiveMaskRenderer never(0.0, [] { return std::make_unique<TransmittanceRenderer>(); });
  never.render(floorReceiver(), 4, 4, lightSamples(16), quadTriangles(chip), small);
  EXPECT_EQ(never.rayCastPasses(), 0);
  EXPECT_EQ(never.passes(), 1);
}

}  // namespace
}  // namespace rad
