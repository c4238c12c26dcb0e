// libcommon/path_tracer: the reference renderer against answers known exactly —
// the uniform furnace of tests/data/reference/furnace.json (closed enclosure, reflectance rho,
// emitted radiosity E everywhere: B = E / (1 - rho), so the radiance seen anywhere is
// B / pi = L_e / (1 - rho)) and a small receiver under a square emitter (L = rho / pi * pi L_e
// * F, F from the exact point-to-polygon form factor). Monte Carlo figures are checked within
// 4 standard errors.
#include "libcommon/reference/path_tracer.h"

#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <nlohmann/json.hpp>

#include "libcommon/radiosity/form_factor.h"

namespace rad {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct TestPolygon {
  std::vector<glm::dvec3> v;  // CCW about the front normal
  int material = 0;
  std::vector<glm::dvec2> uv = {};  // per vertex, or empty
};

// One static mesh node per polygon (fan triangulation keeps the orientation); optional camera.
Scene sceneOf(const std::vector<TestPolygon>& polygons, const std::vector<Material>& materials) {
  Scene s;
  s.path = "test";
  s.materials = materials;
  for (const TestPolygon& p : polygons) {
    Mesh mesh;
    for (size_t k = 1; k + 1 < p.v.size(); ++k) {
      MeshTriangle t;
      t.p = {p.v[0], p.v[k], p.v[k + 1]};
      t.material = p.material;
      if (!p.uv.empty()) t.uv = {p.uv[0], p.uv[k], p.uv[k + 1]};
      mesh.triangles.push_back(t);
    }
    Node node;
    node.mesh = int(s.meshes.size());
    s.meshes.push_back(mesh);
    s.nodes.push_back(node);
  }
  return s;
}

void addCamera(Scene& s, const glm::dvec3& eye, double yfov) {
  Camera lens;
  lens.name = "cam";
  lens.yfov = yfov;
  lens.znear = 0.001;
  s.cameras.push_back(lens);
  Node node;
  node.name = "cam";
  node.camera = 0;
  node.translation = eye;
  s.nodes.push_back(node);
}

Material material(glm::dvec3 rho, glm::dvec3 le, bool doubleSided = false) {
  Material m;
  m.reflectance = rho;
  m.emission = le;
  m.doubleSided = doubleSided;
  return m;
}

std::vector<TestPolygon> furnaceGeometry(const std::string& name) {
  std::ifstream in(std::string(RAD_TEST_DATA) + "/reference/furnace.json");
  nlohmann::json j = nlohmann::json::parse(in);
  std::vector<TestPolygon> polygons;
  for (const auto& patch : j.at("geometries").at(name).at("patches")) {
    TestPolygon p;
    for (const auto& v : patch)
      p.v.emplace_back(v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
    polygons.push_back(p);
  }
  return polygons;
}

// The uniform furnace cases of furnace.json: E = 1 (emitted radiosity), so L_e = 1 / pi.
double furnaceRho(const std::string& caseName) {
  std::ifstream in(std::string(RAD_TEST_DATA) + "/reference/furnace.json");
  nlohmann::json j = nlohmann::json::parse(in);
  for (const auto& c : j.at("cases"))
    if (c.at("name") == caseName) return c.at("rho").get<double>();
  ADD_FAILURE() << "no case " << caseName;
  return 0.0;
}

double furnaceExactB(const std::string& caseName) {
  std::ifstream in(std::string(RAD_TEST_DATA) + "/reference/furnace.json");
  nlohmann::json j = nlohmann::json::parse(in);
  for (const auto& c : j.at("cases"))
    if (c.at("name") == caseName) return c.at("exact_B").at("value").get<double>();
  return 0.0;
}

PathTracerOptions unbiasedOptions() {
  PathTracerOptions o;
  o.maxDepth = 100000;  // Russian roulette alone ends paths: no truncation bias
  return o;
}

struct FurnaceCase {
  const char* caseName;
  const char* geometry;
  glm::dvec3 probe;  // interior point the rays start from
};

class Furnace : public ::testing::TestWithParam<FurnaceCase> {};

TEST_P(Furnace, RadianceIsBOverPiEverywhere) {
  const FurnaceCase fc = GetParam();
  const double rho = furnaceRho(fc.caseName);
  const double E = 1.0, Le = E / kPi;
  const double expected = furnaceExactB(fc.caseName) / kPi;
  ASSERT_NEAR(expected, E / (1.0 - rho) / kPi, 1e-12);
  const std::vector<TestPolygon> patches = furnaceGeometry(fc.geometry);
  Scene scene = sceneOf(patches, {material(glm::dvec3(rho), glm::dvec3(Le))});
  PathTracer tracer(scene, 0.0);
  EXPECT_EQ(tracer.emitterCount(), int(patches.size()));
  const glm::dvec3 dirs[] = {{0.3, 0.2, 0.9}, {-1, 0.1, -0.2}, {0.05, -1, 0.4}};
  double worstSigmas = 0.0;
  for (size_t i = 0; i < 3; ++i) {
    Ray ray;
    ray.origin = fc.probe;
    ray.direction = glm::normalize(dirs[i]);
    ray.tNear = 0.0;
    ray.tFar = std::numeric_limits<double>::infinity();
    RadianceEstimate e = tracer.estimateRadiance(ray, 20000, 1234 + i, unbiasedOptions());
    for (int c = 0; c < 3; ++c) {
      if (rho == 0.0) {
        EXPECT_NEAR(e.mean[c], expected, 1e-12 * expected);  // no reflection, no randomness
        continue;
      }
      const double sigma = e.standardError[c];
      EXPECT_GT(sigma, 0.0);
      EXPECT_LT(sigma, 0.01 * expected) << "estimate too noisy to test anything";
      EXPECT_NEAR(e.mean[c], expected, 4.0 * sigma) << fc.caseName << " " << fc.geometry;
      worstSigmas = std::max(worstSigmas, std::abs(e.mean[c] - expected) / sigma);
    }
    if (i == 0)
      std::printf("  %s %s: L = %.6f +- %.6f (exact %.6f)\n", fc.caseName, fc.geometry, e.mean.x,
                  e.standardError.x, expected);
  }
  std::printf("  %s %s: worst |error| = %.2f sigma\n", fc.caseName, fc.geometry, worstSigmas);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, Furnace,
    ::testing::Values(FurnaceCase{"uniform_furnace_rho0", "unit_cube_6", {0.5, 0.5, 0.5}},
                      FurnaceCase{"uniform_furnace_rho0.5", "unit_cube_6", {0.3, 0.6, 0.2}},
                      FurnaceCase{"uniform_furnace_rho0.9", "unit_cube_6", {0.5, 0.4, 0.7}},
                      FurnaceCase{"uniform_furnace_rho0.9", "box_1x2x3_6", {0.2, 1.7, 0.3}},
                      FurnaceCase{"uniform_furnace_rho0.9", "unit_cube_24", {0.9, 0.1, 0.5}}));

// A whole rendered frame of the furnace: every pixel estimates L_e / (1 - rho); the image mean
// is within 4 standard errors (pixels are independent), and the image does not depend on the
// thread count.
TEST(PathTracer, FurnaceFrameIsUniformAndThreadCountIndependent) {
  const double rho = 0.5, Le = 1.0 / kPi, expected = Le / (1.0 - rho);
  Scene scene =
      sceneOf(furnaceGeometry("unit_cube_6"), {material(glm::dvec3(rho), glm::dvec3(Le))});
  addCamera(scene, {0.5, 0.5, 0.6}, 1.2);
  PathTracer tracer(scene, 0.0);
  const CameraView view = scene.cameraAt(scene.cameraNode(""), 0.0);
  PathTracerOptions o = unbiasedOptions();
  o.samplesPerPixel = 16;
  FloatImage a;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    a = tracer.render(view, {24, 16}, o);
  }
  FloatImage b = tracer.render(view, {24, 16}, o);
  ASSERT_EQ(a.pixels.size(), size_t(24 * 16 * 3));
  EXPECT_EQ(a.pixels, b.pixels) << "thread count changed the image";
  double sum = 0.0, sumSq = 0.0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 24; ++x) {
      const double v = a.at(x, y, 1);
      sum += v;
      sumSq += v * v;
    }
  const double n = 24 * 16, mean = sum / n;
  const double sigma = std::sqrt((sumSq / n - mean * mean) / (n - 1));
  EXPECT_GT(sigma, 0.0);
  EXPECT_NEAR(mean, expected, 4.0 * sigma);
  std::printf("  furnace frame rho 0.5: mean %.6f +- %.6f (exact %.6f)\n", mean, sigma, expected);

