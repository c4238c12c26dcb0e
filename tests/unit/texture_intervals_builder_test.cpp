#include "libcommon/intervals/texture_intervals_builder.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>

#include <gtest/gtest.h>

#include "formats/gltf_scene.h"
#include "formats/item_buffer_exr.h"
#include "formats/provenance.h"
#include "formats/texture_intervals.h"
#include "libcommon/core/error.h"
#include "libcommon/intervals/projected_area.h"

namespace rad {
namespace {

constexpr ImageSize kSize{176, 120};

// Synthetic scenes built directly in the scene model: fronto-parallel rectangles and one
// camera at the origin looking down -Z, both optionally animated (LINEAR translation).
struct TestScene {
  Scene scene;
  int camera = -1;

  TestScene() {
    scene.path = "test.gltf";
    scene.materials.push_back(Material{});
    Node cam;
    cam.name = "camera";
    cam.camera = 0;
    Camera lens;
    lens.name = "lens";
    lens.yfov = 0.8;
    lens.znear = 0.05;
    scene.cameras.push_back(lens);
    camera = addNode(cam);
  }
  int addNode(const Node& n) {
    scene.nodes.push_back(n);
    return int(scene.nodes.size()) - 1;
  }
  // Rectangle [x0, x1] x [y0, y1] in the plane z (local frame), facing +Z (the camera).
  int addRect(const std::string& name, double x0, double y0, double x1, double y1, double z) {
    Mesh m;
    m.name = name;
    glm::dvec3 a(x0, y0, z), b(x1, y0, z), c(x1, y1, z), d(x0, y1, z);
    MeshTriangle t1, t2;
    t1.p = {a, b, c};
    t2.p = {a, c, d};
    t1.material = t2.material = 0;
    m.triangles = {t1, t2};
    scene.meshes.push_back(m);
    Node n;
    n.name = name;
    n.mesh = int(scene.meshes.size()) - 1;
    return addNode(n);
  }
  // Linear translation from `from` at t = 0 to `to` at t = t1.
  void move(int node, glm::dvec3 from, glm::dvec3 to, double t1) {
    AnimationChannel ch;
    ch.node = node;
    ch.path = AnimationPath::kTranslation;
    ch.interpolation = Interpolation::kLinear;
    ch.times = {0.0, t1};
    ch.values = {from.x, from.y, from.z, to.x, to.y, to.z};
    scene.channels.push_back(ch);
    scene.nodes[node].translation = from;
  }
};

std::vector<int> frameRange(int a, int b) {
  std::vector<int> f;
  for (int i = a; i <= b; ++i) f.push_back(i);
  return f;
}

int topOfNode(const PatchHierarchy& h, int sceneNode) {
  for (int t = 0; t < h.topCount(); ++t)
    if (h.top(t).node == sceneNode) return t;
  return -1;
}

std::vector<MovieExtent> moviesOfTop(const std::vector<MovieExtent>& all, int top) {
  std::vector<MovieExtent> out;
  for (const MovieExtent& m : all)
    if (int(m.patch.top) == top) out.push_back(m);
  return out;
}

TEST(TextureSize, PowerOfTwoClampedWithHysteresis) {
  TextureIntervalsOptions o;
  o.sizeRatio = 2.0;
  EXPECT_EQ(textureSideFor(30.0 * 30.0, 0, o), 32);
  EXPECT_EQ(textureSideFor(33.0 * 33.0, 0, o), 64);
  EXPECT_EQ(textureSideFor(1.0, 0, o), 4);            // min size
  EXPECT_EQ(textureSideFor(1e6 * 1e6, 0, o), 256);    // max size
  EXPECT_EQ(textureSideFor(47.0 * 47.0, 32, o), 32);  // within (32/3, 48]: kept
  EXPECT_EQ(textureSideFor(49.0 * 49.0, 32, o), 64);
  EXPECT_EQ(textureSideFor(11.0 * 11.0, 32, o), 32);
  EXPECT_EQ(textureSideFor(10.0 * 10.0, 32, o), 16);
  o.texelDensity = 4.0;  // two texels per pixel along each side
  EXPECT_EQ(textureSideFor(30.0 * 30.0, 0, o), 64);
  o.resizeTolerance = 0.0;
  o.texelDensity = 1.0;
  EXPECT_EQ(textureSideFor(33.0 * 33.0, 32, o), 64);
  EXPECT_EQ(textureSideFor(16.5 * 16.5, 32, o), 32);
  EXPECT_EQ(textureSideFor(16.0 * 16.0, 32, o), 16);
}

// A texture has its node's shape (issue 56): a square patch keeps n x n; a long thin rectangle
// gets its texels along its length, so that they lie as far apart along it as across (a 4 m x
// 4 cm lamp face was 128 x 128 texels of which 3 along its width and 128 along 4 m); a sliver
// triangle's texels follow its two edges at v0, and a sheared map takes 1 / sin more.
TEST(TextureSize, TexturesTakeTheShapeOfTheirPatch) {
  TextureIntervalsOptions o;
  o.sizeRatio = 2.0;
  o.minSize = 1;
  o.maxSize = 4096;
  auto quad = [](double a, double b) {
    Polygon p;
    p.count = 4;
    p.v = {glm::dvec3(0, 0, 0), glm::dvec3(a, 0, 0), glm::dvec3(a, b, 0), glm::dvec3(0, b, 0)};
    return p;
  };
  const TextureShape square = textureShapeOf(quad(2.0, 2.0));
  EXPECT_NEAR(square.u, 1.0, 1e-12);
  EXPECT_NEAR(square.v, 1.0, 1e-12);
  EXPECT_EQ(textureSizeFor(32.0 * 32.0, square, {}, o), (TextureSize{32, 32}));
  // 100 x 1 pixels: 128 x 1, not 16 x 16 (6 pixels a texel along the length).
  const TextureShape lamp = textureShapeOf(quad(4.0, 0.04));
  EXPECT_NEAR(lamp.u / lamp.v, 100.0, 1e-9);
  EXPECT_EQ(textureSizeFor(100.0, lamp, {}, o), (TextureSize{128, 1}));
  EXPECT_EQ(textureSideFor(100.0, 0, o), 16);
  // A right triangle at v0 keeps the square; v0 at a 30 degree corner takes twice the texels.
  Polygon right;
  right.count = 3;
  right.v = {glm::dvec3(0, 0, 0), glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0)};
  const TextureShape r = textureShapeOf(right);
  EXPECT_NEAR(r.u * r.v, 1.0, 1e-12);
  Polygon sheared = right;
  const double a = std::acos(-1.0) / 6;  // 30 degrees
  sheared.v[2] = glm::dvec3(std::cos(a), std::sin(a), 0.0);
  const TextureShape sh = textureShapeOf(sheared);
  EXPECT_NEAR(sh.u * sh.v, 2.0, 1e-9);
  // Hysteresis per axis: a small zoom keeps both sides.
  EXPECT_EQ(textureSizeFor(110.0, lamp, {128, 1}, o), (TextureSize{128, 1}));
  // Degenerate: square.
  Polygon flat = right;
  flat.v[2] = flat.v[1];
  EXPECT_EQ(textureShapeOf(flat).u, 1.0);
}

// --size-ratio sqrt 2: sides round(sqrt(2)^k), so a texture holds its patch's pixels with at most
// twice the texels (powers of two: up to four times).
TEST(TextureSize, SquareRootOfTwoLadderHoldsEveryPixelWithAtMostTwiceTheTexels) {
  TextureIntervalsOptions o;
  o.sizeRatio = std::sqrt(2.0);
  EXPECT_EQ(textureSideFor(30.0 * 30.0, 0, o), 32);
  EXPECT_EQ(textureSideFor(23.0 * 23.0, 0, o), 23);
  EXPECT_EQ(textureSideFor(24.0 * 24.0, 0, o), 32);
  EXPECT_EQ(textureSideFor(40.0 * 40.0, 0, o), 45);
  EXPECT_EQ(textureSideFor(5.0 * 5.0, 0, o), 6);
  EXPECT_EQ(textureSideFor(1.0, 0, o), 4);  // min size
  EXPECT_EQ(textureSideFor(1e6, 0, o), 256);
  for (int n = 4; n <= 256; ++n) {
    const int side = textureSideFor(double(n) * n, 0, o);
    EXPECT_GE(side, n);
    EXPECT_LE(double(side) * side, 2.0 * (n + 0.5) * (n + 0.5)) << n;
  }
  // Hysteresis: 32 is kept while the ideal side is in (32 / (sqrt 2 x 1.5), 32 x 1.5].
  EXPECT_EQ(textureSideFor(16.0 * 16.0, 32, o), 32);
  EXPECT_EQ(textureSideFor(15.0 * 15.0, 32, o), 16);
  EXPECT_EQ(textureSideFor(48.0 * 48.0, 32, o), 32);
  EXPECT_EQ(textureSideFor(49.0 * 49.0, 32, o), 64);
}

TEST(TextureIntervalsOptions, RejectsBadValuesNamingTheFlag) {
  TextureIntervalsOptions o;
  o.minVisibleFraction = 1.5;
  try {
    o.validate();
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kUsage);
    EXPECT_NE(std::string(e.what()).find("--min-visible-fraction"), std::string::npos);
  }
  o = {};
  o.maxSize = 2;
  EXPECT_THROW(o.validate(), Error);
}

