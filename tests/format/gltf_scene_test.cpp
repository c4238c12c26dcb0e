// glTF reader on the external test scenes (tests/data/external/INDEX.txt lists the quirks)
// and on broken files written here. Expected animation values are worked out in the test from
// key values decoded from the files' .bin with an independent script (quoted in comments).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include <sys/resource.h>

#include "formats/gltf_scene.h"
#include "libcommon/core/error.h"

namespace rad {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;
const std::string kExternal = std::string(RAD_TEST_DATA) + "/external/";

glm::dvec3 apply(const glm::dmat4& m, const glm::dvec3& p) {
  return glm::dvec3(m * glm::dvec4(p, 1.0));
}
// Rotation part of a local transform, as the angle of the x axis' image about +z.
double zAngle(const glm::dmat4& m) {
  glm::dvec3 x = glm::normalize(glm::dvec3(m * glm::dvec4(1, 0, 0, 0)));
  return std::atan2(x.y, x.x);
}
double scaleX(const glm::dmat4& m) {
  return glm::length(glm::dvec3(m[0]));
}
double wrap(double a) {
  return std::remainder(a, 2 * kPi);
}

// ---------------------------------------------------------------- InterpolationTest

class InterpolationTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // Its nodes 0, 3 and 4 animate scale: an affine motion the tools render (issue 57).
    scene =
        new Scene(readGltfScene(kExternal + "khronos_InterpolationTest/InterpolationTest.gltf"));
  }
  static void TearDownTestSuite() { delete scene; }
  static Scene* scene;
  // Key times as float32 in interpolation.bin.
  static constexpr double kT1 = 0.4166666567325592, kT2 = 0.875, kT0s = 0.0416666679084301;
};
Scene* InterpolationTest::scene = nullptr;

TEST_F(InterpolationTest, Structure) {
  EXPECT_EQ(scene->nodes.size(), 12u);
  EXPECT_EQ(scene->meshes.size(), 10u);
  EXPECT_EQ(scene->channels.size(), 9u);
  size_t tris = 0;
  for (const Mesh& m : scene->meshes) tris += m.triangles.size();
  EXPECT_EQ(tris, 110u);
  EXPECT_DOUBLE_EQ(scene->startTime(), 0.0);
  EXPECT_DOUBLE_EQ(scene->endTime(), double(1.7083333730697632f));
  // "Light" and "Camera" are empty Blender nodes: no camera.
  EXPECT_TRUE(scene->cameraNodes().empty());
  // The label plane's JPEG is decoded, sRGB -> linear; reflectance = factor (1) x mean.
  ASSERT_EQ(scene->textures.size(), 1u);
  const Texture& tex = scene->textures[0];
  EXPECT_GT(tex.width, 0);
  EXPECT_EQ(tex.rgb.size(), size_t(tex.width) * size_t(tex.height) * 3);
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(tex.mean[c], 0.0);
    EXPECT_LT(tex.mean[c], 1.0);
  }
  int plane = scene->meshes[9].triangles.at(0).material;
  ASSERT_GE(plane, 0);
  EXPECT_EQ(scene->materials[size_t(plane)].baseColorTexture, 0);
  EXPECT_NEAR(scene->materials[size_t(plane)].reflectance.x, tex.mean.x, 1e-12);
  EXPECT_NEAR(scene->materials[0].reflectance.x, double(0.800000011920929f), 1e-12);
}

TEST_F(InterpolationTest, StepScale) {
  // Node 0, keys 0.0417 1 | 0.4167 0.5 | 0.875 1 | 1.25 0.5 | 1.6667 1.
  EXPECT_NEAR(scaleX(scene->localTransform(0, 0.0)), 1.0, 1e-7);  // held before first key
  EXPECT_NEAR(scaleX(scene->localTransform(0, 0.4)), 1.0, 1e-7);
  EXPECT_NEAR(scaleX(scene->localTransform(0, kT1)), 0.5, 1e-7);
  EXPECT_NEAR(scaleX(scene->localTransform(0, 0.87)), 0.5, 1e-7);
  EXPECT_NEAR(scaleX(scene->localTransform(0, kT2)), 1.0, 1e-7);
  EXPECT_NEAR(scaleX(scene->localTransform(0, 9.0)), 1.0, 1e-7);
}

TEST_F(InterpolationTest, LinearScale) {
  // Node 3, same keys: halfway between 0.4167 (0.5) and 0.875 (1.0) -> 0.75.
  EXPECT_NEAR(scaleX(scene->localTransform(3, 0.5 * (kT1 + kT2))), 0.75, 1e-7);
  // Between 0.0417 (1.0) and 0.4167 (0.5), a quarter of the way -> 0.875.
  EXPECT_NEAR(scaleX(scene->localTransform(3, kT0s + 0.25 * (kT1 - kT0s))), 0.875, 1e-7);
}

TEST_F(InterpolationTest, CubicSplineScale) {
  // Node 4: same values, all tangents 0, so p(s) = h00 v_k + h01 v_{k+1}.
  // s = 0.25 on [0.4167 (0.5), 0.875 (1)]: h00 = 0.84375, h01 = 0.15625 -> 0.578125.
  EXPECT_NEAR(scaleX(scene->localTransform(4, kT1 + 0.25 * (kT2 - kT1))), 0.578125, 1e-7);
  EXPECT_NEAR(scaleX(scene->localTransform(4, 0.5 * (kT1 + kT2))), 0.75, 1e-7);
}

