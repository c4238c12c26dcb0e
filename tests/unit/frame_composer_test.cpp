// FrameComposer (paper §3.1 last step): L = Le + rho/pi H from movies, B/pi fallback, pixel
// agreement with the item buffer, texture orientation, sRGB encoding and auto exposure.
#include "libcommon/compose/frame_composer.h"

#include <cmath>
#include <cstring>

#include <gtest/gtest.h>
#include <unistd.h>

#include "formats/texture_movie.h"
#include "tests/unit/compose_fixture.h"

namespace rad {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr ImageSize kSize{64, 48};

class FrameComposerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // One folder per process: ctest -j runs this suite's tests as concurrent processes, which
    // wrote the same files at once (a test was seen skipped by its suite's failed set-up).
    std::string dir = ::testing::TempDir() + "/frame_composer_test_" + std::to_string(::getpid());
    scene = new Scene(readGltfScene(test::writeComposeScene(dir)));
  }
  static void TearDownTestSuite() { delete scene; }
  static Scene* scene;

  // Item buffer of the same scene, straight from ItemBufferRenderer.
  static ItemBuffer itemBuffer() {
    std::vector<ItemTriangle> tris;
    auto tops = scene->inputPolygons();
    for (size_t i = 0; i < tops.size(); ++i) {
      const Polygon& p = tops[i].local;
      for (int k = 1; k + 1 < p.count; ++k)
        tris.push_back({{p.v[0], p.v[k], p.v[k + 1]}, uint32_t(i + 1)});
    }
    return renderItemBuffer(tris, scene->cameraAt(scene->cameraNode(""), 0.0), kSize);
  }
  static glm::dvec3 pixel(const ComposedFrame& f, size_t p) {
    return {f.rgb[3 * p], f.rgb[3 * p + 1], f.rgb[3 * p + 2]};
  }
};
Scene* FrameComposerTest::scene = nullptr;

void expectRel(const glm::dvec3& got, const glm::dvec3& want, double rel, const std::string& at) {
  for (int a = 0; a < 3; ++a)
    EXPECT_NEAR(got[a], want[a], rel * std::abs(want[a]) + 1e-30) << at << " channel " << a;
}

TEST_F(FrameComposerTest, SceneIsWhatTheTestsAssume) {
  auto tops = scene->inputPolygons();
  ASSERT_EQ(tops.size(), 2u);
  EXPECT_EQ(tops[test::kWallTop].local.count, 4);
  EXPECT_EQ(scene->materials[tops[test::kLampTop].material].emission, test::kLampEmission);
  EXPECT_EQ(scene->materials[tops[test::kWallTop].material].reflectance, glm::dvec3(0.5));
}

TEST_F(FrameComposerTest, ConstantMovieGivesRhoOverPiTimesH) {
  GlobalSolution g =
      test::makeSolution(*scene, {0.0}, false, [](int, int) { return glm::dvec3(0); });
  const glm::dvec3 H(2.0, 4.0, 8.0);
  std::vector<float> tex;
  for (int i = 0; i < 5 * 3; ++i) tex.insert(tex.end(), {float(H.x), float(H.y), float(H.z)});
  // Wall: constant H; lamp: constant H too (L = Le + rho/pi H).
  std::vector<MovieTexture> movies = {{PatchId{test::kWallTop, 1}, 5, 3, tex.data()},
                                      {PatchId{test::kLampTop, 1}, 5, 3, tex.data()}};
  FrameComposer composer(*scene, g, kSize, scene->cameraNode(""));
  ComposedFrame f = composer.compose(0.0, movies);
  ItemBuffer ib = itemBuffer();
  ASSERT_EQ(f.rgb.size(), size_t(kSize.pixelCount()) * 3);
  long long covered = 0, wall = 0, lamp = 0;
  for (size_t p = 0; p < ib.id.size(); ++p) {
    std::string at = "pixel " + std::to_string(p);
    if (ib.id[p] == kNoItem) {
      EXPECT_EQ(pixel(f, p), glm::dvec3(0.0)) << at;
      EXPECT_EQ(f.source[p], PixelSource::kBackground) << at;
      continue;
    }
    ++covered;
    EXPECT_EQ(f.source[p], PixelSource::kMovie) << at;
    if (ib.id[p] == test::kWallTop + 1) {
      ++wall;
      expectRel(pixel(f, p), 0.5 / kPi * H, 1e-5, at);
    } else {
      ++lamp;
      expectRel(pixel(f, p), test::kLampEmission + 0.5 / kPi * H, 1e-5, at);
    }
  }
  EXPECT_GT(wall, 300);
  EXPECT_GT(lamp, 20);
  EXPECT_EQ(f.coveredPixels, covered);
  EXPECT_EQ(f.moviePixels, covered);
  EXPECT_EQ(f.fallbackPixels, 0);
}

