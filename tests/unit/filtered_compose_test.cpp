// rad-compose's pixel filter (libcommon/compose/footprint_filter.h) on a known edge: two flat-lit
// coplanar walls of radiances A and B meet along a vertical line that crosses a pixel row at a
// known sub-pixel offset. Each pixel must be the filter over the grid's samples (exactly, as the
// discrete sum says), which approaches the filter's integral (Cycles' value) as the grid gets
// finer; --pixel-filter none must be the single-sample frame; threads must not matter.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "libcommon/compose/frame_composer.h"
#include "tests/unit/compose_fixture.h"

namespace rad {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr ImageSize kSize{32, 20};
constexpr double kDepth = 5.0, kYfov = 0.8;
// The edge's image column: 13.37 px from the left, inside pixel 13, off every sample of the
// grids below (samples at (k + 1/2) / s).
constexpr double kEdgeColumn = 13.37;
const glm::dvec3 kHa(2.0, 4.0, 8.0), kHb(10.0, 1.0, 0.5);  // irradiance of the walls
constexpr double kRho = 0.5;

struct EdgeScene {
  Scene scene;
  GlobalSolution solution;
  std::vector<float> texA, texB;
  std::vector<MovieTexture> movies;
};

// Two walls at z = -5 facing the camera at the origin, meeting at the world x of kEdgeColumn,
// far larger than the view; each with a constant one-texel movie.
EdgeScene edgeScene() {
  EdgeScene e;
  Scene& s = e.scene;
  s.path = "edge";
  Material m;
  m.reflectance = glm::dvec3(kRho);
  s.materials = {m};
  const double aspect = double(kSize.width) / kSize.height, halfTan = std::tan(0.5 * kYfov);
  const double x0 = (2.0 * kEdgeColumn / kSize.width - 1.0) * aspect * halfTan * kDepth;
  for (const auto& [a, b] : {std::pair<double, double>{-20.0, x0}, {x0, 20.0}}) {
    Mesh mesh;
    MeshTriangle t1, t2;
    t1.p = {glm::dvec3(a, -20, -kDepth), glm::dvec3(b, -20, -kDepth), glm::dvec3(b, 20, -kDepth)};
    t2.p = {glm::dvec3(a, -20, -kDepth), glm::dvec3(b, 20, -kDepth), glm::dvec3(a, 20, -kDepth)};
    t1.material = t2.material = 0;
    mesh.triangles = {t1, t2};
    Node node;
    node.mesh = int(s.meshes.size());
    s.meshes.push_back(mesh);
    s.nodes.push_back(node);
  }
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
  e.texA = {float(kHa.x), float(kHa.y), float(kHa.z)};
  e.texB = {float(kHb.x), float(kHb.y), float(kHb.z)};
  e.movies = {{PatchId{0, 1}, 1, 1, e.texA.data()}, {PatchId{1, 1}, 1, 1, e.texB.data()}};
  return e;
}

ComposedFrame composeEdge(const EdgeScene& e, const PixelSampling& sampling, bool every = false) {
  FrameComposer composer(e.scene, e.solution, kSize, e.scene.cameraNode(""), sampling, every);
  return composer.compose(0.0, e.movies);
}

// The fraction of the filter's weight left of the edge for pixel `col`: over the grid's samples
// (the discrete sum compose must give) or over the continuous filter (Cycles' value).
double leftShareOnGrid(const PixelFilter& f, int s, int col) {
  const int reach = int(std::floor(f.radius() * s + 1e-9));
  double left = 0.0, all = 0.0;
  for (int k = -reach; k <= reach; ++k) {
    const double x = col + 0.5 + double(k) / s, w = f.weight(double(k) / s);
    all += w;
    if (x < kEdgeColumn) left += w;
  }
  return left / all;
}
double leftShareOfFilter(const PixelFilter& f, int col) {
  const int n = 100000;
  const double r = f.radius();
  double left = 0.0, all = 0.0;
  for (int i = 0; i < n; ++i) {
    const double v = -r + 2.0 * r * (i + 0.5) / n, w = f.weight(v);
    all += w;
    if (col + 0.5 + v < kEdgeColumn) left += w;
  }
  return left / all;
}

glm::dvec3 at(const ComposedFrame& f, int col, int row) {
  const size_t p = size_t(row) * kSize.width + col;
  return {f.rgb[3 * p], f.rgb[3 * p + 1], f.rgb[3 * p + 2]};
}

TEST(FilteredCompose, EdgePixelsAreTheFilterOverTheSamplesAndApproachItsIntegral) {
  const EdgeScene e = edgeScene();
  const glm::dvec3 A = kRho / kPi * kHa, B = kRho / kPi * kHb;
  for (const PixelFilter& f : {PixelFilter{}, PixelFilter{PixelFilterType::kGaussian, 1.5},
                               PixelFilter{PixelFilterType::kBox, 1.0}}) {
    for (int s : {3, 15}) {
      const ComposedFrame frame = composeEdge(e, PixelSampling{f, s});
      EXPECT_EQ(frame.fallbackPixels, 0);
      for (int col = 0; col < kSize.width; ++col) {
        const double share = leftShareOnGrid(f, s, col);
        const glm::dvec3 want = share * A + (1.0 - share) * B;
        for (int row : {0, kSize.height / 2, kSize.height - 1})
          for (int c = 0; c < 3; ++c)
            ASSERT_NEAR(at(frame, col, row)[c], want[c], 2e-6 * want[c])
                << f.toString() << " s " << s << " pixel " << col << "," << row;
        // The grid's sum against the filter's integral: its quadrature error bound,
        // at most the largest normalised weight of one column of samples.
        const double exact = leftShareOfFilter(f, col);
        EXPECT_NEAR(share, exact, (s == 15 ? 0.04 : 0.2)) << f.toString() << " col " << col;
      }
    }
  }
}

TEST(FilteredCompose, PixelFilterNoneIsTheSingleSampleFrame) {
  const EdgeScene e = edgeScene();
  FrameComposer before(e.scene, e.solution, kSize, e.scene.cameraNode(""));  // the pre-filter API
  const ComposedFrame single = before.compose(0.0, e.movies);
  const ComposedFrame none = composeEdge(e, PixelSampling{PixelFilter::pixelCentre(), 3});
  EXPECT_EQ(none.rgb, single.rgb);
  // Point sampling: every pixel is A or B, the edge pixel the side its centre is on.
  const glm::dvec3 A = kRho / kPi * kHa, B = kRho / kPi * kHb;
  for (int col = 0; col < kSize.width; ++col) {
    const glm::dvec3 want = col + 0.5 < kEdgeColumn ? A : B;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(at(none, col, 7)[c], want[c], 1e-6 * want[c]);
  }
}

TEST(FilteredCompose, ShortcutMatchesEverySampleAndThreadsDoNotMatter) {
  const EdgeScene e = edgeScene();
  const PixelSampling sampling{PixelFilter{}, 5};
  ComposedFrame one, two;
  {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 1);
    one = composeEdge(e, sampling);
  }
  {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
    two = composeEdge(e, sampling);
  }
  EXPECT_EQ(one.rgb, two.rgb);
  // A flat field: the uniform footprints' shortcut and the interpolated samples are exact.
  const ComposedFrame every = composeEdge(e, sampling, true);
  ASSERT_EQ(every.rgb.size(), one.rgb.size());
  for (size_t i = 0; i < one.rgb.size(); ++i)
    ASSERT_NEAR(one.rgb[i], every.rgb[i], 2e-6 * every.rgb[i]) << i;
}

}  // namespace
}  // namespace rad