TEST_F(InterpolationTest, StepAndLinearRotation) {
  // Nodes 5 (STEP) and 7 (LINEAR): keys 0 -> 0, 0.4167 -> -45 deg, 0.875 -> -90 deg,
  // 1.25 -> -135 deg, 1.7083 -> -180 deg about z (q = (0,0,-1,-0) at the end). Node 7's rest
  // rotation is replaced by the channel.
  EXPECT_NEAR(zAngle(scene->localTransform(5, 0.2)), 0.0, 1e-6);
  EXPECT_NEAR(zAngle(scene->localTransform(5, 0.5)), -kPi / 4, 1e-6);
  EXPECT_NEAR(zAngle(scene->localTransform(7, 0.5 * kT1)), -kPi / 8, 1e-6);
  // s = 0.3 between 1.25 and 1.7083 -> -135 - 0.3 * 45 deg.
  const double t4 = double(1.7083333730697632f);
  EXPECT_NEAR(zAngle(scene->localTransform(7, 1.25 + 0.3 * (t4 - 1.25))),
              -(135.0 + 0.3 * 45.0) * kPi / 180.0, 1e-6);
  EXPECT_NEAR(std::abs(zAngle(scene->localTransform(7, 5.0))), kPi, 1e-6);
}

TEST_F(InterpolationTest, CubicSplineRotation) {
  // Node 6, first segment [0, 0.4167]: v0 = (0,0,0,1), out-tangent b0 = (0,0,-0,1),
  // in-tangent a1 = (0,0,-0.04789090156555176,0.9988526701927185),
  // v1 = (0,0,-0.3826834559440613,0.9238795638084412). At s = 0.5 (t_d = kT1):
  // p = 0.5 v0 + t_d 0.125 b0 + 0.5 v1 - t_d 0.125 a1, then normalised.
  const double td = kT1;
  double z = 0.5 * double(-0.3826834559440613f) - td * 0.125 * double(-0.04789090156555176f);
  double w = 0.5 + td * 0.125 + 0.5 * double(0.9238795638084412f) -
             td * 0.125 * double(0.9988526701927185f);
  const double expected = 2.0 * std::atan2(z, w);  // angle about +z of q = (0,0,z,w)
  EXPECT_NEAR(zAngle(scene->localTransform(6, 0.5 * kT1)), expected, 1e-6);
  // At the keys themselves: -45 deg and -90 deg.
  EXPECT_NEAR(zAngle(scene->localTransform(6, kT1)), -kPi / 4, 1e-6);
  EXPECT_NEAR(zAngle(scene->localTransform(6, kT2)), -kPi / 2, 1e-6);
}

TEST_F(InterpolationTest, Translations) {
  // Node 8 STEP y: 0 -> 6.6652, 0.4583 -> 10, 0.8333 -> 6.
  auto y = [&](int node, double t) { return apply(scene->localTransform(node, t), {}).y; };
  EXPECT_NEAR(y(8, 0.45), double(6.665226459503174f), 1e-5);
  EXPECT_NEAR(y(8, 0.5), 10.0, 1e-6);
  // Node 10 LINEAR y: 0.4167 -> 10, 0.8333 -> 6: halfway 8.
  const double t2 = double(0.8333333134651184f);
  EXPECT_NEAR(y(10, 0.5 * (kT1 + t2)), 8.0, 1e-6);
  // Node 9 CUBICSPLINE y, zero tangents: 0.4167 -> 10, 0.8333 -> 6, s = 0.25 -> 10 - 4*0.15625.
  EXPECT_NEAR(y(9, kT1 + 0.25 * (t2 - kT1)), 10.0 - 4.0 * 0.15625, 1e-6);
  // Static x of node 9 comes from the channel values (3.3052), not the rest pose.
  EXPECT_NEAR(apply(scene->localTransform(9, 0.3), {}).x, 3.3051798343658447, 1e-5);
}

TEST_F(InterpolationTest, Dynamic) {
  EXPECT_TRUE(scene->isDynamic(0, 0.0, 1.0));
  EXPECT_FALSE(scene->isDynamic(11, 0.0, 2.0));  // the label plane
  EXPECT_FALSE(scene->isDynamic(7, 2.0, 3.0));   // after the last key
}

// ---------------------------------------------------------------- BoxAnimated

TEST(BoxAnimated, GlbAndGltfAgree) {
  Scene a = readGltfScene(kExternal + "khronos_BoxAnimated/BoxAnimated.glb");
  Scene b = readGltfScene(kExternal + "khronos_BoxAnimated/BoxAnimated.gltf");
  ASSERT_EQ(a.nodes.size(), 4u);
  EXPECT_EQ(a.roots, (std::vector<int>{3, 0}));
  EXPECT_EQ(a.roots, b.roots);
  ASSERT_EQ(a.meshes.size(), b.meshes.size());
  size_t tris = 0;
  for (size_t m = 0; m < a.meshes.size(); ++m) {
    ASSERT_EQ(a.meshes[m].triangles.size(), b.meshes[m].triangles.size());
    tris += a.meshes[m].triangles.size();
    for (size_t i = 0; i < a.meshes[m].triangles.size(); ++i)
      for (int k = 0; k < 3; ++k)
        EXPECT_EQ(a.meshes[m].triangles[i].p[k], b.meshes[m].triangles[i].p[k]);
  }
  EXPECT_EQ(tris, 254u);
  ASSERT_EQ(a.channels.size(), 2u);
  EXPECT_EQ(a.channels[0].values, b.channels[0].values);
  EXPECT_EQ(a.channels[1].times, b.channels[1].times);
  ASSERT_EQ(a.materials.size(), 2u);
  EXPECT_NEAR(a.materials[0].reflectance.y, double(0.4159420132637024f), 1e-12);
  for (double t : {0.0, 0.7, 1.5, 1.875, 2.2, 3.0, 4.0})
    for (int n = 0; n < 4; ++n) EXPECT_EQ(a.worldTransform(n, t), b.worldTransform(n, t));
  auto pa = a.inputPolygons(), pb = b.inputPolygons();
  ASSERT_EQ(pa.size(), pb.size());
  EXPECT_LT(pa.size(), tris);  // box faces merge into quads
}