TEST_F(FrameComposerTest, EmitterWithZeroIrradianceShowsLe) {
  GlobalSolution g =
      test::makeSolution(*scene, {0.0}, false, [](int, int) { return glm::dvec3(0); });
  std::vector<float> zero(3, 0.0f);
  FrameComposer composer(*scene, g, kSize, scene->cameraNode(""));
  ComposedFrame f = composer.compose(0.0, {{PatchId{test::kLampTop, 1}, 1, 1, zero.data()}});
  ItemBuffer ib = itemBuffer();
  int lamp = 0;
  for (size_t p = 0; p < ib.id.size(); ++p)
    if (ib.id[p] == test::kLampTop + 1) {
      ++lamp;
      expectRel(pixel(f, p), test::kLampEmission, 1e-6, "pixel " + std::to_string(p));
    }
  EXPECT_GT(lamp, 20);
}

TEST_F(FrameComposerTest, NoMovieFallsBackToBOverPiAndCountsEveryCoveredPixel) {
  // Radiosity linear in time between keys 0 s and 1 s; composed at 0.25 s.
  auto B = [](int node, int key) {
    return node == test::kLampTop ? glm::dvec3(kPi * test::kLampEmission) * (1.0 + key)
                                  : glm::dvec3(1.0, 2.0, 3.0) * (1.0 + 3.0 * key);
  };
  GlobalSolution g = test::makeSolution(*scene, {0.0, 1.0}, false, B);
  FrameComposer composer(*scene, g, kSize, scene->cameraNode(""));
  ComposedFrame f = composer.compose(0.25, {});
  ItemBuffer ib = itemBuffer();
  long long covered = 0;
  for (size_t p = 0; p < ib.id.size(); ++p) {
    if (ib.id[p] == kNoItem) {
      EXPECT_EQ(pixel(f, p), glm::dvec3(0.0));
      continue;
    }
    ++covered;
    int top = int(ib.id[p]) - 1;
    glm::dvec3 want = (0.75 * B(top, 0) + 0.25 * B(top, 1)) / kPi;
    expectRel(pixel(f, p), want, 1e-6, "pixel " + std::to_string(p));
    EXPECT_EQ(f.source[p], PixelSource::kFallback);
  }
  EXPECT_GT(covered, 300);
  EXPECT_EQ(f.fallbackPixels, covered);
  EXPECT_EQ(f.coveredPixels, covered);
  EXPECT_EQ(f.moviePixels, 0);
}

// Where a pixel lies in the wall's (u,v), from its centre ray.
glm::dvec2 wallUvAt(const Scene& scene, int col, int row) {
  CameraView view = scene.cameraAt(scene.cameraNode(""), 0.0);
  Ray r = pixelCentreRay(view, kSize, col, row);
  double s = (-5.0 - r.origin.z) / r.direction.z;
  return polygonUvAt(scene.inputPolygons()[test::kWallTop].local, r.origin + s * r.direction);
}

