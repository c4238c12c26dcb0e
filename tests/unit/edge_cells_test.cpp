// rad-compose's edge cells (libcommon/compose/edge_cells.h, cell_coverage.h, footprint_filter.h):
// a bright lamp in front of a dark flat-lit wall, its outline crossing pixels at known sub-pixel
// offsets, straight and rotated. Each pixel must be the filter's integral over the scene's
// radiance, L_wall + (L_lamp - L_wall) * (the filter's weight over the lamp's outline), to a
// small share of the step; the plain grid (--no-edge-coverage) places the outline to 1/3 px and
// misses by a large share of it. A floor through the eye plane checks the outline clipped at
// the near plane. Threads must not change a bit.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "libcommon/compose/cell_coverage.h"
#include "libcommon/compose/frame_composer.h"
#include "tests/unit/compose_fixture.h"

namespace rad {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr ImageSize kSize{32, 20};
constexpr double kYfov = 0.8, kWallDepth = 5.0, kLampDepth = 4.9;
const glm::dvec3 kLampLe(60.0, 50.0, 40.0);  // the lamp's radiance: a thousand times the wall's
const glm::dvec3 kWallH(0.2, 0.3, 0.4);      // the wall's irradiance (reflectance 0.5)
constexpr double kWallRho = 0.5;

// World point at depth `depth` on the ray through pixel position `px` of the camera at the
// origin looking down -Z (camera_projection.h): the lamp is parallel to the image, so its
// outline in pixels is exactly the polygon it was made from.
glm::dvec3 atPixel(glm::dvec2 px, double depth) {
  const double halfTan = std::tan(0.5 * kYfov), aspect = double(kSize.width) / kSize.height;
  return {(2.0 * px.x / kSize.width - 1.0) * aspect * halfTan * depth,
          (1.0 - 2.0 * px.y / kSize.height) * halfTan * depth, -depth};
}

struct LampScene {
  Scene scene;
  GlobalSolution solution;
  std::vector<float> wallTexel, lampTexel;
  std::vector<MovieTexture> movies;
  std::vector<glm::dvec2> outline;  // the lamp in pixels (row 0 at the top), clockwise on screen
};

// A wall far larger than the view and a rectangular lamp in front of it: its centre at `centre`
// px, half sides `half` px, turned by `angle` radians.
LampScene lampScene(glm::dvec2 centre, glm::dvec2 half, double angle) {
  LampScene e;
  Scene& s = e.scene;
  s.path = "lamp";
  Material wall, lamp;
  wall.reflectance = glm::dvec3(kWallRho);
  lamp.reflectance = glm::dvec3(0.0);
  lamp.emission = kLampLe;
  s.materials = {wall, lamp};
  const glm::dvec2 u(std::cos(angle), std::sin(angle)), v(-std::sin(angle), std::cos(angle));
  e.outline = {centre - half.x * u - half.y * v, centre + half.x * u - half.y * v,
               centre + half.x * u + half.y * v, centre - half.x * u + half.y * v};
  auto addQuad = [&](const std::array<glm::dvec3, 4>& q, int material) {
    Mesh mesh;
    MeshTriangle t1, t2;
    t1.p = {q[0], q[1], q[2]};
    t2.p = {q[0], q[2], q[3]};
    t1.material = t2.material = material;
    mesh.triangles = {t1, t2};
    Node node;
    node.mesh = int(s.meshes.size());
    s.meshes.push_back(mesh);
    s.nodes.push_back(node);
  };
  // Both wound to face the camera (+z).
  addQuad({glm::dvec3(-20, -20, -kWallDepth), glm::dvec3(20, -20, -kWallDepth),
           glm::dvec3(20, 20, -kWallDepth), glm::dvec3(-20, 20, -kWallDepth)},
          0);
  std::array<glm::dvec3, 4> lampQuad;
  for (int k = 0; k < 4; ++k) lampQuad[size_t(3 - k)] = atPixel(e.outline[size_t(k)], kLampDepth);
  addQuad(lampQuad, 1);
  Camera lens;
  lens.name = "cam";
  lens.yfov = kYfov;
  lens.znear = 0.01;
  s.cameras.push_back(lens);
  Node cam;
  cam.name = "cam";
  cam.camera = 0;
  s.nodes.push_back(cam);
  e.solution = test::makeSolution(s, {0.0}, false, [](int, int) { return glm::dvec3(0.0); });
  e.wallTexel = {float(kWallH.x), float(kWallH.y), float(kWallH.z)};
  e.lampTexel = {0.0f, 0.0f, 0.0f};
  e.movies = {{PatchId{0, 1}, 1, 1, e.wallTexel.data()}, {PatchId{1, 1}, 1, 1, e.lampTexel.data()}};
  return e;
}

ComposedFrame compose(const LampScene& e, bool edgeCoverage, int samples = 3) {
  FrameComposer composer(e.scene, e.solution, kSize, e.scene.cameraNode(""),
                         PixelSampling{PixelFilter{}, samples}, false, edgeCoverage);
  return composer.compose(0.0, e.movies);
}

// The filter's weight over the outline for every pixel, normalised, row-major: the rows of each
// support integrated exactly across (the outline is convex: one interval a row), n rows.
std::vector<double> lampShares(const std::vector<glm::dvec2>& outline) {
  const PixelFilter f;
  const double r = f.radius();
  const int n = 2000;
  // F(x) = \int_{-r}^{x} f, tabulated finely.
  std::vector<double> cdf(size_t(n) + 1, 0.0);
  for (int i = 0; i < n; ++i)
    cdf[size_t(i + 1)] = cdf[size_t(i)] + f.weight(-r + 2.0 * r * (i + 0.5) / n) * 2.0 * r / n;
  auto F = [&](double x) {
    const double t = std::clamp((x + r) / (2.0 * r) * n, 0.0, double(n));
    const int i = std::min(int(t), n - 1);
    return cdf[size_t(i)] + (t - i) * (cdf[size_t(i + 1)] - cdf[size_t(i)]);
  };
  std::vector<double> shares;
  for (int row = 0; row < kSize.height; ++row)
    for (int col = 0; col < kSize.width; ++col) {
      double in = 0.0;
      for (int j = 0; j < n; ++j) {
        const double dy = -r + 2.0 * r * (j + 0.5) / n, y = row + 0.5 + dy;
        double lo = HUGE_VAL, hi = -HUGE_VAL;  // the outline's x interval on this row
        for (size_t k = 0; k < outline.size(); ++k) {
          const glm::dvec2 a = outline[k], b = outline[(k + 1) % outline.size()];
          if ((a.y - y) * (b.y - y) > 0.0 || a.y == b.y) continue;
          const double x = a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x);
          lo = std::min(lo, x), hi = std::max(hi, x);
        }
        if (hi > lo) in += f.weight(dy) * (F(hi - col - 0.5) - F(lo - col - 0.5)) * 2.0 * r / n;
      }
      shares.push_back(in / (cdf[size_t(n)] * cdf[size_t(n)]));
    }
  return shares;
}