// A rectangle to the right of the view comes in as the camera pans right: its first movie
// starts at the first frame where one pixel centre is inside its image.
TEST(TextureIntervalsBuilder, PatchEnteringTheFrustumOpensAtTheExactFrame) {
  TestScene s;
  int rect = s.addRect("rect", 6.1, -1.0, 8.1, 1.0, -5.0);
  s.move(s.camera, {0, 0, 0}, {10, 0, 0}, 2.0);  // 5 m/s; 48 frames at 24 fps
  TextureIntervalsOptions o;
  o.imageSize = kSize;
  // Expected: first frame whose left edge projects left of the last column's centre.
  int expected = -1;
  for (int f = 0; f <= 48 && expected < 0; ++f) {
    CameraView v = s.scene.cameraAt(s.camera, f / 24.0);
    double x = projectToPixel(v, kSize, {6.1, 0.0, -5.0}).pixel.x;
    ASSERT_GT(std::abs(x - (kSize.width - 0.5)), 0.05) << "ambiguous frame " << f;
    if (x < kSize.width - 0.5) expected = f;
  }
  ASSERT_GT(expected, 5);
  TextureIntervalsBuilder b(s.scene, s.camera, o);
  for (int f : frameRange(0, 48)) b.addFrame(f);
  std::vector<MovieExtent> all = b.finish();
  std::vector<MovieExtent> mine = moviesOfTop(all, topOfNode(b.hierarchy(), rect));
  ASSERT_FALSE(mine.empty());
  int first = mine.front().firstFrame;
  for (const MovieExtent& m : mine) first = std::min(first, m.firstFrame);
  EXPECT_EQ(first, expected);
  // Entering with a small visible fraction, it starts below the top level and goes up.
  EXPECT_GT(mine.front().patch.level(), 0);
  EXPECT_EQ(mine.back().patch.level(), 0);
  EXPECT_EQ(mine.back().end, MovieEnd::kWindow);
  for (size_t i = 0; i + 1 < mine.size(); ++i) EXPECT_EQ(mine[i].end, MovieEnd::kLevelChange) << i;
}

// A 2 m rectangle at z = -10 and an occluder `halfWidth` m either side of its centre at z = -5
// sliding across in front of it, centre x(f) = -10 + 0.3 f; the rectangle is [-0.5, 0.5] at
// z = -5 in projection. One level only: no level changes, only visibility events.
struct OccluderPassing {
  TestScene s;
  int back = -1, occluder = -1;
  TextureIntervalsOptions o;
  explicit OccluderPassing(double halfWidth) {
    back = s.addRect("back", -1.0, -1.0, 1.0, 1.0, -10.0);
    occluder = s.addRect("occluder", -halfWidth, -3.0, halfWidth, 3.0, -5.0);
    s.move(occluder, {-10, 0, 0}, {20, 0, 0}, 100.0 / 24.0);
    o.imageSize = kSize;
    o.maxLevel = 0;
  }
};

// A wide occluder slides across in front of a small rectangle: the rectangle's movie closes
// as hidden the frame before it is fully covered and a new one opens when it reappears.
TEST(TextureIntervalsBuilder, OccluderPassingInFrontClosesAsHidden) {
  // 4 m wide: it hides the back rectangle for x in [-1.5, 1.5], frames 29..38.
  OccluderPassing p(2.0);
  const TestScene& s = p.s;
  const int back = p.back, occluder = p.occluder;
  std::vector<MovieExtent> all = buildTextureIntervals(s.scene, s.camera, frameRange(0, 60), p.o);
  PatchHierarchy h(s.scene.inputPolygons());
  std::vector<MovieExtent> mine = moviesOfTop(all, topOfNode(h, back));
  ASSERT_EQ(mine.size(), 2u);
  EXPECT_EQ(mine[0].firstFrame, 0);
  EXPECT_EQ(mine[0].lastFrame, 28);
  EXPECT_EQ(mine[0].end, MovieEnd::kHidden);
  EXPECT_EQ(mine[1].firstFrame, 39);
  EXPECT_EQ(mine[1].lastFrame, 60);
  EXPECT_EQ(mine[1].end, MovieEnd::kWindow);
  // The occluder itself leaves the frustum to the right before frame 60.
  std::vector<MovieExtent> occ = moviesOfTop(all, topOfNode(h, occluder));
  ASSERT_FALSE(occ.empty());
  EXPECT_EQ(occ.back().end, MovieEnd::kLeftFrustum);
  EXPECT_LT(occ.back().lastFrame, 60);
}