TEST_F(FrameComposerTest, FallbackUsesTheUnionLeafUnderThePixel) {
  // Wall split into 4 children (nodes 2..5) with distinct radiosity.
  auto B = [](int node, int) { return glm::dvec3(10.0 * node + 1.0); };
  GlobalSolution g = test::makeSolution(*scene, {0.0}, true, B);
  FrameComposer composer(*scene, g, kSize, scene->cameraNode(""));
  ComposedFrame f = composer.compose(0.0, {});
  ItemBuffer ib = itemBuffer();
  int checked = 0;
  for (int row = 0; row < kSize.height; ++row)
    for (int col = 0; col < kSize.width; ++col) {
      size_t p = size_t(row) * kSize.width + col;
      if (ib.id[p] != test::kWallTop + 1) continue;
      glm::dvec2 uv = wallUvAt(*scene, col, row);
      if (std::abs(uv.x - 0.5) < 0.02 || std::abs(uv.y - 0.5) < 0.02) continue;  // seams
      int child = uv.y < 0.5 ? (uv.x < 0.5 ? 0 : 1) : (uv.x < 0.5 ? 3 : 2);
      expectRel(pixel(f, p), B(2 + child, 0) / kPi, 1e-6, "pixel " + std::to_string(p));
      ++checked;
    }
  EXPECT_GT(checked, 300);
}

TEST_F(FrameComposerTest, MovieTexelsMapToTheirPatchPoints) {
  // H = 100 u on a 4x1 texture: texel i centre at u = (i+.5)/4, bilinear between centres
  // reproduces the linear function exactly, and so does the lookup in the outer half texel up
  // to the patch's border, which carries the last two texels on (held flat, clamp-to-edge, it
  // was off by up to 12 % of the range there); row j = 0 is v = 0, so a 1x4 texture in v checks
  // the other axis.
  GlobalSolution g =
      test::makeSolution(*scene, {0.0}, false, [](int, int) { return glm::dvec3(0); });
  constexpr int n = 4;
  std::vector<float> ramp;
  for (int i = 0; i < n; ++i) {
    float h = float(100.0 * (i + 0.5) / n);
    ramp.insert(ramp.end(), {h, h, h});
  }
  FrameComposer composer(*scene, g, kSize, scene->cameraNode(""));
  for (int axis = 0; axis < 2; ++axis) {
    MovieTexture mt{PatchId{test::kWallTop, 1}, axis == 0 ? n : 1, axis == 0 ? 1 : n, ramp.data()};
    ComposedFrame f = composer.compose(0.0, {mt});
    ItemBuffer ib = itemBuffer();
    int checked = 0, border = 0;
    for (int row = 0; row < kSize.height; ++row)
      for (int col = 0; col < kSize.width; ++col) {
        size_t p = size_t(row) * kSize.width + col;
        if (ib.id[p] != test::kWallTop + 1) continue;
        double u = wallUvAt(*scene, col, row)[axis];
        double want = 0.5 / kPi * 100.0 * u;
        EXPECT_NEAR(pixel(f, p).x, want, 1e-4 * want + 1e-9)
            << col << "," << row << " axis " << axis;
        ++checked;
        border += u < 0.5 / n || u > 1 - 0.5 / n;
      }
    EXPECT_GT(checked, 250);
    EXPECT_GT(border, 10);
  }
}