TEST(BoxAnimated, RotationDotZero180) {
  Scene s = readGltfScene(kExternal + "khronos_BoxAnimated/BoxAnimated.glb");
  // Channel 0: node 2 rotation, keys 1.25 -> (-0,-0,-0,-1), 2.5 -> (1,0,0,4.4896593e-11)
  // (decoded from BoxAnimated.bin). The dot is -4.49e-11 < 0, so glTF negates the second key:
  // slerp from (0,0,0,-1) to (-1,0,0,-4.5e-11), q(s) = -(sin(s pi/2), 0, 0, cos(s pi/2)),
  // a rotation by s * 180 deg about +x: the image of +y is (0, cos, sin).
  const AnimationChannel& ch = s.channels[0];
  EXPECT_EQ(ch.node, 2);
  EXPECT_EQ(ch.path, AnimationPath::kRotation);
  EXPECT_DOUBLE_EQ(ch.times.front(), 1.25);
  EXPECT_DOUBLE_EQ(ch.times.back(), 2.5);
  EXPECT_GT(ch.values[7], 0.0);
  EXPECT_LT(ch.values[7], 1e-10);
  for (double sp : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    const double t = 1.25 + sp * 1.25;
    glm::dvec3 y = glm::dvec3(s.localTransform(2, t) * glm::dvec4(0, 1, 0, 0));
    const double angle = sp * kPi;
    EXPECT_NEAR(y.x, 0.0, 1e-6) << t;
    EXPECT_NEAR(y.y, std::cos(angle), 1e-6) << t;
    EXPECT_NEAR(y.z, std::sin(angle), 1e-6) << t;
  }
  // Before 1.25 s the first key (identity as stored, -1 w) is held.
  EXPECT_EQ(s.localTransform(2, 0.0), s.localTransform(2, 1.25));
  EXPECT_TRUE(s.isDynamic(2, 1.0, 1.3));
  EXPECT_TRUE(s.isDynamic(2, 0.0, 1.0));   // node 0 (ancestor) translates on [0, 3.708]
  EXPECT_FALSE(s.isDynamic(3, 0.0, 4.0));  // the static box
}

// ---------------------------------------------------------------- AnimatedTriangle

TEST(AnimatedTriangle, ShortestArcThroughNegativeW) {
  Scene s = readGltfScene(kExternal + "khronos_AnimatedTriangle/AnimatedTriangle.gltf");
  ASSERT_EQ(s.channels.size(), 1u);
  EXPECT_EQ(s.channels[0].times, (std::vector<double>{0, 0.25, 0.5, 0.75, 1.0}));
  EXPECT_EQ(s.meshes.at(0).triangles.size(), 1u);
  EXPECT_EQ(s.meshes[0].triangles[0].material, -1);  // glTF default material
  // Keys are 0, 90, 180, 270, 360 deg about z (0.707 is not exactly sqrt(1/2), hence 1e-3).
  // The last segment goes (0,0,0.707,-0.707) -> (0,0,0,1): dot < 0, so the sign flip makes it
  // turn +90 deg, not -270 deg. The angle is 360 t deg throughout.
  for (double t : {0.1, 0.3, 0.6, 0.8, 0.875, 0.95, 1.0}) {
    EXPECT_NEAR(wrap(zAngle(s.localTransform(0, t)) - t * 2 * kPi), 0.0, 1e-3) << t;
  }
}

// ---------------------------------------------------------------- Cameras

TEST(Cameras, NoSceneKeyAndOrthographic) {
  Scene s = readGltfScene(kExternal + "khronos_Cameras/Cameras.gltf");
  EXPECT_EQ(s.roots, (std::vector<int>{0, 1, 2}));  // no "scene": scene 0
  ASSERT_EQ(s.cameras.size(), 2u);
  EXPECT_TRUE(s.cameras[0].perspective);
  EXPECT_DOUBLE_EQ(s.cameras[0].yfov, 0.7);
  EXPECT_DOUBLE_EQ(s.cameras[0].aspectRatio, 1.0);
  EXPECT_FALSE(s.cameras[1].perspective);
  EXPECT_DOUBLE_EQ(s.cameras[1].xmag, 1.0);
  EXPECT_DOUBLE_EQ(s.cameras[1].ymag, 1.0);
  EXPECT_DOUBLE_EQ(s.cameras[1].zfar, 100.0);
  EXPECT_EQ(s.cameraNodes(), (std::vector<int>{1, 2}));
  EXPECT_EQ(s.cameraNode(""), 1);
  CameraView v = s.cameraAt(2, 0.0);
  EXPECT_FALSE(v.lens.perspective);
  EXPECT_EQ(v.eye(), glm::dvec3(0.5, 0.5, 3.0));
  EXPECT_EQ(s.meshes.at(0).triangles.size(), 2u);
  auto polys = s.inputPolygons();
  ASSERT_EQ(polys.size(), 1u);  // the square merges into one quad
  EXPECT_NEAR(polys[0].local.area(), 1.0, 1e-6);
}

// ---------------------------------------------------------------- Cornell box

std::vector<Polygon> worldPolygons(const Scene& s) {
  std::vector<Polygon> out;
  for (const InputPolygon& p : s.inputPolygons())
    out.push_back(p.local.transformed(s.worldTransform(p.node, 0.0)));
  return out;
}