// The same occluder, 2.1 m wide, hides the back rectangle for 4 frames (32..35): within a
// hidden gap of 4 frames or more its movie goes on over them; with less, or 0 (the paper's
// rule), it closes as hidden and a new one opens when the rectangle shows again.
TEST(TextureIntervalsBuilder, ShortHiddenGapKeepsTheMovie) {
  OccluderPassing p(1.05);
  const TestScene& s = p.s;
  TextureIntervalsOptions& o = p.o;
  const int back = p.back;
  PatchHierarchy h(s.scene.inputPolygons());
  for (int gap : {0, 3, 4, 6}) {
    o.hiddenGap = gap;
    TextureIntervalsBuilder b(s.scene, s.camera, o);
    for (int f : frameRange(0, 60)) b.addFrame(f);
    std::vector<MovieExtent> mine = moviesOfTop(b.finish(), topOfNode(h, back));
    if (gap >= 4) {
      ASSERT_EQ(mine.size(), 1u) << gap;
      EXPECT_EQ(mine[0].firstFrame, 0);
      EXPECT_EQ(mine[0].lastFrame, 60);
      EXPECT_EQ(mine[0].end, MovieEnd::kWindow);
      EXPECT_EQ(b.moviesContinuedOverGaps(), 1);
    } else {
      ASSERT_EQ(mine.size(), 2u) << gap;
      EXPECT_EQ(mine[0].lastFrame, 31) << gap;
      EXPECT_EQ(mine[0].end, MovieEnd::kHidden) << gap;
      EXPECT_EQ(mine[1].firstFrame, 36) << gap;
      EXPECT_EQ(b.moviesContinuedOverGaps(), 0);
    }
  }
}

// The camera moves from 8 m to 4 m in front of a rectangle that starts at about 30 x 30
// pixels: the ideal side doubles (30.3 -> 60.6), crossing 32 x 1.5 = 48, so its 32 x 32 movie
// closes as resized and a 64 x 64 one follows, at the first frame past the threshold.
TEST(TextureIntervalsBuilder, ZoomThatDoublesResolutionResizes) {
  TestScene s;
  double focal = kSize.height / 2.0 / std::tan(0.8 / 2.0);
  double half = 15.15 * 8.0 / focal;  // 30.3 pixels wide at 8 m
  int rect = s.addRect("rect", -half, -half, half, half, -8.0);
  s.move(s.camera, {0, 0, 0}, {0, 0, -4}, 2.0);  // 48 frames
  TextureIntervalsOptions o;
  o.imageSize = kSize;
  o.maxLevel = 0;
  int expected = -1;
  for (int f = 0; f <= 48 && expected < 0; ++f) {
    CameraView v = s.scene.cameraAt(s.camera, f / 24.0);
    Polygon p;
    p.count = 4;
    p.v = {glm::dvec3(-half, -half, -8), glm::dvec3(half, -half, -8), glm::dvec3(half, half, -8),
           glm::dvec3(-half, half, -8)};
    double n = std::sqrt(projectedAreaPixels(v, kSize, p));
    ASSERT_GT(std::abs(n - 48.0), 0.1) << "ambiguous frame " << f;
    if (n > 48.0) expected = f;
  }
  ASSERT_GT(expected, 0);
  std::vector<MovieExtent> all = buildTextureIntervals(s.scene, s.camera, frameRange(0, 48), o);
  PatchHierarchy h(s.scene.inputPolygons());
  std::vector<MovieExtent> mine = moviesOfTop(all, topOfNode(h, rect));
  ASSERT_EQ(mine.size(), 2u);
  EXPECT_EQ(mine[0].width, 32);
  EXPECT_EQ(mine[0].height, 32);
  EXPECT_EQ(mine[0].end, MovieEnd::kResize);
  EXPECT_EQ(mine[0].lastFrame, expected - 1);
  EXPECT_EQ(mine[1].firstFrame, expected);
  EXPECT_EQ(mine[1].width, 64);
  EXPECT_EQ(mine[1].end, MovieEnd::kWindow);
}

// A room no frame shows (issue 58: most rooms of a floor): behind a wall that fills the view, and
// behind the camera. Its tops get no nodes below them (before, every top was subdivided to
// maxLevel, 21 nodes a top at level 2), and the movies are those of the scene without it: the
// item buffers draw its leaves all the same, so they hide what they hid.
TEST(TextureIntervalsBuilder, TopsNoFrameShowsAreNotSubdivided) {
  auto scene = [](bool withHiddenRoom) {
    TestScene s;
    s.addRect("wall", -20.0, -20.0, 20.0, 20.0, -10.0);
    int box = s.addRect("box", -1.0, -1.0, 1.0, 1.0, -5.0);
    s.move(box, {-2.0, 0.0, 0.0}, {2.0, 0.0, 0.0}, 0.5);
    if (withHiddenRoom)
      for (int k = 0; k < 40; ++k) {
        const double x = -8.0 + 0.4 * k;
        s.addRect("behind the wall", x, -1.0, x + 0.3, 1.0, -15.0);
        s.addRect("behind the camera", x, -1.0, x + 0.3, 1.0, 5.0);
      }
    return s;
  };
  TextureIntervalsOptions o;
  o.imageSize = kSize;
  TestScene with = scene(true), without = scene(false);
  TextureIntervalsBuilder b(with.scene, with.camera, o);
  TextureIntervalsBuilder reference(without.scene, without.camera, o);
  for (int f = 0; f < 12; ++f) {
    b.addFrame(f);
    reference.addFrame(f);
  }
  const int tops = b.hierarchy().topCount();
  ASSERT_EQ(tops, 82);
  EXPECT_EQ(b.fullNodeCount(), uint64_t(tops) * 21u);
  EXPECT_EQ(b.topsSeen(), 2) << "the wall and the box";
  EXPECT_EQ(b.hierarchy().size(), tops + 2 * 20);
  // The wall and the box come first: the same top indices, so the same patch ids.
  std::vector<MovieExtent> movies = b.finish(), expected = reference.finish();
  ASSERT_FALSE(expected.empty());
  EXPECT_EQ(movies, expected);
}