// Between the last texel centres and the patch's edge (the border half texel) the texture goes
// on linearly: H = 100 u is reproduced up to u = 0 and u = 1. Clamped to the edge, as GL's
// CLAMP_TO_EDGE, the border held the value half a texel inside, and two patches meeting at an
// edge stepped there by the gradient times a texel (issue 56).
TEST_F(FrameComposerTest, TheBorderHalfTexelContinuesTheTextureLinearly) {
  GlobalSolution g =
      test::makeSolution(*scene, {0.0}, false, [](int, int) { return glm::dvec3(0); });
  std::vector<float> ramp;
  for (int i = 0; i < 4; ++i) {
    float h = float(100.0 * (i + 0.5) / 4);
    ramp.insert(ramp.end(), {h, h, h});
  }
  FrameComposer composer(*scene, g, kSize, scene->cameraNode(""));
  const ComposedFrame f = composer.compose(0.0, {{PatchId{test::kWallTop, 1}, 4, 1, ramp.data()}});
  ItemBuffer ib = itemBuffer();
  int checked = 0;
  for (int row = 0; row < kSize.height; ++row)
    for (int col = 0; col < kSize.width; ++col) {
      size_t p = size_t(row) * kSize.width + col;
      if (ib.id[p] != test::kWallTop + 1) continue;
      double u = wallUvAt(*scene, col, row).x;
      if (u >= 0.5 / 4 && u <= 1 - 0.5 / 4) continue;  // inside: MovieTexelsMapToTheirPatchPoints
      double want = 0.5 / kPi * 100.0 * u;
      EXPECT_NEAR(pixel(f, p).x, want, 1e-4 * want + 1e-6) << col << "," << row;
      ++checked;
    }
  EXPECT_GT(checked, 10);
}

// The four children of the wall, each its own 4 x 4 movie of H = 100 u + 50 v at its texels'
// points, compose into the one linear field: no step where the children's textures meet.
TEST_F(FrameComposerTest, SiblingMoviesMeetWithoutAStep) {
  GlobalSolution g =
      test::makeSolution(*scene, {0.0}, false, [](int, int) { return glm::dvec3(0); });
  std::vector<std::vector<float>> tex(4);
  std::vector<MovieTexture> movies;
  for (int c = 0; c < 4; ++c) {
    const PatchId child = PatchId{test::kWallTop, 1}.child(c);
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        const glm::dvec2 uv = topUvFromNodeUv(child, {(i + 0.5) / 4, (j + 0.5) / 4}, false);
        const float h = float(100.0 * uv.x + 50.0 * uv.y);
        tex[size_t(c)].insert(tex[size_t(c)].end(), {h, h, h});
      }
    movies.push_back({child, 4, 4, tex[size_t(c)].data()});
  }
  FrameComposer composer(*scene, g, kSize, scene->cameraNode(""));
  const ComposedFrame f = composer.compose(0.0, movies);
  ItemBuffer ib = itemBuffer();
  int checked = 0;
  for (int row = 0; row < kSize.height; ++row)
    for (int col = 0; col < kSize.width; ++col) {
      size_t p = size_t(row) * kSize.width + col;
      if (ib.id[p] != test::kWallTop + 1) continue;
      const glm::dvec2 uv = wallUvAt(*scene, col, row);
      double want = 0.5 / kPi * (100.0 * uv.x + 50.0 * uv.y);
      EXPECT_NEAR(pixel(f, p).x, want, 1e-4 * want + 1e-6) << col << "," << row;
      ++checked;
    }
  EXPECT_GT(checked, 300);
}

TEST_F(FrameComposerTest, SubPatchMovieCoversItsQuarterAndTheRestFallsBack) {
  auto B = [](int, int) { return glm::dvec3(kPi); };  // fallback L = 1
  GlobalSolution g = test::makeSolution(*scene, {0.0}, false, B);
  std::vector<float> h(3, float(4.0 * kPi));             // movie L = 0.5/pi * 4 pi = 2
  PatchId child2 = PatchId{test::kWallTop, 1}.child(2);  // (u,v) in [.5,1]^2
  FrameComposer composer(*scene, g, kSize, scene->cameraNode(""));
  ComposedFrame f = composer.compose(0.0, {{child2, 1, 1, h.data()}});
  ItemBuffer ib = itemBuffer();
  int movie = 0, fallback = 0;
  for (int row = 0; row < kSize.height; ++row)
    for (int col = 0; col < kSize.width; ++col) {
      size_t p = size_t(row) * kSize.width + col;
      if (ib.id[p] != test::kWallTop + 1) continue;
      glm::dvec2 uv = wallUvAt(*scene, col, row);
      if (std::abs(uv.x - 0.5) < 0.02 || std::abs(uv.y - 0.5) < 0.02) continue;
      bool inChild = uv.x > 0.5 && uv.y > 0.5;
      EXPECT_NEAR(pixel(f, p).x, inChild ? 2.0 : 1.0, 1e-5) << col << "," << row;
      (inChild ? movie : fallback)++;
    }
  EXPECT_GT(movie, 50);
  EXPECT_GT(fallback, 150);
  EXPECT_EQ(f.moviePixels + f.fallbackPixels, f.coveredPixels);
}