TEST(CornellBox, EmitterCameraAndMerge) {
  Scene s = readGltfScene(kExternal + "cornell_box/cornell_box.gltf");
  size_t tris = 0;
  for (const Mesh& m : s.meshes) tris += m.triangles.size();
  EXPECT_EQ(tris, 32u);
  EXPECT_TRUE(s.warnings.empty());
  ASSERT_EQ(s.materials.size(), 4u);
  int emitters = 0;
  for (const Material& m : s.materials) {
    if (!m.isEmitter()) continue;
    ++emitters;
    // (1, 12/17, 4/17) x 17 (KHR_materials_emissive_strength).
    EXPECT_NEAR(m.emission.x, 17.0, 1e-12);
    EXPECT_NEAR(m.emission.y, 12.0, 1e-12);
    EXPECT_NEAR(m.emission.z, 4.0, 1e-12);
  }
  EXPECT_EQ(emitters, 1);
  // 16 faces of 2 triangles. The measured left (red) wall is not planar (its 4th corner is
  // 3.2 mm off the plane of the other three), so it stays 2 triangles: 15 quads + 2 triangles.
  // The light, 0.1 mm under the ceiling, cuts it into 13 quads (contact_cuts.h: its outline and
  // rims 4 gaps wide on either side): 27 quads + 2 triangles.
  auto polys = s.inputPolygons();
  EXPECT_EQ(polys.size(), 29u);
  int quads = 0;
  double area = 0.0;
  for (const InputPolygon& p : polys) {
    quads += p.local.count == 4;
    area += p.local.area();
  }
  EXPECT_EQ(quads, 27);
  double triArea = 0.0;
  for (const Mesh& m : s.meshes)
    for (const MeshTriangle& t : m.triangles)
      triArea += 0.5 * glm::length(glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]));
  EXPECT_NEAR(area, triArea, 1e-12);
  int cam = s.cameraNode("cornell_camera");
  ASSERT_EQ(cam, 16);
  CameraView v = s.cameraAt(cam, 0.0);
  EXPECT_NEAR(glm::length(v.eye() - glm::dvec3(0.278, 0.273, -0.8)), 0.0, 1e-12);
  // Looks along world +z (its -Z axis), +y up.
  EXPECT_NEAR(glm::length(glm::dvec3(v.worldFromCamera[2]) - glm::dvec3(0, 0, -1)), 0, 1e-12);
  EXPECT_NEAR(glm::length(glm::dvec3(v.worldFromCamera[1]) - glm::dvec3(0, 1, 0)), 0, 1e-12);
  EXPECT_NEAR(v.lens.yfov, 0.6860478808414068, 1e-15);
  EXPECT_FALSE(s.isDynamic(0, 0.0, 10.0));
}

TEST(CornellBox, MillimetreRootScaleMatches) {
  Scene m = readGltfScene(kExternal + "cornell_box/cornell_box.gltf");
  Scene mm = readGltfScene(kExternal + "cornell_box/cornell_box_mm_rootscale.gltf");
  auto a = worldPolygons(m), b = worldPolygons(mm);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].count, b[i].count);
    for (int k = 0; k < a[i].count; ++k)
      // float32 vertices: 556 mm and 0.556 m round differently (~3e-8 m).
      EXPECT_NEAR(glm::length(a[i].v[k] - b[i].v[k]), 0.0, 1e-6) << i;
  }
  CameraView va = m.cameraAt(m.cameraNode(""), 0.0), vb = mm.cameraAt(mm.cameraNode(""), 0.0);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      EXPECT_NEAR(va.worldFromCamera[c][r], vb.worldFromCamera[c][r], 1e-12);
  EXPECT_DOUBLE_EQ(va.lens.znear, vb.lens.znear);  // metres in both
}

// ---------------------------------------------------------------- every external file

TEST(External, EveryFileLoads) {
  int files = 0;
  for (const auto& e : fs::recursive_directory_iterator(kExternal)) {
    const std::string ext = e.path().extension().string();
    if (ext != ".gltf" && ext != ".glb") continue;
    ++files;
    // Every file loads (InterpolationTest's animated scale too, issue 57).
    EXPECT_NO_THROW(readGltfScene(e.path().string())) << e.path();
  }
  EXPECT_EQ(files, 7);
}

// ---------------------------------------------------------------- bad input

class BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() /
          ("rad_gltf_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
           "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  std::string write(const std::string& name, const std::string& text) {
    std::string p = (dir / name).string();
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  // A triangle: 3 float VEC3 positions (36 bytes) + 3 unsigned short indices (6 bytes).
  static std::string triangleBin(bool withNan = false) {
    float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    if (withNan) pos[4] = std::numeric_limits<float>::quiet_NaN();
    uint16_t idx[4] = {0, 1, 2, 0};
    std::string bin(reinterpret_cast<const char*>(pos), sizeof pos);
    bin.append(reinterpret_cast<const char*>(idx), sizeof idx);
    return bin;  // 44 bytes
  }
  static std::string triangleGltf(const std::string& extra = "", const std::string& node = "",
                                  const std::string& posAccessor = "\"count\": 3",
                                  size_t byteLength = 44) {
    return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
      "nodes": [{"mesh": 0)" +
           node + R"(}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
      "buffers": [{"uri": "tri.bin", "byteLength": )" +
           std::to_string(byteLength) + R"(}],
      "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                      {"buffer": 0, "byteOffset": 36, "byteLength": 8}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "type": "VEC3", )" +
           posAccessor +
           R"(, "min": [0,0,0], "max": [1,1,0]},
                    {"bufferView": 1, "componentType": 5123, "type": "SCALAR", "count": 3}])" +
           extra + "}";
  }
  void expectBadInput(const std::string& path, const std::string& fragment) {
    try {
      readGltfScene(path);
      ADD_FAILURE() << path << ": no error";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ExitCode::kBadInput);
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
      EXPECT_NE(what.find(fragment), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    } catch (const std::exception& e) {
      ADD_FAILURE() << path << ": not a rad::Error: " << e.what();
    }
  }
  fs::path dir;

  // The triangle scene with one animation channel of node 0 (`path`: translation or scale) whose
  // two keys, at t = 0 and 1, hold values[0..2] and values[3..5].
  std::string animatedTriangleGltf(const char* path, const float (&values)[6]) {
    std::string bin = triangleBin();
    const float times[2] = {0, 1};
    bin.append(reinterpret_cast<const char*>(times), 8);    // 44..51
    bin.append(reinterpret_cast<const char*>(values), 24);  // 52..75
    write("tri.bin", bin);
    std::string gltf =
        triangleGltf(std::string(R"(, "animations": [{"samplers": [{"input": 2, "output": 3}],
        "channels": [{"sampler": 0, "target": {"node": 0, "path": ")") +
                         path + R"("}}]}])",
                     "", "\"count\": 3", 76);
    gltf.replace(gltf.find("\"byteLength\": 8}]"), 17,
                 R"("byteLength": 8}, {"buffer": 0, "byteOffset": 44, "byteLength": 8},
                    {"buffer": 0, "byteOffset": 52, "byteLength": 24}])");
    gltf.replace(
        gltf.find("\"count\": 3}]"), 12,
        R"("count": 3}, {"bufferView": 2, "componentType": 5126, "type": "SCALAR", "count": 2},
                    {"bufferView": 3, "componentType": 5126, "type": "VEC3", "count": 2}])");
    return gltf;
  }
};