// A rectangle mostly (60 %) outside the frustum has a visible fraction below theta: it is
// represented by its children inside the frustum; the children wholly outside get nothing.
TEST(TextureIntervalsBuilder, PatchHalfOutsideTheFrustumIsRepresentedByChildren) {
  TestScene s;
  // Image half-width at z = -5: 5 tan(0.4) x aspect.
  double edge = 5.0 * std::tan(0.4) * kSize.aspect();
  double w = 2.0;
  int rect = s.addRect("rect", edge - 0.4 * w, -1.0, edge + 0.6 * w, 1.0, -5.0);
  TextureIntervalsOptions o;
  o.imageSize = kSize;
  o.maxLevel = 1;
  TextureIntervalsBuilder b(s.scene, s.camera, o);
  int top = topOfNode(b.hierarchy(), rect);
  std::vector<int> chosen;
  b.addFrame(0, [&](const IntervalFrame& f) { chosen = *f.chosen; });
  std::vector<MovieExtent> all = b.finish();
  ASSERT_EQ(chosen.size(), 2u);
  for (int i : chosen) {
    EXPECT_EQ(b.hierarchy().node(i).parent, top);
    EXPECT_EQ(b.hierarchy().node(i).id.level(), 1);
  }
  ASSERT_EQ(all.size(), 2u);
  // The same rectangle fully inside the view is represented by itself.
  TestScene inside;
  int r2 = inside.addRect("rect", -1.0, -1.0, 1.0, 1.0, -5.0);
  TextureIntervalsBuilder b2(inside.scene, inside.camera, o);
  b2.addFrame(0, [&](const IntervalFrame& f) { chosen = *f.chosen; });
  ASSERT_EQ(chosen.size(), 1u);
  EXPECT_EQ(chosen[0], topOfNode(b2.hierarchy(), r2));
}

// Issue 16: the same rectangle, 60 % outside the frustum, but far away and small, covers fewer
// pixels than its children's smallest textures would hold (4 x 4^2): it keeps one texture, one
// movie, instead of going down to its children (what made the 10k-triangle hall's 75,727
// movies).
TEST(TextureIntervalsBuilder, TinyPartlyVisiblePatchKeepsOneTexture) {
  TestScene s;
  const double z = -20.0, edge = -z * std::tan(0.4) * kSize.aspect(), w = 0.4;
  int rect = s.addRect("rect", edge - 0.4 * w, -0.2, edge + 0.6 * w, 0.2, z);
  TextureIntervalsOptions o;
  o.imageSize = kSize;
  o.maxLevel = 1;
  TextureIntervalsBuilder b(s.scene, s.camera, o);
  std::vector<int> chosen;
  long visiblePixels = 0;
  b.addFrame(0, [&](const IntervalFrame& f) {
    chosen = *f.chosen;
    visiblePixels = (*f.visiblePixels)[size_t(topOfNode(b.hierarchy(), rect))];
  });
  ASSERT_GT(visiblePixels, 0) << "it is on screen";
  ASSERT_LT(visiblePixels, 64) << "and small";
  ASSERT_EQ(chosen.size(), 1u);
  EXPECT_EQ(chosen[0], topOfNode(b.hierarchy(), rect));
}

// But a big near patch almost out of the frustum, a sliver of it left at the image's edge, goes
// down to its children: its whole-area texture is large (the 10k-triangle hall's floor tiles
// took 181-256 texels a side for the one frame before they left the view, ~1 s of rad-movies
// each), and the children holding the sliver need a fraction of its texels.
TEST(TextureIntervalsBuilder, BigPatchLeavingTheFrustumGoesToItsChildren) {
  TestScene s;
  const double z = -2.0, edge = -z * std::tan(0.4) * kSize.aspect(),
               pixel = -z * std::tan(0.4) / 60;
  // 28 pixels tall, 1.5 pixels of it on screen, 280 beyond the right edge.
  int rect = s.addRect("rect", edge - 1.5 * pixel, -0.2, edge + 280 * pixel, 0.2, z);
  TextureIntervalsOptions o;
  o.imageSize = kSize;
  o.maxLevel = 1;
  TextureIntervalsBuilder b(s.scene, s.camera, o);
  const PatchHierarchy& h = b.hierarchy();
  std::vector<int> chosen;
  long visiblePixels = 0;
  double wholeArea = 0.0;
  b.addFrame(0, [&](const IntervalFrame& f) {
    chosen = *f.chosen;
    for (int t = 0; t < h.topCount(); ++t)
      if (h.top(t).node == rect && (*f.visiblePixels)[size_t(t)] > 0) {
        visiblePixels += (*f.visiblePixels)[size_t(t)];
        wholeArea = std::max(wholeArea, (*f.projectedArea)[size_t(t)]);
      }
  });
  const std::vector<MovieExtent> all = b.finish();
  ASSERT_GT(visiblePixels, 0) << "it is on screen";
  ASSERT_LT(visiblePixels, 64) << "on fewer pixels than four smallest textures hold";
  const int ownSide = textureSideFor(wholeArea, 0, o);
  ASSERT_GT(ownSide, 4 * o.minSize) << "and its own texture is big";
  ASSERT_FALSE(chosen.empty());
  for (int i : chosen) EXPECT_EQ(h.node(i).id.level(), 1) << "its children hold the sliver";
  long texels = 0;
  for (const MovieExtent& m : all) texels += long(m.width) * m.height;
  // Its own texture has its shape (TextureShape: 10 times longer than tall); the two children
  // holding the sliver, half as long each, round up on the ladder by up to sqrt 2 per axis.
  const TextureSize own = textureSizeFor(wholeArea, textureShapeOf(h.top(0).local), {}, o);
  EXPECT_GT(own.width, 4 * own.height) << "the rectangle's texture runs along it";
  EXPECT_LT(texels, long(own.width) * own.height)
      << "in fewer texels than the whole patch's texture";
}