// Two keys blended per sampled texel (MovieTexture::nextIrradiance, weight) give exactly the
// frame of the texture blended beforehand as TextureMovie::textureAt does: rad-compose's
// frames did not change by one bit when it stopped copying the blend (32-cube scene: 41 MB).
TEST_F(FrameComposerTest, PerTexelKeyBlendIsBitIdenticalToTheBlendedTexture) {
  GlobalSolution g =
      test::makeSolution(*scene, {0.0}, false, [](int, int) { return glm::dvec3(0); });
  const int w = 7, h = 5;
  TextureMovie m;
  m.width = w;
  m.height = h;
  m.keyTimes = {0.0, 0.37};
  for (int k = 0; k < 2; ++k) {
    std::vector<float> key(size_t(w) * h * 3);
    for (size_t i = 0; i < key.size(); ++i)
      key[i] = 3.0f + std::sin(float(i) * 0.61f + 1.7f * float(k)) * 2.9f;
    m.keys.push_back(key);
  }
  FrameComposer composer(*scene, g, kSize, scene->cameraNode(""));
  const PatchId wall{test::kWallTop, 1};
  int differing = 0;
  for (double t : {0.01, 0.1, 0.2333, 0.36}) {
    std::vector<float> blended;
    m.textureAt(t, blended);
    ComposedFrame want = composer.compose(t, {{wall, w, h, blended.data()}});
    MovieTexture two{wall, w, h, m.keys[0].data(), m.keys[1].data(), m.keyWeight(t, 0, 1)};
    ComposedFrame got = composer.compose(t, {two});
    ASSERT_EQ(got.rgb.size(), want.rgb.size());
    EXPECT_EQ(0, std::memcmp(got.rgb.data(), want.rgb.data(), got.rgb.size() * sizeof(float))) << t;
    EXPECT_EQ(got.moviePixels, want.moviePixels);
    EXPECT_GT(got.moviePixels, 300);
    // The blend matters: key 0 alone gives another frame (the test could fail).
    ComposedFrame first = composer.compose(t, {{wall, w, h, m.keys[0].data()}});
    differing += first.rgb != want.rgb;
  }
  EXPECT_EQ(differing, 4);
}

TEST_F(FrameComposerTest, DeterministicAcrossCalls) {
  GlobalSolution g =
      test::makeSolution(*scene, {0.0}, true, [](int n, int) { return glm::dvec3(0.1 * n + 0.3); });
  FrameComposer composer(*scene, g, kSize, scene->cameraNode(""));
  ComposedFrame a = composer.compose(0.0, {}), b = composer.compose(0.0, {});
  EXPECT_EQ(a.rgb, b.rgb);
}