TEST_F(BadInput, GoodTriangleLoads) {
  write("tri.bin", triangleBin());
  Scene s = readGltfScene(write("ok.gltf", triangleGltf()));
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].triangles.size(), 1u);
}

TEST_F(BadInput, MissingFile) {
  expectBadInput((dir / "nope.gltf").string(), "cannot open");
}

TEST_F(BadInput, InvalidJson) {
  expectBadInput(write("bad.gltf", "{ \"asset\": { \"version\": \"2.0\" , nope"), "invalid gltf");
}

TEST_F(BadInput, TruncatedBin) {
  write("tri.bin", triangleBin().substr(0, 20));  // declared 44 bytes
  expectBadInput(write("trunc.gltf", triangleGltf()), "");
}

TEST_F(BadInput, TruncatedGlb) {
  std::ifstream in(kExternal + "khronos_BoxAnimated/BoxAnimated.glb", std::ios::binary);
  std::string glb((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(glb.size(), 1000u);
  expectBadInput(write("cut.glb", glb.substr(0, 1000)), "truncated glb");
  std::string v3 = glb;
  v3[4] = 3;
  expectBadInput(write("v3.glb", v3), "glb version 3, expected 2");
}

TEST_F(BadInput, NanPosition) {
  write("tri.bin", triangleBin(true));
  expectBadInput(write("nan.gltf", triangleGltf()), "non-finite");
}

TEST_F(BadInput, Skin) {
  write("tri.bin", triangleBin());
  expectBadInput(
      write("skin.gltf", triangleGltf(R"(, "skins": [{"joints": [0]}])", ", \"skin\": 0")), "skin");
}

TEST_F(BadInput, AccessorOutOfBounds) {
  write("tri.bin", triangleBin());
  expectBadInput(write("oob.gltf", triangleGltf("", "", "\"count\": 4")), "exceed");
  expectBadInput(
      write("oob2.gltf", triangleGltf("", "", "\"count\": 3, \"byteOffset\": 4000000000")), "");
}

TEST_F(BadInput, IndexOutOfRange) {
  std::string bin = triangleBin();
  bin[36 + 4] = 7;  // third index = 7 with 3 vertices
  write("tri.bin", bin);
  expectBadInput(write("idx.gltf", triangleGltf()), "index 7 out of range");
}

TEST_F(BadInput, MorphWeightsChannel) {
  write("tri.bin", triangleBin());
  const std::string anim = R"(, "animations": [{"samplers": [{"input": 0, "output": 0}],
      "channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}]}])";
  expectBadInput(write("weights.gltf", triangleGltf(anim)), "morph");
}

TEST_F(BadInput, ZeroAreaTriangleDroppedAndCounted) {
  std::string bin = triangleBin();
  float p[3] = {2, 0, 0};  // third vertex on the line through the first two
  std::memcpy(&bin[24], p, 12);
  write("tri.bin", bin);
  Scene s = readGltfScene(write("zero.gltf", triangleGltf()));
  EXPECT_TRUE(s.meshes[0].triangles.empty());
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0], "dropped 1 zero-area triangles");
}