// A rectangle straddling the right image edge while the camera sways: its visible fraction
// swings between 0.6 and 0.4 around theta = 0.5. The paper's rule switches level at every
// swing; with a level hysteresis of 0.15 it keeps its first (top-level) movie throughout.
TEST(TextureIntervalsBuilder, LevelHysteresisKeepsTheLevelNearTheta) {
  TestScene s;
  double edge = 5.0 * std::tan(0.4) * kSize.aspect();
  double w = 2.0;
  int rect = s.addRect("rect", edge - 0.5 * w, -1.0, edge + 0.5 * w, 1.0, -5.0);
  AnimationChannel ch;
  ch.node = s.camera;
  ch.path = AnimationPath::kTranslation;
  ch.interpolation = Interpolation::kStep;
  for (int k = 0; k < 5; ++k) {
    ch.times.push_back(k * 6 / 24.0);
    double c = (k % 2 == 0 ? 0.1 : -0.1) * w;  // fraction 0.5 + c / w
    ch.values.insert(ch.values.end(), {c, 0.0, 0.0});
  }
  s.scene.channels.push_back(ch);
  TextureIntervalsOptions o;
  o.imageSize = kSize;
  o.maxLevel = 1;
  PatchHierarchy h(s.scene.inputPolygons());
  int top = topOfNode(h, rect);
  auto levelChanges = [&](double hysteresis) {
    o.levelHysteresis = hysteresis;
    std::vector<MovieExtent> all = buildTextureIntervals(s.scene, s.camera, frameRange(0, 29), o);
    int n = 0;
    for (const MovieExtent& m : moviesOfTop(all, top)) n += m.end == MovieEnd::kLevelChange;
    return std::make_pair(n, moviesOfTop(all, top));
  };
  EXPECT_GE(levelChanges(0.0).first, 4);
  auto [changes, movies] = levelChanges(0.15);
  EXPECT_EQ(changes, 0);
  ASSERT_EQ(movies.size(), 1u);
  EXPECT_EQ(movies[0].patch.level(), 0);
  EXPECT_EQ(movies[0].firstFrame, 0);
  EXPECT_EQ(movies[0].lastFrame, 29);
  // From scratch (one-frame movies) each frame chooses by theta alone: the same movies whatever
  // the hysteresis, children in the frames where less than half is seen.
  o.maxLength = 1;
  const std::vector<MovieExtent> paper = levelChanges(0.0).second;
  const std::vector<MovieExtent> scratch = levelChanges(0.4).second;
  ASSERT_EQ(scratch.size(), paper.size());
  int children = 0;
  for (size_t i = 0; i < paper.size(); ++i) {
    EXPECT_EQ(scratch[i].patch.packed(), paper[i].patch.packed()) << i;
    EXPECT_EQ(scratch[i].firstFrame, paper[i].firstFrame) << i;
    children += paper[i].patch.level() == 1;
  }
  EXPECT_GT(children, 0);
}

TEST(TextureIntervalsBuilder, MaxLengthSplitsMovies) {
  TestScene s;
  int rect = s.addRect("rect", -1.0, -1.0, 1.0, 1.0, -5.0);
  TextureIntervalsOptions o;
  o.imageSize = kSize;
  o.maxLength = 10;
  std::vector<MovieExtent> all = buildTextureIntervals(s.scene, s.camera, frameRange(3, 27), o);
  PatchHierarchy h(s.scene.inputPolygons());
  std::vector<MovieExtent> mine = moviesOfTop(all, topOfNode(h, rect));
  ASSERT_EQ(mine.size(), 3u);
  EXPECT_EQ(mine[0].firstFrame, 3);
  EXPECT_EQ(mine[0].lastFrame, 12);
  EXPECT_EQ(mine[0].end, MovieEnd::kMaxLength);
  EXPECT_EQ(mine[1].firstFrame, 13);
  EXPECT_EQ(mine[1].lastFrame, 22);
  EXPECT_EQ(mine[2].firstFrame, 23);
  EXPECT_EQ(mine[2].lastFrame, 27);
  EXPECT_EQ(mine[2].end, MovieEnd::kWindow);
}

TEST(TextureIntervalsBuilder, EdgeCasesGiveNoMoviesOrValidOnes) {
  // A scene with nothing but the camera.
  TestScene empty;
  TextureIntervalsOptions o;
  o.imageSize = kSize;
  EXPECT_TRUE(buildTextureIntervals(empty.scene, empty.camera, {0}, o).empty());
  // One frame, 1 x 1 textures, a frame far from zero (time precision).
  TestScene s;
  s.addRect("rect", -1.0, -1.0, 1.0, 1.0, -5.0);
  o.minSize = o.maxSize = 1;
  std::vector<MovieExtent> one = buildTextureIntervals(s.scene, s.camera, {100000}, o);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].firstFrame, 100000);
  EXPECT_EQ(one[0].lastFrame, 100000);
  EXPECT_EQ(one[0].width, 1);
  EXPECT_EQ(one[0].end, MovieEnd::kWindow);
  // Seen from behind (one-sided patch): visible nowhere, so no movie.
  TestScene behind;
  behind.addRect("rect", -1.0, -1.0, 1.0, 1.0, -5.0);
  behind.scene.nodes[behind.camera].translation = {0, 0, -10};
  behind.scene.nodes[behind.camera].rotation = glm::dquat(0.0, 0.0, 1.0, 0.0);  // turn around
  ASSERT_TRUE(
      projectToPixel(behind.scene.cameraAt(behind.camera, 0.0), kSize, {0, 0, -5}).inFrustum);
  EXPECT_TRUE(buildTextureIntervals(behind.scene, behind.camera, {0}, o).empty());
  // Frames must increase; a node that is not a camera is refused.
  TextureIntervalsBuilder b(s.scene, s.camera, o);
  b.addFrame(3);
  EXPECT_THROW(b.addFrame(3), Error);
  EXPECT_THROW(TextureIntervalsBuilder(s.scene, 1, o), Error);
}

std::string cornellPath() {
  return RAD_SOURCE_DIR "/pipelines/scenes/cornell-moving.gltf";
}