TEST_F(FrameComposerTest, BaseColourTextureModulatesMovieAndFallback) {
  // The wall gets a 1x2 base colour texture (row 0 at glTF v = 0, the top of the wall) with
  // baseColorFactor 0.5: rho(x) = 0.5 tex(x); Material::reflectance holds 0.5 mean(tex).
  Scene s = *scene;
  Texture tex;
  tex.width = 1;
  tex.height = 2;
  tex.rgb = {0.2f, 0.4f, 0.6f, 0.8f, 0.8f, 0.8f};
  tex.mean = glm::dvec3(0.5, 0.6, 0.7);
  s.textures.push_back(tex);
  int wallMaterial = s.inputPolygons()[test::kWallTop].material;
  s.materials[wallMaterial].baseColorTexture = 0;
  s.materials[wallMaterial].reflectance = 0.5 * tex.mean;
  for (Mesh& mesh : s.meshes)
    for (MeshTriangle& t : mesh.triangles)
      for (int k = 0; k < 3; ++k) t.uv[k] = {(t.p[k].x + 1) / 2, (1 - t.p[k].y) / 2};
  const glm::dvec3 B(0.3, 0.6, 0.9), H(2.0, 3.0, 4.0);
  GlobalSolution g = test::makeSolution(s, {0.0}, false, [&](int, int) { return B; });
  std::vector<float> h = {float(H.x), float(H.y), float(H.z)};
  FrameComposer composer(s, g, kSize, s.cameraNode(""));
  ComposedFrame withMovie = composer.compose(0.0, {{PatchId{test::kWallTop, 1}, 1, 1, h.data()}});
  ComposedFrame fallback = composer.compose(0.0, {});
  ItemBuffer ib = itemBuffer();
  CameraView view = s.cameraAt(s.cameraNode(""), 0.0);
  int checked = 0;
  for (int row = 0; row < kSize.height; ++row)
    for (int col = 0; col < kSize.width; ++col) {
      size_t p = size_t(row) * kSize.width + col;
      if (ib.id[p] != test::kWallTop + 1) continue;
      Ray r = pixelCentreRay(view, kSize, col, row);
      double y = r.origin.y + (-5.0 - r.origin.z) / r.direction.z * r.direction.y;
      double v = (1 - y) / 2;
      if (v < 0.3 || v > 0.7) continue;  // bilinear REPEAT wraps outside [.25, .75]
      double w = 2 * v - 0.5;
      glm::dvec3 c = (1 - w) * glm::dvec3(0.2, 0.4, 0.6) + w * glm::dvec3(0.8);
      expectRel(pixel(withMovie, p), 0.5 * c / kPi * H, 1e-5, "movie " + std::to_string(p));
      expectRel(pixel(fallback, p), c / tex.mean * B / kPi, 1e-5, "fallback " + std::to_string(p));
      ++checked;
    }
  EXPECT_GT(checked, 100);
}

TEST_F(FrameComposerTest, MovingPatchCarriesItsTextureAlong) {
  // The wall node slides down 1 m over [0, 1] s; at t = 0.5 it is 0.5 m lower. A ramp H = 100 v
  // (1x16 texture) must follow the surface: value by the pixel's *local* (u,v).
  Scene s = *scene;
  int wallNode = s.inputPolygons()[test::kWallTop].node;
  AnimationChannel ch;
  ch.node = wallNode;
  ch.path = AnimationPath::kTranslation;
  ch.interpolation = Interpolation::kLinear;
  ch.times = {0.0, 1.0};
  ch.values = {0, 0, 0, 0, -1, 0};
  s.channels.push_back(ch);
  GlobalSolution g = test::makeSolution(s, {0.0}, false, [](int, int) { return glm::dvec3(0); });
  std::vector<float> ramp;
  for (int j = 0; j < 16; ++j) {
    float h = float(100.0 * (j + 0.5) / 16);
    ramp.insert(ramp.end(), {h, h, h});
  }
  FrameComposer composer(s, g, kSize, s.cameraNode(""));
  ComposedFrame f = composer.compose(0.5, {{PatchId{test::kWallTop, 1}, 1, 16, ramp.data()}});
  CameraView view = s.cameraAt(s.cameraNode(""), 0.5);
  const Polygon local = s.inputPolygons()[test::kWallTop].local;
  int inside = 0, outside = 0;
  for (int row = 0; row < kSize.height; ++row)
    for (int col = 0; col < kSize.width; ++col) {
      size_t p = size_t(row) * kSize.width + col;
      Ray r = pixelCentreRay(view, kSize, col, row);
      glm::dvec3 world = r.origin + (-5.0 - r.origin.z) / r.direction.z * r.direction;
      glm::dvec3 localPoint = world - glm::dvec3(0, -0.5, 0);
      if (std::abs(localPoint.x) > 1.1 || std::abs(localPoint.y) > 1.1) {
        if (world.x < 1.2) {  // not the lamp
          EXPECT_EQ(pixel(f, p), glm::dvec3(0.0)) << col << "," << row;
          ++outside;
        }
        continue;
      }
      glm::dvec2 uv = polygonUvAt(local, localPoint);
      if (uv.x < 0.05 || uv.x > 0.95 || uv.y < 0.5 / 16 + 0.01 || uv.y > 1 - 0.5 / 16 - 0.01)
        continue;
      EXPECT_EQ(f.source[p], PixelSource::kMovie) << col << "," << row;
      double want = 0.5 / kPi * 100.0 * uv.y;
      EXPECT_NEAR(pixel(f, p).x, want, 1e-4 * want) << col << "," << row;
      ++inside;
    }
  EXPECT_GT(inside, 250);
  EXPECT_GT(outside, 500);
}