// The largest |pixel - truth| over the frame, as a share of the lamp's step (the worst
// channel).
double worstShareOfStep(const std::vector<double>& shares, const ComposedFrame& frame) {
  const glm::dvec3 wall = kWallRho / kPi * kWallH;
  double worst = 0.0;
  for (size_t p = 0; p < shares.size(); ++p)
    for (int c = 0; c < 3; ++c) {
      const double want = wall[c] + shares[p] * (kLampLe[c] - wall[c]);
      worst =
          std::max(worst, std::abs(frame.rgb[3 * p + size_t(c)] - want) / (kLampLe[c] - wall[c]));
    }
  return worst;
}

TEST(CellCoverage, SquareHalfCoveredAndTriangleCorner) {
  const glm::dvec2 half[4] = {{0.0, -5.0}, {5.0, -5.0}, {5.0, 5.0}, {0.0, 5.0}};
  const CellCoverage c = polygonCellCoverage(half, 4, glm::dvec2(0.1, 0.0), 0.5);
  EXPECT_NEAR(c.fraction, 0.6, 1e-12);          // x in [0, 0.6] of [-0.4, 0.6]
  EXPECT_NEAR(c.centroid.x, 0.3 - 0.1, 1e-12);  // centred at x = 0.3
  EXPECT_NEAR(c.centroid.y, 0.0, 1e-12);
  const glm::dvec2 corner[3] = {{-0.5, -0.5}, {0.5, -0.5}, {-0.5, 0.5}};  // either winding
  const CellCoverage t = polygonCellCoverage(corner, 3, glm::dvec2(0.0), 0.5);
  EXPECT_NEAR(t.fraction, 0.5, 1e-12);
  EXPECT_NEAR(t.centroid.x, -1.0 / 6.0, 1e-12);
  EXPECT_NEAR(t.centroid.y, -1.0 / 6.0, 1e-12);
  const glm::dvec2 far[3] = {{3, 3}, {4, 3}, {3, 4}};
  EXPECT_EQ(polygonCellCoverage(far, 3, glm::dvec2(0.0), 0.5).fraction, 0.0);
}