// The invariants rad-compose and rad-movies rely on, checked frame by frame:
//  * every visible pixel is covered by exactly one chosen node, an ancestor-or-self of its
//    leaf, and each chosen (frame, node) lies in exactly one movie of that node;
//  * movies are ordered by (firstFrame, patch), sizes are within [minSize, maxSize];
//  * each close reason is what happened at the next frame.
// Returns the number of visible pixels checked.
long checkInvariants(const Scene& scene, int camera, const std::vector<int>& frames,
                     const TextureIntervalsOptions& o) {
  TextureIntervalsBuilder b(scene, camera, o);
  const PatchHierarchy& h = b.hierarchy();
  std::set<std::pair<int, uint64_t>> uses;  // (frame, packed patch) of every chosen node
  long pixels = 0;
  for (int frame : frames) {
    b.addFrame(frame, [&](const IntervalFrame& f) {
      std::vector<char> isChosen(h.size(), 0);
      for (int i : *f.chosen) isChosen[i] = 1;
      for (uint32_t id : f.itemBuffer->id) {
        if (id == kNoItem) continue;
        int covering = 0;
        const int leaf = b.nodeOfItem(id);
        ASSERT_GE(leaf, 0) << "frame " << f.frame << ": id " << id << " shows no leaf made";
        for (int n = leaf; n >= 0; n = h.node(n).parent) covering += isChosen[n];
        ASSERT_EQ(covering, 1) << "frame " << f.frame << " leaf " << id - 1;
        ++pixels;
      }
      for (size_t c = 0; c < f.chosen->size(); ++c) {
        int node = (*f.chosen)[c];
        EXPECT_GT((*f.visiblePixels)[node], 0);
        uses.insert({f.frame, h.node(node).id.packed()});
        ASSERT_GE((*f.chosenMovie)[c], 0);
      }
    });
  }
  std::vector<MovieExtent> all = b.finish();
  for (auto [frame, packed] : uses) {
    int n = 0;
    for (const MovieExtent& m : all)
      n += m.patch.packed() == packed && m.firstFrame <= frame && frame <= m.lastFrame;
    EXPECT_EQ(n, 1) << "frame " << frame << " patch " << PatchId::fromPacked(packed).toString();
  }
  auto related = [](const PatchId& p, const PatchId& q) {  // the same node, or relatives
    if (q.top != p.top) return false;
    PatchId deep = q.level() > p.level() ? q : p, shallow = q.level() > p.level() ? p : q;
    while (deep.level() > shallow.level()) deep = deep.parent();
    return deep == shallow;
  };
  // A node or any relative (ancestor or descendant) chosen at a frame.
  auto relativeUsed = [&](const PatchId& p, int frame) {
    for (auto it = uses.lower_bound({frame, 0}); it != uses.end() && it->first == frame; ++it) {
      PatchId q = PatchId::fromPacked(it->second);
      if (!(q == p) && related(p, q)) return true;
    }
    return false;
  };
  // A movie starts and ends at frames where its node is chosen; in between (with a frame step,
  // movies also span the skipped frames: the processed ones count), a frame where it is not
  // chosen is a hidden gap: no relative chosen, at most hiddenGap such frames in a row.
  for (const MovieExtent& m : all) {
    EXPECT_EQ(uses.count({m.firstFrame, m.patch.packed()}), 1u);
    EXPECT_EQ(uses.count({m.lastFrame, m.patch.packed()}), 1u);
    int gap = 0;
    for (int f : frames) {
      if (f < m.firstFrame || f > m.lastFrame) continue;
      if (uses.count({f, m.patch.packed()})) {
        gap = 0;
        continue;
      }
      EXPECT_FALSE(relativeUsed(m.patch, f)) << "frame " << f;
      EXPECT_LE(++gap, o.hiddenGap) << "frame " << f;
    }
  }
  // No two movies of one node, or of a node and a relative, share a frame.
  for (size_t i = 0; i < all.size(); ++i)
    for (size_t j = i + 1; j < all.size() && all[j].firstFrame <= all[i].lastFrame; ++j)
      EXPECT_FALSE(related(all[i].patch, all[j].patch)) << "movies " << i << ", " << j;
  for (size_t i = 0; i < all.size(); ++i) {
    const MovieExtent& m = all[i];
    if (i > 0) {
      bool ordered =
          all[i - 1].firstFrame < m.firstFrame ||
          (all[i - 1].firstFrame == m.firstFrame && all[i - 1].patch.packed() < m.patch.packed());
      EXPECT_TRUE(ordered) << i;
    }
    EXPECT_GE(m.width, o.minSize);
    EXPECT_LE(m.width, o.maxSize);
    EXPECT_GE(m.height, o.minSize);
    EXPECT_LE(m.height, o.maxSize);
    if (o.maxLength > 0) {
      EXPECT_LE(m.lastFrame - m.firstFrame + 1, o.maxLength);
    }
    // Open at the window's last frame: it ends as kWindow, whatever gaps it went over.
    if (m.lastFrame == frames.back()) {
      EXPECT_EQ(m.end, MovieEnd::kWindow) << i;
    }
    auto after = std::upper_bound(frames.begin(), frames.end(), m.lastFrame);
    int next = after == frames.end() ? m.lastFrame + 1 : *after;
    bool nodeNext = uses.count({next, m.patch.packed()}) > 0;
    switch (m.end) {
      case MovieEnd::kWindow:
        EXPECT_EQ(m.lastFrame, frames.back()) << i;
        break;
      case MovieEnd::kResize:
      case MovieEnd::kMaxLength:
        EXPECT_TRUE(nodeNext) << i;
        break;
      case MovieEnd::kLevelChange:
        EXPECT_FALSE(nodeNext) << i;
        EXPECT_TRUE(relativeUsed(m.patch, next)) << i;
        break;
      case MovieEnd::kHidden:
      case MovieEnd::kLeftFrustum:
        EXPECT_FALSE(nodeNext) << i;
        EXPECT_FALSE(relativeUsed(m.patch, next)) << i;
        break;
    }
  }
  return pixels;
}

TEST(TextureIntervalsBuilder, EveryVisiblePixelOfCornellIsCoveredByExactlyOneMovie) {
  Scene scene = readGltfScene(cornellPath());
  TextureIntervalsOptions o;
  o.imageSize = kSize;
  EXPECT_GT(checkInvariants(scene, scene.cameraNode(""), frameRange(0, 23), o),
            24L * kSize.pixelCount() / 2);
  // Other options: deeper, hysteresis on both level and size, limited length.
  o.maxLevel = 3;
  o.levelHysteresis = 0.15;
  o.resizeTolerance = 0.0;
  o.maxLength = 5;
  o.minSize = 2;
  o.maxSize = 64;
  EXPECT_GT(checkInvariants(scene, scene.cameraNode(""), frameRange(40, 63), o), 0);
}

// Triangles (subdivided into 4 with an inverted centre child), occlusion, a pan and a step.
TEST(TextureIntervalsBuilder, InvariantsHoldWithTrianglesOccludersAndSteps) {
  TestScene s;
  Mesh tri;
  tri.name = "tri";
  MeshTriangle t;
  t.p = {glm::dvec3(-3, -2, -8), glm::dvec3(3, -2, -8), glm::dvec3(0, 3, -8)};
  t.material = 0;
  tri.triangles = {t};
  s.scene.meshes.push_back(tri);
  Node n;
  n.name = "tri";
  n.mesh = int(s.scene.meshes.size()) - 1;
  s.addNode(n);
  s.addRect("wall", -6, -4, 6, 4, -12);
  int occluder = s.addRect("occluder", -0.7, -0.7, 0.7, 0.7, -4.0);
  s.move(occluder, {-4, 0, 0}, {4, 0.5, 0}, 2.0);
  s.move(s.camera, {-1, 0, 0}, {1.5, 0.3, 1}, 2.0);
  TextureIntervalsOptions o;
  o.imageSize = kSize;
  o.maxLevel = 3;
  for (int gap : {0, 2, 6}) {
    o.hiddenGap = gap;
    EXPECT_GT(checkInvariants(s.scene, s.camera, frameRange(0, 47), o), 24L * kSize.pixelCount());
  }
  std::vector<int> stepped;
  for (int f = 0; f <= 48; f += 3) stepped.push_back(f);
  o.levelHysteresis = 0.1;
  EXPECT_GT(checkInvariants(s.scene, s.camera, stepped, o), 0);
}