  // A different seed changes the noise, not the answer.
  o.seed = 99;
  FloatImage c = tracer.render(view, {24, 16}, o);
  EXPECT_NE(c.pixels, a.pixels);
  // Frames share per-pixel seeds unless asked otherwise.
  EXPECT_EQ(tracer.render(view, {24, 16}, o, 7).pixels, c.pixels);
  o.decorrelateFrames = true;
  EXPECT_NE(tracer.render(view, {24, 16}, o, 7).pixels, c.pixels);
}

// A unit square emitter at height h facing down over a small receiver square facing up.
struct SquareLight {
  double h = 0.7;
  glm::dvec3 le{2.0, 1.0, 0.5};
  glm::dvec3 rho{0.8, 0.5, 0.3};
  glm::dvec3 p{0.3, -0.2, 0.0};  // receiver centre (off-axis)
  double receiverSide = 0.02;

  std::vector<glm::dvec3> emitterFacingDown() const {
    return {{-0.5, -0.5, h}, {-0.5, 0.5, h}, {0.5, 0.5, h}, {0.5, -0.5, h}};
  }
  std::vector<glm::dvec3> receiverFacingUp() const {
    const double s = receiverSide / 2;
    return {p + glm::dvec3(-s, -s, 0), p + glm::dvec3(s, -s, 0), p + glm::dvec3(s, s, 0),
            p + glm::dvec3(-s, s, 0)};
  }
  // A ray that ends on the receiver centre, coming from above at a slant (misses the emitter).
  Ray probe(double side) const {
    Ray r;
    const glm::dvec3 w = glm::normalize(glm::dvec3(1.0, 0.4, side * 0.5));
    r.origin = p + 0.05 * w;
    r.direction = -w;
    r.tNear = 0.0;
    r.tFar = std::numeric_limits<double>::infinity();
    return r;
  }
};