TEST_F(BadInput, StripSparseAndNormalisedTexcoords) {
  // 4 vertices as a TRIANGLE_STRIP (-> 2 triangles, a unit square), positions partly replaced
  // by a sparse accessor; UNSIGNED_BYTE normalised texcoords; UNSIGNED_BYTE indices.
  std::string bin;
  auto put = [&](const void* d, size_t n) { bin.append(static_cast<const char*>(d), n); };
  float pos[12] = {0, 0, 0, 1, 0, 0, 0, 9, 0, 1, 1, 0};  // vertex 2 is wrong: sparse fixes it
  put(pos, sizeof pos);                                  // 0..47
  uint8_t uv[8] = {0, 0, 255, 0, 0, 255, 255, 255};
  put(uv, sizeof uv);  // 48..55
  uint8_t idx[4] = {0, 1, 2, 3};
  put(idx, sizeof idx);  // 56..59
  uint32_t sparseIdx = 2;
  put(&sparseIdx, 4);  // 60..63
  float fix[3] = {0, 1, 0};
  put(fix, sizeof fix);  // 64..75
  write("strip.bin", bin);
  const std::string gltf = R"({"asset": {"version": "2.0"},
    "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2,
                                "mode": 5, "material": 0}]}],
    "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
    "textures": [{"source": 0}],
    "images": [{"uri": "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAIAAAABCAIAAAB7QOjdAAAAD0lEQVR4nGP4//8/AwMDAA74Av7Ji4P1AAAAAElFTkSuQmCC"}],
    "buffers": [{"uri": "strip.bin", "byteLength": 76}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                    {"buffer": 0, "byteOffset": 48, "byteLength": 8},
                    {"buffer": 0, "byteOffset": 56, "byteLength": 4},
                    {"buffer": 0, "byteOffset": 60, "byteLength": 4},
                    {"buffer": 0, "byteOffset": 64, "byteLength": 12}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 4,
                   "min": [0,0,0], "max": [1,9,0],
                   "sparse": {"count": 1, "indices": {"bufferView": 3, "componentType": 5125},
                              "values": {"bufferView": 4}}},
                  {"bufferView": 1, "componentType": 5121, "normalized": true, "type": "VEC2",
                   "count": 4},
                  {"bufferView": 2, "componentType": 5121, "type": "SCALAR", "count": 4}]})";
  Scene s = readGltfScene(write("strip.gltf", gltf));
  EXPECT_EQ(s.roots, (std::vector<int>{0}));  // no scenes: all root nodes
  ASSERT_EQ(s.meshes[0].triangles.size(), 2u);
  // Strip (glTF §3.7.2): p_i = {v_i, v_{i+1+i%2}, v_{i+2-i%2}}: (0,1,2), then (1,3,2).
  EXPECT_EQ(s.meshes[0].triangles[0].p[2], glm::dvec3(0, 1, 0));
  EXPECT_EQ(s.meshes[0].triangles[1].p[0], glm::dvec3(1, 0, 0));
  EXPECT_EQ(s.meshes[0].triangles[1].p[1], glm::dvec3(1, 1, 0));
  EXPECT_EQ(s.meshes[0].triangles[1].p[2], glm::dvec3(0, 1, 0));
  for (const MeshTriangle& t : s.meshes[0].triangles)
    EXPECT_GT(glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]).z, 0.0);
  // Normalised UNSIGNED_BYTE texcoords: 255 -> 1.
  EXPECT_EQ(s.meshes[0].triangles[1].uv[1], glm::dvec2(1, 1));
  EXPECT_EQ(s.meshes[0].triangles[0].uv[1], glm::dvec2(1, 0));
  // The 2x1 PNG (white, black) has linear mean 0.5; reflectance = 1 x 0.5.
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].width, 2);
  EXPECT_NEAR(s.textures[0].mean.x, 0.5, 1e-12);
  EXPECT_NEAR(s.materials[0].reflectance.y, 0.5, 1e-12);
  auto polys = s.inputPolygons();
  ASSERT_EQ(polys.size(), 1u);
  EXPECT_NEAR(polys[0].local.area(), 1.0, 1e-12);
}

}  // namespace
// glTF NORMAL (§3.7.2.1): read as the vertex shading normals, normalised; a triangle whose
// normals are its flat normal is flat; a NORMAL that is not VEC3 is one line.
TEST_F(BadInput, NormalsAreReadNormalisedAndCheckedForType) {
  std::string bin = triangleBin();                         // 44 bytes
  float n[9] = {0, 0, 2, 0.6f, 0, 0.8f, 0, 0, 1};          // not unit at vertex 0
  bin.append(reinterpret_cast<const char*>(n), sizeof n);  // 44..79
  write("tri.bin", bin);
  auto gltf = [](const std::string& type) {
    return R"({"asset": {"version": "2.0"}, "nodes": [{"mesh": 0}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 2}, "indices": 1}]}],
      "buffers": [{"uri": "tri.bin", "byteLength": 80}],
      "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                      {"buffer": 0, "byteOffset": 36, "byteLength": 8},
                      {"buffer": 0, "byteOffset": 44, "byteLength": 36}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 3,
                     "min": [0,0,0], "max": [1,1,0]},
                    {"bufferView": 1, "componentType": 5123, "type": "SCALAR", "count": 3},
                    {"bufferView": 2, "componentType": 5126, "type": ")" +
           type + R"(", "count": 3}]})";
  };
  Scene s = readGltfScene(write("n.gltf", gltf("VEC3")));
  ASSERT_EQ(s.meshes[0].triangles.size(), 1u);
  const MeshTriangle& t = s.meshes[0].triangles[0];
  EXPECT_EQ(t.normal[0], glm::dvec3(0, 0, 1));
  EXPECT_NEAR(t.normal[1].x, 0.6, 1e-7);
  EXPECT_NEAR(glm::length(t.normal[1]), 1.0, 1e-12);
  const InputPolygon p = s.inputPolygons()[0];
  EXPECT_NEAR(shadingNormalAt(p, {0, 0}).z, 1.0, 1e-12);
  EXPECT_GT(shadingNormalAt(p, {1, 0}).x, 0.5);
  expectBadInput(write("n2.gltf", gltf("VEC2")), "NORMAL is not VEC3");
}

namespace {

// ---------------------------------------------------------------- hostile input (issue 18)

// The triangle with material 0 given by `material` (a JSON object).
std::string withMaterial(const std::string& gltf, const std::string& material) {
  std::string out = gltf;
  const std::string key = "\"indices\": 1}";
  out.replace(out.find(key), key.size(), "\"indices\": 1, \"material\": 0}");
  return out.substr(0, out.size() - 1) + ", \"materials\": [" + material + "]}";
}

std::string glbOf(const std::string& json, const std::string& bin) {
  std::string j = json, b = bin;
  while (j.size() % 4) j += ' ';
  while (b.size() % 4) b += '\0';
  auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  return "glTF" + u32(2) + u32(uint32_t(12 + 8 + j.size() + 8 + b.size())) +
         u32(uint32_t(j.size())) + "JSON" + j + u32(uint32_t(b.size())) + std::string("BIN\0", 4) +
         b;
}

// nlohmann's recursion under tinygltf overflowed the stack (SIGSEGV) at 100,000 levels.
TEST_F(BadInput, DeepJsonNestingIsOneLine) {
  write("tri.bin", triangleBin());
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  std::string gltf = triangleGltf(", \"extras\": " + deep);
  expectBadInput(write("deep.gltf", gltf), "JSON nested deeper than 256 levels");
  // Brackets inside strings (escaped quotes too) do not count; 200 levels load.
  const std::string fine = std::string(200, '[') + std::string(200, ']');
  Scene s =
      readGltfScene(write("fine.gltf", triangleGltf(", \"extras\": [\"\\\"[[[[\", " + fine + "]")));
  EXPECT_EQ(s.meshes[0].triangles.size(), 1u);
  // The .glb's JSON chunk is checked the same way (its buffer is the BIN chunk).
  std::string json = triangleGltf(", \"extras\": " + deep, "", "\"count\": 3", 44);
  const std::string uri = "\"uri\": \"tri.bin\", ";
  json.erase(json.find(uri), uri.size());
  expectBadInput(write("deep.glb", glbOf(json, triangleBin())), "nested deeper than 256");
}

// Embree aborted (ray.valid()) on positions of 3e38 and a translation of 1e38.
TEST_F(BadInput, CoordinatesBeyondTheLimitAreOneLine) {
  std::string bin = triangleBin();
  float big = 3e38f;
  std::memcpy(&bin[12], &big, 4);
  write("big.bin", bin);
  std::string gltf = triangleGltf();
  gltf.replace(gltf.find("tri.bin"), 7, "big.bin");
  expectBadInput(write("big.gltf", gltf), "vertex coordinate 3e+38 beyond the limit 1e+15");
  write("tri.bin", triangleBin());
  expectBadInput(write("t.gltf", triangleGltf("", ", \"translation\": [1e38, 0, 0]")),
                 "node 0: world coordinates reach up to 1e+38");
  // Each factor within the limit, their product not: a parent's scale times a child's position.
  const std::string nested =
      R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [1]}],
    "nodes": [{"mesh": 0, "translation": [1e9, 0, 0]}, {"children": [0], "scale": [1e9, 1e9, 1e9]}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "buffers": [{"uri": "tri.bin", "byteLength": 44}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                    {"buffer": 0, "byteOffset": 36, "byteLength": 8}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 3},
                  {"bufferView": 1, "componentType": 5123, "type": "SCALAR", "count": 3}]})";
  expectBadInput(write("nested.gltf", nested), "node 0: world coordinates reach up to 1e+18");
  // A scale of 0 flattens the triangle: its world normal would be NaN.
  expectBadInput(write("flat.gltf", triangleGltf("", ", \"scale\": [1, 0, 1]")),
                 "flattens triangle 0 of mesh 0 to zero area");
  // A legitimate large scene (10 km, mm geometry under a 1000x scale) loads.
  Scene s = readGltfScene(write(
      "ok.gltf", triangleGltf("", ", \"translation\": [1e4, 0, 0], \"scale\": [1e3, 1e3, 1e3]")));
  EXPECT_EQ(s.meshes[0].triangles.size(), 1u);
}