// Tiles on a wall behind a fence of slats sliding past: the small tiles and the large tiles'
// children (chosen while the large tiles are partly hidden) are hidden for a few frames at a
// time, so movies are kept over hidden gaps and ended by gaps too long or by a relative chosen
// in them, and hidden children come back after their parent was chosen in between (without the
// builder's relative rule their kept movies overlap their parent's: 40 failed checks).
TEST(TextureIntervalsBuilder, InvariantsHoldBehindASlidingFence) {
  TestScene s;
  s.addRect("wall", -6, -4, 6, 4, -12);
  for (int i = 0; i < 8; ++i) {
    const double x = -5.0 + 1.4 * i, half = i % 2 ? 0.2 : 0.6;
    for (double y : {-3.0, 3.0}) s.addRect("tile", x - half, y - half, x + half, y + half, -11.9);
  }
  for (int i = 0; i < 4; ++i) s.addRect("large", -5.2 + 2.8 * i, -1.0, -3.2 + 2.8 * i, 1.0, -11.9);
  for (int k = 0; k < 5; ++k) {
    int slat = s.addRect("slat", -0.3, -3.0, 0.3, 3.0, -4.0);
    s.move(slat, {-6.0 + 0.8 * k, 0, 0}, {-2.0 + 0.8 * k, 0, 0}, 2.0);
  }
  TextureIntervalsOptions o;
  o.imageSize = kSize;
  for (int gap : {0, 2, 6}) {
    o.hiddenGap = gap;
    EXPECT_GT(checkInvariants(s.scene, s.camera, frameRange(0, 47), o), 24L * kSize.pixelCount());
    TextureIntervalsBuilder b(s.scene, s.camera, o);
    for (int f : frameRange(0, 47)) b.addFrame(f);
    if (gap == 0)
      EXPECT_EQ(b.moviesContinuedOverGaps(), 0);
    else
      EXPECT_GT(b.moviesContinuedOverGaps(), 0) << gap;
  }
}

TEST(TextureIntervalsBuilder, BitIdenticalAcrossRuns) {
  Scene scene = readGltfScene(cornellPath());
  TextureIntervalsOptions o;
  o.imageSize = kSize;
  std::vector<MovieExtent> a =
      buildTextureIntervals(scene, scene.cameraNode(""), frameRange(0, 23), o);
  std::vector<MovieExtent> b =
      buildTextureIntervals(scene, scene.cameraNode(""), frameRange(0, 23), o);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_TRUE(a == b);
  // And the files: same bytes.
  auto write = [&](const std::vector<MovieExtent>& ms, const std::string& path) {
    TextureIntervals iv;
    iv.firstFrame = 0;
    iv.lastFrame = 23;
    iv.imageWidth = kSize.width;
    iv.imageHeight = kSize.height;
    iv.movies = ms;  // the builder's records are the file's
    const char* argv[] = {"rad-intervals", "cornell-moving.gltf"};
    writeTextureIntervals(path, iv, makeProvenance("rad-intervals", 2, argv, {}), {});
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  std::string dir = testing::TempDir();
  std::string fa = write(a, dir + "/rad_iv_a.rti"), fb = write(b, dir + "/rad_iv_b.rti");
  EXPECT_GT(fa.size(), 100u);
  EXPECT_EQ(fa, fb);
  EXPECT_EQ(readTextureIntervals(dir + "/rad_iv_a.rti").movies.size(), a.size());
}

// addFrames draws the item buffers on several GL contexts, one a thread: the same buffers, in
// frame order, and the same movies as addFrame's one context, whatever the count (a step
// between frames and more renderers than there are frames included).
TEST(TextureIntervalsBuilder, ItemBuffersDrawnOnSeveralContextsGiveTheSameMovies) {
  Scene scene = readGltfScene(cornellPath());
  TextureIntervalsOptions o;
  o.imageSize = kSize;
  const int camera = scene.cameraNode("");
  for (const std::vector<int>& frames : {frameRange(0, 23), std::vector<int>{0, 5, 10, 15}}) {
    std::vector<std::vector<uint32_t>> ids;
    std::vector<double> depthSums;
    TextureIntervalsBuilder one(scene, camera, o);
    for (int f : frames)
      one.addFrame(f, [&](const IntervalFrame& fr) {
        ids.push_back(fr.itemBuffer->id);
        double sum = 0.0;
        for (float z : fr.itemBuffer->depth) sum += z;
        depthSums.push_back(sum);
      });
    const std::vector<MovieExtent> expected = one.finish();
    ASSERT_FALSE(expected.empty());
    for (size_t renderers : {size_t(1), size_t(2), size_t(3), size_t(8)}) {
      TextureIntervalsBuilder b(scene, camera, o);
      size_t seen = 0, done = 0;
      b.addFrames(
          frames, renderers,
          [&](const IntervalFrame& fr) {
            ASSERT_LT(seen, frames.size());
            EXPECT_EQ(fr.frame, frames[seen]);
            EXPECT_TRUE(fr.itemBuffer->id == ids[seen]) << "frame " << fr.frame;
            double sum = 0.0;
            for (float z : fr.itemBuffer->depth) sum += z;
            EXPECT_EQ(sum, depthSums[seen]) << "frame " << fr.frame;
            ++seen;
          },
          [&] { ++done; });
      EXPECT_EQ(seen, frames.size()) << renderers << " renderers";
      EXPECT_EQ(done, frames.size());
      EXPECT_EQ(b.framesAdded(), int(frames.size()));
      EXPECT_TRUE(b.finish() == expected) << renderers << " renderers";
    }
  }
}

// An observer that throws stops the workers: the error reaches the caller, nothing hangs.
TEST(TextureIntervalsBuilder, ObserverErrorStopsTheRenderers) {
  Scene scene = readGltfScene(cornellPath());
  TextureIntervalsOptions o;
  o.imageSize = kSize;
  TextureIntervalsBuilder b(scene, scene.cameraNode(""), o);
  int calls = 0;
  EXPECT_THROW(b.addFrames(frameRange(0, 23), 2,
                           [&](const IntervalFrame&) {
                             if (++calls == 3) throw std::runtime_error("observer");
                           }),
               std::runtime_error);
  EXPECT_EQ(calls, 3);
}

// Embree with one-sided triangles (the item buffer culls back faces).
struct EmbreeCaster {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<glm::dvec3> normals;
  std::vector<uint32_t> ids;

  explicit EmbreeCaster(const std::vector<ItemTriangle>& triangles) {
    device = rtcNewDevice(nullptr);
    scene = rtcNewScene(device);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), triangles.size() * 3));
    auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), triangles.size()));
    for (size_t i = 0; i < triangles.size(); ++i) {
      for (int k = 0; k < 3; ++k) {
        for (int c = 0; c < 3; ++c) vb[9 * i + 3 * k + c] = float(triangles[i].p[k][c]);
        ib[3 * i + k] = unsigned(3 * i + k);
      }
      const auto& p = triangles[i].p;
      normals.push_back(glm::cross(p[1] - p[0], p[2] - p[0]));
      ids.push_back(triangles[i].id);
    }
    rtcSetGeometryUserData(g, &normals);
    rtcSetGeometryIntersectFilterFunction(g, &EmbreeCaster::frontFacesOnly);
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);
  }
  ~EmbreeCaster() {
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
  }
  static void frontFacesOnly(const RTCFilterFunctionNArguments* args) {
    const auto& n = *static_cast<const std::vector<glm::dvec3>*>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
      if (args->valid[i] == 0) continue;
      unsigned prim = RTCHitN_primID(args->hit, args->N, i);
      glm::dvec3 dir(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                     RTCRayN_dir_z(args->ray, args->N, i));
      if (glm::dot(n[prim], dir) >= 0.0) args->valid[i] = 0;
    }
  }
  uint32_t cast(const Ray& r) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh{};
    rh.ray.org_x = float(r.origin.x);
    rh.ray.org_y = float(r.origin.y);
    rh.ray.org_z = float(r.origin.z);
    rh.ray.dir_x = float(r.direction.x);
    rh.ray.dir_y = float(r.direction.y);
    rh.ray.dir_z = float(r.direction.z);
    rh.ray.tnear = float(r.tNear);
    rh.ray.tfar = std::isinf(r.tFar) ? std::numeric_limits<float>::infinity() : float(r.tFar);
    rh.ray.mask = ~0u;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return kNoItem;
    return ids[rh.hit.primID];
  }
};