TEST(Srgb, EncodeAndExposure) {
  EXPECT_DOUBLE_EQ(srgbEncode(0.0), 0.0);
  EXPECT_DOUBLE_EQ(srgbEncode(1.0), 1.0);
  EXPECT_NEAR(srgbEncode(0.5), 0.735356983, 1e-8);
  EXPECT_NEAR(srgbEncode(0.002), 0.02584, 1e-8);
  EXPECT_DOUBLE_EQ(srgbEncode(7.0), 1.0);
  std::vector<float> rgb = {0.25f, 0.5f, 2.0f, -1.0f, 0.0f, 0.125f};
  std::vector<uint8_t> b = toSrgb8(rgb, 1.0);  // x2
  std::vector<uint8_t> want = {188, 255, 255, 0, 0, 137};
  EXPECT_EQ(b, want);
}

// toSrgb8 at exposure 0 reads thresholds instead of calling pow: the same codes. Every 61st
// float of [0, 1.125] here (the whole range, 1.07e9 floats, was checked once: no difference),
// the floats next to 1, and values that are not finite or negative.
TEST(Srgb, ExposureZeroTableEqualsPowOnFloats) {
  auto pow8 = [](float f) {
    return std::isfinite(f) ? uint8_t(std::lround(255.0 * srgbEncode(double(f)))) : uint8_t(0);
  };
  long checked = 0;
  for (uint32_t u = 0; u <= 0x3F900000u; u += (u > 0x3F7FFF00u && u < 0x3F800100u) ? 1u : 61u) {
    float f;
    std::memcpy(&f, &u, sizeof f);
    ASSERT_EQ(int(srgb8AtExposureZero(f)), int(pow8(f))) << f;
    ++checked;
  }
  EXPECT_GT(checked, 17000000);
  for (float f : {-1.0f, -0.0f, 1e30f, INFINITY, -INFINITY, NAN, 0.0031308f, 1e-40f})
    EXPECT_EQ(int(srgb8AtExposureZero(f)), int(pow8(f))) << f;
  const std::vector<float> rgb = {0.25f, 0.5f, 2.0f, -1.0f, 0.0f, 0.125f, NAN};
  std::vector<uint8_t> want;
  for (float f : rgb) want.push_back(pow8(f));
  EXPECT_EQ(toSrgb8(rgb, 0.0), want);
}

TEST_F(FrameComposerTest, AutoExposureIgnoresEmittersAndDependsOnlyOnTheSolution) {
  // Wall leaves B/pi luminance 0.25; lamp (emitter) much brighter, ignored.
  auto B = [](int node, int) {
    return node == test::kLampTop ? glm::dvec3(1000.0) : glm::dvec3(0.25 * kPi);
  };
  GlobalSolution g = test::makeSolution(*scene, {0.0}, false, B);
  EXPECT_NEAR(autoExposureEV(*scene, g), 2.0, 1e-6);  // 0.25 * 2^2 = 1 (B stored as float)
}

}  // namespace
}  // namespace rad