TEST(PathTracer, ReceiverUnderSquareEmitterMatchesExactFormFactor) {
  SquareLight sl;
  Scene scene = sceneOf({{sl.emitterFacingDown(), 0}, {sl.receiverFacingUp(), 1}},
                        {material(glm::dvec3(0.0), sl.le), material(sl.rho, glm::dvec3(0.0))});
  PathTracer tracer(scene, 0.0);
  Polygon emitter;
  emitter.count = 4;
  for (int k = 0; k < 4; ++k) emitter.v[size_t(k)] = sl.emitterFacingDown()[size_t(k)];
  const double F = pointToPolygonFormFactor(sl.p, {0, 0, 1}, emitter);
  EXPECT_GT(F, 0.2);
  const glm::dvec3 expected = sl.rho / kPi * (kPi * sl.le) * F;
  RadianceEstimate e = tracer.estimateRadiance(sl.probe(1.0), 20000, 7, PathTracerOptions());
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(e.standardError[c], 0.0);
    EXPECT_LT(e.standardError[c], 0.01 * expected[c]);
    EXPECT_NEAR(e.mean[c], expected[c], 4.0 * e.standardError[c]) << c;
  }
  std::printf("  square emitter: L = %.6f +- %.6f, exact %.6f (%.2f sigma)\n", e.mean.x,
              e.standardError.x, expected.x, (e.mean.x - expected.x) / e.standardError.x);
  // The back of the one-sided receiver is black.
  EXPECT_EQ(tracer.estimateRadiance(sl.probe(-1.0), 100, 7, PathTracerOptions()).mean,
            glm::dvec3(0.0));
  // maxDepth 0: emission only (the receiver does not emit).
  PathTracerOptions emissionOnly;
  emissionOnly.maxDepth = 0;
  EXPECT_EQ(tracer.estimateRadiance(sl.probe(1.0), 100, 7, emissionOnly).mean, glm::dvec3(0.0));
}