// The item buffer's leaf ids agree with Embree primary rays through the pixel centres, away
// from leaf edges (3 x 3 neighbourhood of one id), at several frames of the moving scene.
TEST(TextureIntervalsBuilder, ItemBufferIdsAgreeWithEmbreeRayCasts) {
  Scene scene = readGltfScene(cornellPath());
  TextureIntervalsOptions o;
  o.imageSize = kSize;
  int camera = scene.cameraNode("");
  TextureIntervalsBuilder b(scene, camera, o);
  const PatchHierarchy& h = b.hierarchy();
  int checked = 0, framesChecked = 0;
  for (int frame : {0, 11, 23, 47, 95}) {
    b.addFrame(frame, [&](const IntervalFrame& f) {
      // The leaves made, by their item ids; the tops not made (no frame showed them yet) whole,
      // with an id no item buffer holds.
      std::vector<ItemTriangle> world;
      for (int i = 0; i < h.size(); ++i) {
        const bool unmadeTop = h.node(i).parent < 0 && h.isLeaf(i) && o.maxLevel > 0;
        if (!h.isLeaf(i)) continue;
        const uint32_t id = unmadeTop ? ~uint32_t(0) : uint32_t(b.numberOf(i) + 1);
        Polygon p = h.node(i).local.transformed(scene.worldTransform(h.topOf(i).node, f.time));
        for (int k = 1; k + 1 < p.count; ++k) world.push_back({{p.v[0], p.v[k], p.v[k + 1]}, id});
      }
      EmbreeCaster caster(world);
      CameraView view = scene.cameraAt(camera, f.time);
      const ItemBuffer& ib = *f.itemBuffer;
      for (int row = 1; row + 1 < ib.height; row += 3)
        for (int col = 1; col + 1 < ib.width; col += 3) {
          uint32_t id = ib.idAt(col, row);
          bool uniform = true;
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) uniform &= ib.idAt(col + dx, row + dy) == id;
          if (!uniform) continue;
          ASSERT_EQ(caster.cast(pixelCentreRay(view, kSize, col, row)), id)
              << "frame " << f.frame << " pixel " << col << "," << row;
          ++checked;
        }
      ++framesChecked;
    });
  }
  EXPECT_EQ(framesChecked, 5);
  EXPECT_GT(checked, 5 * 1000);
}

TEST(ItemBufferExr, RoundTripKeepsIdsAndDepth) {
  ItemBuffer b;
  b.width = 7;
  b.height = 5;
  for (int i = 0; i < 35; ++i) {
    b.id.push_back(i % 4 == 0 ? kNoItem : uint32_t(i * 1000003u));
    b.depth.push_back(i % 4 == 0 ? std::numeric_limits<float>::infinity() : 0.5f + i);
  }
  std::string path = testing::TempDir() + "/rad_ib_test.exr";
  writeItemBufferExr(path, b, 12, 0.5, "{}");
  ItemBuffer r = readItemBufferExr(path);
  EXPECT_EQ(r.width, 7);
  EXPECT_EQ(r.height, 5);
  EXPECT_EQ(r.id, b.id);
  EXPECT_EQ(r.depth, b.depth);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << "not an exr";
  EXPECT_THROW(readItemBufferExr(path), Error);
}

}  // namespace
}  // namespace rad

namespace rad {
namespace {

// docs/design.md §9 scene scale: the Cornell box in millimetres under a 0.001 root scale gives the
// same movies as the same box in metres.
TEST(TextureIntervalsBuilder, SameMoviesAtMillimetreScale) {
  Scene m = readGltfScene(RAD_TEST_DATA "/external/cornell_box/cornell_box.gltf");
  Scene mm = readGltfScene(RAD_TEST_DATA "/external/cornell_box/cornell_box_mm_rootscale.gltf");
  TextureIntervalsOptions o;
  o.imageSize = kSize;
  std::vector<MovieExtent> a = buildTextureIntervals(m, m.cameraNode(""), {0, 1, 2}, o);
  std::vector<MovieExtent> b = buildTextureIntervals(mm, mm.cameraNode(""), {0, 1, 2}, o);
  ASSERT_FALSE(a.empty());
  EXPECT_TRUE(a == b);
}

}  // namespace
}  // namespace rad