// An animated translation key of 1e38 (the camera's or a mesh node's) is refused the same way.
TEST_F(BadInput, AnimatedTranslationBeyondTheLimit) {
  const float values[6] = {0, 0, 0, 1e38f, 0, 0};
  const std::string gltf = animatedTriangleGltf("translation", values);
  expectBadInput(write("anim.gltf", gltf), "node 0: world coordinates reach up to 1e+38");
}

// An emissiveStrength of 1e308 gave an infinite emitter power and NaN radiosity with exit 0.
TEST_F(BadInput, EmissionBeyondTheLimitIsOneLine) {
  write("tri.bin", triangleBin());
  const std::string mat = R"({"emissiveFactor": [1, 0.5, 0],
      "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 1e308}}})";
  expectBadInput(
      write("e.gltf", withMaterial(triangleGltf(), mat)),
      "material 0: emission (emissiveFactor x emissiveStrength) 1e+308 beyond the limit");
  const std::string fine = R"({"emissiveFactor": [1, 0.5, 0],
      "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 1e6}}})";
  Scene s = readGltfScene(write("ok.gltf", withMaterial(triangleGltf(), fine)));
  EXPECT_EQ(s.materials[0].emission, glm::dvec3(1e6, 5e5, 0));
}

// rho = 1 with emission diverges; clamped to kMaxReflectance with one warning.
TEST_F(BadInput, ReflectanceOneIsClampedWithAWarning) {
  write("tri.bin", triangleBin());
  Scene s = readGltfScene(
      write("w.gltf",
            withMaterial(triangleGltf(),
                         R"({"pbrMetallicRoughness": {"baseColorFactor": [1, 0.5, 0.999, 1]}})")));
  EXPECT_EQ(s.materials[0].reflectance, glm::dvec3(kMaxReflectance, 0.5, 0.999));
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0],
            "material 0: reflectance 1 clamped to 0.999 (the radiosity solve needs rho < 1)");
}

// tinygltf read a negative (or fractional) byteOffset as 0 without a word: the view then read
// another mesh's bytes.
TEST_F(BadInput, NegativeByteOffsetIsOneLine) {
  write("tri.bin", triangleBin());
  std::string gltf = triangleGltf();
  gltf.replace(gltf.find("\"byteOffset\": 36"), 16, "\"byteOffset\": -8");
  expectBadInput(write("neg.gltf", gltf),
                 "bufferView 1: byteOffset -8 is not a non-negative integer");
  std::string json = triangleGltf("", "", "\"count\": 3, \"byteOffset\": 2.5");
  const std::string uri = "\"uri\": \"tri.bin\", ";
  json.erase(json.find(uri), uri.size());
  expectBadInput(write("frac.glb", glbOf(json, triangleBin())),
                 "accessor 0: byteOffset 2.5 is not a non-negative integer");
}

// POSITION of unsigned bytes read 0..255 "metres" from a float buffer: garbage geometry.
TEST_F(BadInput, QuantizedPositionIsOneLine) {
  write("tri.bin", triangleBin());
  std::string gltf = triangleGltf();
  gltf.replace(gltf.find("\"componentType\": 5126"), 21, "\"componentType\": 5121");
  expectBadInput(write("q.gltf", gltf), "mesh 0 primitive 0: POSITION has component type 5121");
}

// TRIANGLE_FAN (glTF 3.7.2): p_i = {v_{i+1}, v_{i+2}, v_0}; a square of 4 vertices, 2 triangles.
TEST_F(BadInput, TriangleFanIsTriangulatedBySpec) {
  float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  write("fan.bin", std::string(reinterpret_cast<const char*>(pos), sizeof pos));
  const std::string gltf = R"({"asset": {"version": "2.0"}, "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 6}]}],
    "buffers": [{"uri": "fan.bin", "byteLength": 48}],
    "bufferViews": [{"buffer": 0, "byteLength": 48}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 4}]})";
  Scene s = readGltfScene(write("fan.gltf", gltf));
  ASSERT_EQ(s.meshes[0].triangles.size(), 2u);
  EXPECT_EQ(s.meshes[0].triangles[1].p[0], glm::dvec3(1, 1, 0));
  EXPECT_EQ(s.meshes[0].triangles[1].p[2], glm::dvec3(0, 0, 0));
  for (const MeshTriangle& t : s.meshes[0].triangles)
    EXPECT_GT(glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]).z, 0.0);
}

long peakMemoryMb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024;
}