// Smooth shading (glTF NORMAL): the same flat receiver with every vertex normal tilted 34
// degrees shades with the tilted normal, as Cycles and glTF viewers do: L = rho/pi B F(p, n_s ->
// emitter) with the shading normal n_s, within 4 standard errors, and away from the flat value.
TEST(PathTracer, ShadingNormalIsTheInterpolatedVertexNormal) {
  SquareLight sl;
  Scene scene = sceneOf({{sl.emitterFacingDown(), 0}, {sl.receiverFacingUp(), 1}},
                        {material(glm::dvec3(0.0), sl.le), material(sl.rho, glm::dvec3(0.0))});
  const glm::dvec3 tilted = glm::normalize(glm::dvec3(0.6, -0.3, 1.0));
  for (MeshTriangle& t : scene.meshes[1].triangles) t.normal = {tilted, tilted, tilted};
  PathTracer tracer(scene, 0.0);
  Polygon emitter;
  emitter.count = 4;
  for (int k = 0; k < 4; ++k) emitter.v[size_t(k)] = sl.emitterFacingDown()[size_t(k)];
  const double fShaded = pointToPolygonFormFactor(sl.p, tilted, emitter);
  const double fFlat = pointToPolygonFormFactor(sl.p, {0, 0, 1}, emitter);
  ASSERT_GT(std::abs(fShaded - fFlat), 0.05 * fFlat);
  const glm::dvec3 expected = sl.rho / kPi * (kPi * sl.le) * fShaded;
  RadianceEstimate e = tracer.estimateRadiance(sl.probe(1.0), 20000, 7, PathTracerOptions());
  for (int c = 0; c < 3; ++c) {
    EXPECT_LT(e.standardError[c], 0.01 * expected[c]);
    EXPECT_NEAR(e.mean[c], expected[c], 4.0 * e.standardError[c]) << c;
  }
}

TEST(PathTracer, EmitterFacingAwayOrBlockedGivesNoLight) {
  SquareLight sl;
  std::vector<glm::dvec3> up = sl.emitterFacingDown();
  std::reverse(up.begin(), up.end());  // now faces +z, away from the receiver
  Scene away = sceneOf({{up, 0}, {sl.receiverFacingUp(), 1}},
                       {material(glm::dvec3(0.0), sl.le), material(sl.rho, glm::dvec3(0.0))});
  PathTracer t1(away, 0.0);
  EXPECT_EQ(t1.estimateRadiance(sl.probe(1.0), 200, 3, PathTracerOptions()).mean, glm::dvec3(0.0));

  // A black blocker (facing down, absorbing both sides) between them, larger than the light's
  // view of the receiver.
  std::vector<glm::dvec3> blocker = {{-2, -2, 0.3}, {-2, 2, 0.3}, {2, 2, 0.3}, {2, -2, 0.3}};
  Scene blocked = sceneOf({{sl.emitterFacingDown(), 0}, {sl.receiverFacingUp(), 1}, {blocker, 2}},
                          {material(glm::dvec3(0.0), sl.le), material(sl.rho, glm::dvec3(0.0)),
                           material(glm::dvec3(0.0), glm::dvec3(0.0))});
  PathTracer t2(blocked, 0.0);
  Ray r = sl.probe(1.0);
  r.origin = sl.p + 0.01 * -r.direction;  // start below the blocker
  EXPECT_EQ(t2.estimateRadiance(r, 200, 3, PathTracerOptions()).mean, glm::dvec3(0.0));
}

