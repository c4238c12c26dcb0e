// libcommon/scene/emitter, emissive_polygon_emitter, scene_emitters: a 1 m^2 quad light 1 m over
// the origin facing down, its power, what it emits in front and behind, its samples, and its
// bounds when it moves.
#include "libcommon/scene/emitter.h"

#include <cmath>

#include <gtest/gtest.h>

#include "libcommon/radiosity/form_factor.h"
#include "libcommon/scene/emissive_polygon_emitter.h"
#include "libcommon/scene/scene_emitters.h"

namespace rad {
namespace {

constexpr double kPi = 3.14159265358979323846;
const glm::dvec3 kRadiance(1.0, 2.0, 3.0);

// Node 0: the light (quad z = 1, |x|, |y| <= 0.5, front normal -z), material 0 (emits);
// node 1: a floor triangle with material 1 (does not). With `moving`, the light's node moves
// from x = 0 at t = 0 to x = 2 at t = 1 (LINEAR) and stays there.
Scene quadLightScene(bool moving) {
  Scene s;
  s.path = "test";
  Material light;
  light.emission = kRadiance;
  light.reflectance = glm::dvec3(0.0);
  s.materials = {light, Material()};
  const glm::dvec3 a(-0.5, -0.5, 1.0), b(-0.5, 0.5, 1.0), c(0.5, 0.5, 1.0), d(0.5, -0.5, 1.0);
  Mesh quad;
  quad.triangles.resize(2);
  quad.triangles[0].p = {a, b, c};
  quad.triangles[1].p = {a, c, d};
  for (MeshTriangle& t : quad.triangles) t.material = 0;
  Mesh floor;
  floor.triangles.resize(1);
  floor.triangles[0].p = {glm::dvec3(-1, -1, 0), glm::dvec3(1, -1, 0), glm::dvec3(0, 1, 0)};
  floor.triangles[0].material = 1;
  s.meshes = {quad, floor};
  s.nodes.resize(2);
  s.nodes[0].mesh = 0;
  s.nodes[1].mesh = 1;
  if (moving) {
    AnimationChannel ch;
    ch.node = 0;
    ch.path = AnimationPath::kTranslation;
    ch.interpolation = Interpolation::kLinear;
    ch.times = {0.0, 1.0};
    ch.values = {0, 0, 0, 2, 0, 0};
    s.channels.push_back(ch);
  }
  return s;
}

TEST(SceneEmitters, OneEmitterPerEmittingTop) {
  const Scene scene = quadLightScene(false);
  const std::vector<InputPolygon> tops = scene.inputPolygons();
  ASSERT_EQ(tops.size(), 2u);  // the quad (merged) and the floor
  const SceneEmitters emitters(scene, tops);
  ASSERT_EQ(emitters.size(), 1u);
  EXPECT_EQ(emitters[0].top(), 0);
  EXPECT_EQ(emitters[0].node(), 0);
  EXPECT_TRUE(emitters.topEmits(0));
  EXPECT_FALSE(emitters.topEmits(1));
  EXPECT_EQ(emitters.indexOfTop(5), -1);
  EXPECT_NE(emitters[0].toString().find("emissive polygon"), std::string::npos);
}

TEST(EmissivePolygonEmitter, PowerIsPiRadianceArea) {
  const Scene scene = quadLightScene(false);
  const SceneEmitters emitters(scene, scene.inputPolygons());
  const glm::dvec3 phi = emitters[0].power(0.0);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(phi[c], kPi * kRadiance[c] * 1.0, 1e-12);
  const auto placed = emitters[0].at(0.0);
  ASSERT_TRUE(placed);
  EXPECT_NEAR(placed->area(), 1.0, 1e-12);
  EXPECT_NEAR(placed->samplingWeight(), 6.0, 1e-12);
  EXPECT_NEAR(placed->power().z, 3.0 * kPi, 1e-12);
}

TEST(EmissivePolygonEmitter, EmitsInFrontOnly) {
  const Scene scene = quadLightScene(false);
  const SceneEmitters emitters(scene, scene.inputPolygons());
  const auto placed = emitters[0].at(0.0);
  const glm::dvec3 y(0.1, 0.2, 1.0);
  EXPECT_EQ(placed->radianceToward(y, glm::dvec3(0.0, 0.0, 0.0)), kRadiance);
  EXPECT_EQ(placed->radianceToward(y, glm::dvec3(0.0, 0.0, 2.0)), glm::dvec3(0.0));
  EXPECT_EQ(placed->emittedRadiance(y, glm::dvec3(0.0, 0.0, -1.0)), kRadiance);

  // In front: E = pi L_e F (exact point-to-polygon form factor); behind: nothing.
  const glm::dvec3 x(0.2, -0.1, 0.0), up(0.0, 0.0, 1.0);
  const double F =
      pointToPolygonFormFactor(x, up, static_cast<const PlacedEmissivePolygon&>(*placed).world());
  const glm::dvec3 E = placed->irradiance(x, up);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(E[c], kPi * kRadiance[c] * F, 1e-12 * E[c]);
  EXPECT_GT(E.x, 0.0);
  EXPECT_EQ(placed->irradiance(glm::dvec3(0.0, 0.0, 2.0), -up), glm::dvec3(0.0));
  // A receiver facing away sees none; one tilted by 90 degrees sees the part in its front.
  EXPECT_EQ(placed->irradiance(x, -up), glm::dvec3(0.0));
  const glm::dvec3 side = placed->irradiance(glm::dvec3(0.0), glm::dvec3(1.0, 0.0, 0.0));
  EXPECT_GT(side.x, 0.0);
  EXPECT_LT(side.x, E.x);
}

TEST(EmissivePolygonEmitter, SamplesAreUniformInsideWithPdfOneOverArea) {
  const Scene scene = quadLightScene(false);
  const SceneEmitters emitters(scene, scene.inputPolygons());
  const auto placed = emitters[0].at(0.0);
  const glm::dvec3 x(0.2, -0.1, 0.0), up(0.0, 0.0, 1.0);
  const int n = 64;
  glm::dvec3 mean(0.0), estimate(0.0);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const EmitterSample s = placed->sample(glm::dvec2((i + 0.5) / n, (j + 0.5) / n));
      EXPECT_LE(std::abs(s.point.x), 0.5 + 1e-12);
      EXPECT_LE(std::abs(s.point.y), 0.5 + 1e-12);
      EXPECT_NEAR(s.point.z, 1.0, 1e-12);
      EXPECT_EQ(s.normal, glm::dvec3(0.0, 0.0, -1.0));
      EXPECT_NEAR(s.pdfArea, 1.0, 1e-12);
      mean += s.point / double(n * n);
      // The sampled estimate of E: L cos_x cos_y / d^2 / pdf.
      const glm::dvec3 d = s.point - x;
      const double d2 = glm::dot(d, d);
      const glm::dvec3 w = d / std::sqrt(d2);
      estimate += placed->radianceToward(s.point, x) * glm::dot(up, w) * -glm::dot(s.normal, w) /
                  d2 / s.pdfArea / double(n * n);
    }
  EXPECT_NEAR(mean.x, 0.0, 1e-3);
  EXPECT_NEAR(mean.y, 0.0, 1e-3);
  const glm::dvec3 E = placed->irradiance(x, up);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(estimate[c], E[c], 2e-3 * E[c]);
}

TEST(EmissivePolygonEmitter, BoundsCoverAMovingLight) {
  const Scene scene = quadLightScene(true);
  const SceneEmitters emitters(scene, scene.inputPolygons());
  const Emitter& light = emitters[0];
  EXPECT_TRUE(light.moves(0.0, 1.0));
  EXPECT_FALSE(light.moves(2.0, 3.0));  // the last key's value is held
  const auto box = light.bounds(0.0, 1.0);
  EXPECT_LE(box[0].x, -0.5);
  EXPECT_GE(box[1].x, 2.5);
  EXPECT_LE(box[0].y, -0.5);
  EXPECT_GE(box[1].y, 0.5);
  EXPECT_LE(box[0].z, 1.0);
  EXPECT_GE(box[1].z, 1.0);
  EXPECT_GT(box[0].x, -0.6);  // padded by at most a sample step
  EXPECT_LT(box[1].x, 2.6);
  const auto still = light.bounds(2.0, 3.0);  // static: exact
  EXPECT_EQ(still[0], glm::dvec3(1.5, -0.5, 1.0));
  EXPECT_EQ(still[1], glm::dvec3(2.5, 0.5, 1.0));
  // Placed halfway: its samples lie around x = 1.
  const EmitterSample s = light.at(0.5)->sample(glm::dvec2(0.5, 0.5));
  EXPECT_NEAR(s.point.x, 1.0, 0.5);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(light.power(0.5)[c], kPi * kRadiance[c], 1e-12);
}

}  // namespace
}  // namespace rad