// A count of 2^25 on a 48-byte view allocated 800 MB before its error (2^28: 6.4 GB).
TEST_F(BadInput, HugeCountsFailBeforeAllocating) {
  write("tri.bin", triangleBin());
  expectBadInput(write("c.gltf", triangleGltf("", "", "\"count\": 268435456")),
                 "268435456 elements at offset 0 exceed bufferView 0 (36 bytes)");
  // Without a bufferView the elements are zeros taking no bytes: bounded.
  std::string gltf = triangleGltf("", "", "\"count\": 268435456");
  gltf.replace(gltf.find("\"bufferView\": 0, "), 17, "");
  expectBadInput(write("z.gltf", gltf), "268435456 elements without a bufferView");
  EXPECT_LT(peakMemoryMb(), 200);
}

// A failed data URI was echoed whole: a 12.5 KB error line.
TEST_F(BadInput, LongInputIsClippedInMessages) {
  std::string gltf = triangleGltf();
  gltf.replace(gltf.find("tri.bin"), 7,
               "data:application/octet-stream;base64," + std::string(12000, 'A') + "!!");
  try {
    readGltfScene(write("uri.gltf", gltf));
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_LT(what.size(), 700u) << what.size();
    EXPECT_NE(what.find("Failed to decode 'uri'"), std::string::npos) << what;
    EXPECT_NE(what.find("AAAA…"), std::string::npos) << what;
  }
}

// KHR_lights_punctual lights are read (issue 57): a scene with lamps and no emissive surface is
// lit; the extension may be required; a light without a node lights nothing.
TEST_F(BadInput, PunctualLightsAreReadAndLightTheScene) {
  write("tri.bin", triangleBin());
  const std::string lights = R"(, "extensionsUsed": ["KHR_lights_punctual"],
      "extensionsRequired": ["KHR_lights_punctual"],
      "extensions": {"KHR_lights_punctual": {"lights": [
        {"type": "point", "color": [1, 0.5, 0.25], "intensity": 4, "range": 3},
        {"type": "spot", "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}}]}})";
  Scene unplaced = readGltfScene(write("dark.gltf", triangleGltf(lights)));
  ASSERT_EQ(unplaced.lights.size(), 2u);
  EXPECT_EQ(unplaced.lights[0].intensity, glm::dvec3(4.0, 2.0, 1.0));
  EXPECT_EQ(unplaced.lights[0].range, 3.0);
  EXPECT_EQ(unplaced.lights[1].type, PunctualLightType::kSpot);
  EXPECT_EQ(unplaced.lights[1].outerConeAngle, 0.5);
  EXPECT_EQ(unplaced.lightUnits, "gltf");
  EXPECT_EQ(missingEmitterMessage(unplaced),
            "no emissive material and no KHR_lights_punctual light of non-zero intensity on a "
            "node of the scene: give a mesh an emissive material (emissiveFactor) or add a lamp");
  EXPECT_THROW(requireEmitter(unplaced), Error);
  const std::string placed =
      triangleGltf(lights, R"(, "extensions": {"KHR_lights_punctual": {"light": 1}})");
  Scene lit = readGltfScene(write("lit.gltf", placed));
  EXPECT_EQ(lit.nodes[0].light, 1);
  EXPECT_EQ(lit.lightNodes(), std::vector<int>{0});
  EXPECT_EQ(missingEmitterMessage(lit), "");
  EXPECT_NO_THROW(requireEmitter(lit));
  expectBadInput(write("bad.gltf", triangleGltf(lights, R"(, "extensions":
                 {"KHR_lights_punctual": {"light": 7}})")),
                 "node 0: light 7 out of range (2 lights)");
}

// A Blender export's lamps are in Blender's units (gltf_lights.h): auto reads them by the
// generator, /683, and its spots take Cycles' profile.
TEST_F(BadInput, BlenderLampUnitsAreDetected) {
  write("tri.bin", triangleBin());
  const std::string lights = R"(, "extensionsUsed": ["KHR_lights_punctual"],
      "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 683},
        {"type": "spot", "intensity": 6830, "spot": {"outerConeAngle": 0.5}}]}})";
  std::string gltf = triangleGltf(lights);
  gltf.replace(gltf.find("\"asset\": {"), 10,
               R"("asset": {"generator": "Khronos glTF Blender I/O v3.4.50", )");
  const std::string path = write("blender.gltf", gltf);
  Scene s = readGltfScene(path);
  EXPECT_EQ(s.lightUnits, "blender");
  EXPECT_DOUBLE_EQ(s.lights[0].intensity.x, 1.0);
  EXPECT_DOUBLE_EQ(s.lights[1].intensity.x, 10.0);
  EXPECT_EQ(s.lights[1].profile, SpotProfile::kCycles);
  GltfReadOptions asGltf;
  asGltf.lightUnits = LightUnits::kGltf;
  Scene g = readGltfScene(path, asGltf);
  EXPECT_EQ(g.lights[0].intensity.x, 683.0);
  EXPECT_EQ(g.lights[1].profile, SpotProfile::kGltf);
}

// An animated scale (squash and stretch) is an affine motion of a dynamic node (issue 57: it was
// refused); a constant one is a static scale.
TEST_F(BadInput, AnimatedScaleIsAnAffineMotion) {
  auto scene = [&](float second) {
    const float values[6] = {2, 2, 2, second, 2, 2};
    return write("s.gltf", animatedTriangleGltf("scale", values));
  };
  Scene squash = readGltfScene(scene(3.0f));
  EXPECT_TRUE(squash.isDynamic(0, 0.0, 1.0));
  EXPECT_NEAR(scaleX(squash.worldTransform(0, 0.5)), 2.5, 1e-12);
  // A constant scale (2, held by the channel) is a static scale: loads, world area x 4.
  Scene s = readGltfScene(scene(2.0f));
  ASSERT_EQ(s.channels.size(), 1u);
  EXPECT_FALSE(s.isDynamic(0, 0.0, 1.0));
  EXPECT_NEAR(scaleX(s.worldTransform(0, 0.5)), 2.0, 1e-12);
}

}  // namespace

}  // namespace rad