// The camera does not see the back of a one-sided polygon (glTF back-face culling, as
// rad-compose's item buffer): a primary ray passes through it and sees the emitter behind, at
// exactly L_e. Seen from the front the same sheet (black) hides the emitter.
TEST(PathTracer, PrimaryRaysPassThroughTheBackOfOneSidedPolygons) {
  SquareLight sl;
  const double z = 0.5 * sl.h;
  std::vector<glm::dvec3> sheetFacingUp = {{-1, -1, z}, {1, -1, z}, {1, 1, z}, {-1, 1, z}};
  std::vector<glm::dvec3> sheetFacingDown(sheetFacingUp.rbegin(), sheetFacingUp.rend());
  const std::vector<Material> materials = {material(glm::dvec3(0.0), sl.le),
                                           material(glm::dvec3(0.0), glm::dvec3(0.0))};
  Ray up;
  up.origin = glm::dvec3(0.1, 0.05, 0.0);
  up.direction = glm::dvec3(0.0, 0.0, 1.0);
  up.tNear = 0.0;
  up.tFar = std::numeric_limits<double>::infinity();
  PathTracer culled(sceneOf({{sl.emitterFacingDown(), 0}, {sheetFacingUp, 1}}, materials), 0.0);
  EXPECT_EQ(culled.estimateRadiance(up, 16, 5, PathTracerOptions()).mean, sl.le);
  PathTracer seen(sceneOf({{sl.emitterFacingDown(), 0}, {sheetFacingDown, 1}}, materials), 0.0);
  EXPECT_EQ(seen.estimateRadiance(up, 16, 5, PathTracerOptions()).mean, glm::dvec3(0.0));
  // Two culled sheets in a row, and a tFar short of the emitter: nothing is seen.
  std::vector<glm::dvec3> second = sheetFacingUp;
  for (glm::dvec3& v : second) v.z = 0.75 * sl.h;
  PathTracer twice(
      sceneOf({{sl.emitterFacingDown(), 0}, {sheetFacingUp, 1}, {second, 1}}, materials), 0.0);
  EXPECT_EQ(twice.estimateRadiance(up, 16, 5, PathTracerOptions()).mean, sl.le);
  Ray shortRay = up;
  shortRay.tFar = 0.9 * sl.h;
  EXPECT_EQ(twice.estimateRadiance(shortRay, 16, 5, PathTracerOptions()).mean, glm::dvec3(0.0));
  // A polygon modelled seen from both sides as two coincident faces of opposite winding (the
  // table scenes' fin): the ray passing the culled back must still meet the front at the same
  // distance, whatever the rounding of either hit (it used to restart past the back, and about
  // half of the pixels saw through the fin).
  for (bool backFirst : {true, false}) {
    PathTracer pair(sceneOf({{sl.emitterFacingDown(), 0},
                             {backFirst ? sheetFacingUp : sheetFacingDown, 1},
                             {backFirst ? sheetFacingDown : sheetFacingUp, 1}},
                            materials),
                    0.0);
    int seenThrough = 0;
    for (int i = 0; i < 400; ++i) {
      Ray r = up;
      r.origin = glm::dvec3(-0.9 + 0.0045 * i, 0.8 - 0.0037 * i, 0.013 * (i % 7));
      r.direction = glm::normalize(glm::dvec3(0.01 * ((i % 5) - 2), 0.007 * ((i % 3) - 1), 1.0));
      if (pair.estimateRadiance(r, 1, 5, PathTracerOptions()).mean != glm::dvec3(0.0))
        ++seenThrough;
    }
    EXPECT_EQ(seenThrough, 0) << (backFirst ? "back face listed first" : "front face listed first");
  }
}