TEST(EdgeCells, LampOutlineIsTheFiltersIntegralAndThePlainGridIsNot) {
  // Outline offsets off every sample of the 3 x 3 grid (samples at (k + 1/2) / 3).
  for (const double angle : {0.0, 0.35}) {
    const LampScene e = lampScene(glm::dvec2(15.37, 9.81), glm::dvec2(7.23, 4.58), angle);
    ASSERT_EQ(e.scene.inputPolygons().size(), 2u);
    const ComposedFrame covered = compose(e, true), plain = compose(e, false);
    EXPECT_EQ(covered.fallbackPixels, 0);
    const std::vector<double> shares = lampShares(e.outline);
    EXPECT_LT(worstShareOfStep(shares, covered), 2.5e-3) << "angle " << angle;
    EXPECT_GT(worstShareOfStep(shares, plain), 5e-2) << "angle " << angle;
  }
}

// A floor from behind the camera to 20 m ahead under a black sky: its polygon crosses the eye
// plane, so its outline is the part beyond the near plane, projected (edge_cells.cpp). Its far
// edge is a horizontal line on the image; each pixel must be the floor's radiance times the
// filter's weight below that line.
TEST(EdgeCells, AFloorThroughTheEyePlaneIsClippedAtTheNearPlane) {
  Scene s;
  s.path = "floor";
  Material floor;
  floor.reflectance = glm::dvec3(kWallRho);
  s.materials = {floor};
  Mesh mesh;
  MeshTriangle t1, t2;
  const glm::dvec3 q[4] = {{-20, -1, 5}, {20, -1, 5}, {20, -1, -20}, {-20, -1, -20}};
  t1.p = {q[0], q[1], q[2]};
  t2.p = {q[0], q[2], q[3]};
  t1.material = t2.material = 0;
  mesh.triangles = {t1, t2};
  Node node;
  node.mesh = 0;
  s.meshes.push_back(mesh);
  s.nodes.push_back(node);
  Camera lens;
  lens.name = "cam";
  lens.yfov = kYfov;
  lens.znear = 0.01;
  s.cameras.push_back(lens);
  Node cam;
  cam.name = "cam";
  cam.camera = 0;
  s.nodes.push_back(cam);
  ASSERT_EQ(s.inputPolygons().size(), 1u);
  const GlobalSolution g =
      test::makeSolution(s, {0.0}, false, [](int, int) { return glm::dvec3(0.0); });
  const std::vector<float> texel = {float(kWallH.x), float(kWallH.y), float(kWallH.z)};
  const std::vector<MovieTexture> movies = {{PatchId{0, 1}, 1, 1, texel.data()}};
  // The far edge's image row: y = -1 at z = -20.
  const double edgeRow = (1.0 + (1.0 / 20.0) / std::tan(0.5 * kYfov)) * 0.5 * kSize.height;
  const PixelFilter f;
  const glm::dvec3 L = kWallRho / kPi * kWallH;
  for (const bool coverage : {true, false}) {
    FrameComposer composer(s, g, kSize, s.cameraNode(""), PixelSampling{f, 3}, false, coverage);
    const ComposedFrame frame = composer.compose(0.0, movies);
    EXPECT_EQ(frame.fallbackPixels, 0);
    double worst = 0.0;
    for (int row = 0; row < kSize.height; ++row) {
      // The filter's weight below the edge (rows of larger y), by a fine midpoint sum.
      const int n = 20000;
      double below = 0.0, all = 0.0;
      for (int i = 0; i < n; ++i) {
        const double v = -f.radius() + 2.0 * f.radius() * (i + 0.5) / n, w = f.weight(v);
        all += w;
        if (row + 0.5 + v > edgeRow) below += w;
      }
      for (int col = 2; col < kSize.width - 2; ++col)
        for (int c = 0; c < 3; ++c) {
          const size_t p = size_t(row) * kSize.width + col;
          worst =
              std::max(worst, std::abs(frame.rgb[3 * p + size_t(c)] - below / all * L[c]) / L[c]);
        }
    }
    if (coverage)
      EXPECT_LT(worst, 2.5e-3);
    else
      EXPECT_GT(worst, 5e-2);
  }
}

TEST(EdgeCells, ThreadsDoNotChangeABit) {
  const LampScene e = lampScene(glm::dvec2(15.37, 9.81), glm::dvec2(7.23, 4.58), 0.35);
  ComposedFrame one, two;
  {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 1);
    one = compose(e, true, 5);
  }
  {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
    two = compose(e, true, 5);
  }
  EXPECT_EQ(one.rgb, two.rgb);
}

}  // namespace
}  // namespace rad