// A textured receiver: reflectance = baseColorFactor x texel at the hit's uv (bilinear,
// texel centres at half-integers), not the material's mean.
TEST(PathTracer, TexturedReceiverUsesTheTexelUnderTheHit) {
  SquareLight sl;
  Texture tex;
  tex.width = 2;
  tex.height = 1;
  tex.rgb = {0.9f, 0.2f, 0.4f, 0.1f, 0.8f, 0.6f};
  tex.mean = glm::dvec3(0.5, 0.5, 0.5);
  const glm::dvec3 factor(1.0, 0.5, 0.75);
  Material textured = material(factor * tex.mean, glm::dvec3(0.0));
  textured.baseColorTexture = 0;
  TestPolygon receiver{sl.receiverFacingUp(), 1, {{0, 0}, {0.5, 0}, {0.5, 1}, {0, 1}}};
  Scene scene = sceneOf({{sl.emitterFacingDown(), 0}, receiver},
                        {material(glm::dvec3(0.0), sl.le), textured});
  scene.textures.push_back(tex);
  PathTracer tracer(scene, 0.0);
  Polygon emitter;
  emitter.count = 4;
  for (int k = 0; k < 4; ++k) emitter.v[size_t(k)] = sl.emitterFacingDown()[size_t(k)];
  const double F = pointToPolygonFormFactor(sl.p, {0, 0, 1}, emitter);
  // The receiver's centre has uv (0.25, 0.5): the centre of texel 0.
  const glm::dvec3 rho = factor * glm::dvec3(0.9, 0.2, 0.4);
  const glm::dvec3 expected = rho * sl.le * F;
  RadianceEstimate e = tracer.estimateRadiance(sl.probe(1.0), 20000, 13, PathTracerOptions());
  for (int c = 0; c < 3; ++c) {
    EXPECT_LT(e.standardError[c], 0.01 * expected[c]);
    EXPECT_NEAR(e.mean[c], expected[c], 4.0 * e.standardError[c]) << c;
  }
}

// A doubleSided receiver lit from below through its back: it reflects like its front.
TEST(PathTracer, DoubleSidedReceiverReflectsOnItsBack) {
  SquareLight sl;
  std::vector<glm::dvec3> below = {{-0.5, -0.5, -sl.h},
                                   {0.5, -0.5, -sl.h},
                                   {0.5, 0.5, -sl.h},
                                   {-0.5, 0.5, -sl.h}};  // faces +z, towards the receiver
  Scene scene =
      sceneOf({{below, 0}, {sl.receiverFacingUp(), 1}},
              {material(glm::dvec3(0.0), sl.le), material(sl.rho, glm::dvec3(0.0), true)});
  PathTracer tracer(scene, 0.0);
  Polygon emitter;
  emitter.count = 4;
  for (int k = 0; k < 4; ++k) emitter.v[size_t(k)] = below[size_t(k)];
  const double F = pointToPolygonFormFactor(sl.p, {0, 0, -1}, emitter);
  const glm::dvec3 expected = sl.rho * sl.le * F;
  RadianceEstimate e = tracer.estimateRadiance(sl.probe(-1.0), 20000, 11, PathTracerOptions());
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(e.mean[c], expected[c], 4.0 * e.standardError[c]) << c;
  // Its front sees no light (the emitter is below, one-sided).
  EXPECT_EQ(tracer.estimateRadiance(sl.probe(1.0), 100, 11, PathTracerOptions()).mean,
            glm::dvec3(0.0));
}

}  // namespace
}  // namespace rad

namespace rad {
namespace {

// --pixel-filter none (what rad-compose --pixel-filter none point-samples): every primary ray goes
// through its pixel's centre, so a pixel that sees an emitter directly (rho 0: nothing else
// contributes) is exactly L_e or exactly 0; area sampling instead averages the edge pixels to
// values in between.
TEST(PathTracer, PixelCentresPointSampleEdges) {
  const glm::dvec3 le(1.0, 2.0, 3.0);
  // A rectangle facing the camera, its edges at no pixel boundary.
  Scene scene =
      sceneOf({{{{-0.23, -0.17, -1}, {0.31, -0.17, -1}, {0.31, 0.2, -1}, {-0.23, 0.2, -1}}}},
              {material(glm::dvec3(0.0), le)});
  addCamera(scene, {0, 0, 0}, 1.0);
  PathTracer tracer(scene, 0.0);
  const CameraView view = scene.cameraAt(scene.cameraNode(""), 0.0);
  PathTracerOptions o = unbiasedOptions();
  o.samplesPerPixel = 16;
  auto count = [&](const FloatImage& im, int& lit, int& dark, int& between) {
    lit = dark = between = 0;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 24; ++x) {
        double v = im.at(x, y, 2);
        (v == 0.0 ? dark : v == float(le.z) ? lit : between)++;
      }
  };
  int lit, dark, between;
  o.filter = PixelFilter::pixelCentre();
  count(tracer.render(view, {24, 16}, o), lit, dark, between);
  EXPECT_EQ(between, 0);
  EXPECT_GT(lit, 10);
  EXPECT_GT(dark, 10);
  const int litCentres = lit;
  o.filter = PixelFilter{PixelFilterType::kBox, 1.0};
  count(tracer.render(view, {24, 16}, o), lit, dark, between);
  EXPECT_GT(between, 8) << "edge pixels are averaged";
  EXPECT_LT(lit, litCentres);
  std::printf(
      "  emitter seen directly: %d lit pixels at centres; %d partly lit with area samples\n",
      litCentres, between);
}

// The pixel filter (Cycles' sampling: offsets drawn from the filter, every sample weight 1): an
// emitter's vertical edge at a known sub-pixel column gives each pixel Le times the filter's
// share left of the edge, and a flat field stays the field whatever the filter; the same image
// with 1 or 2 threads.
TEST(PathTracer, FilteredPixelsAreTheFiltersShareOfAnEdge) {
  const glm::dvec3 le(1.0, 2.0, 3.0);
  constexpr int kW = 24, kH = 16;
  constexpr double kEdge = 11.3;  // image column of the emitter's right edge
  const double halfTan = std::tan(0.5), aspect = double(kW) / kH;
  const double x0 = (2.0 * kEdge / kW - 1.0) * aspect * halfTan;  // at depth 1
  Scene scene = sceneOf({{{{-5, -5, -1}, {x0, -5, -1}, {x0, 5, -1}, {-5, 5, -1}}}},
                        {material(glm::dvec3(0.0), le)});
  addCamera(scene, {0, 0, 0}, 1.0);
  PathTracer tracer(scene, 0.0);
  const CameraView view = scene.cameraAt(scene.cameraNode(""), 0.0);
  PathTracerOptions o = unbiasedOptions();
  o.samplesPerPixel = 1024;  // 32 x 32 strata
  for (const PixelFilter& f : {PixelFilter{}, PixelFilter{PixelFilterType::kGaussian, 1.5},
                               PixelFilter{PixelFilterType::kBox, 1.0}}) {
    o.filter = f;
    const FloatImage im = tracer.render(view, {kW, kH}, o);
    for (int col = 0; col < kW; ++col) {
      // The filter's weight left of the edge, of the pixel centred at col + 1/2.
      double left = 0.0, all = 0.0;
      for (int i = 0; i < 20000; ++i) {
        const double v = -f.radius() + 2.0 * f.radius() * (i + 0.5) / 20000, w = f.weight(v);
        all += w;
        if (col + 0.5 + v < kEdge) left += w;
      }
      for (int row : {3, 8})
        EXPECT_NEAR(im.at(col, row, 2), le.z * left / all, 0.01 * le.z)
            << f.toString() << " pixel " << col;
    }
  }
  // A flat field (the emitter everywhere): every pixel is Le, whatever the filter.
  Scene flat = sceneOf({{{{-50, -50, -1}, {50, -50, -1}, {50, 50, -1}, {-50, 50, -1}}}},
                       {material(glm::dvec3(0.0), le)});
  addCamera(flat, {0, 0, 0}, 1.0);
  PathTracer flatTracer(flat, 0.0);
  o.samplesPerPixel = 16;
  o.filter = PixelFilter{};
  FloatImage one, two;
  {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 1);
    one = flatTracer.render(view, {kW, kH}, o);
  }
  {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
    two = flatTracer.render(view, {kW, kH}, o);
  }
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(one.at(x, y, c), le[c], 1e-6 * le[c]);
        EXPECT_EQ(one.at(x, y, c), two.at(x, y, c));
      }
  // And the edge image, too, is the same with 1 or 2 threads (a 4-spp render).
  o.samplesPerPixel = 4;
  {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 1);
    one = tracer.render(view, {kW, kH}, o);
  }
  {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
    two = tracer.render(view, {kW, kH}, o);
  }
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) EXPECT_EQ(one.at(x, y, 2), two.at(x, y, 2));
}

}  // namespace
}  // namespace rad
