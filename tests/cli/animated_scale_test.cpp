// An animated scale (squash and stretch) is an affine motion of a dynamic object and is
// rendered (issue 57: the reader refused it, naming `node 8`). A box on a floor squashes to half
// its height and widens; the pipeline's frames between key times agree with rad-reference's,
// which shares only the scene model and the camera with it, and the box's outline changes.
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "formats/exr_image.h"
#include "formats/frame_image.h"
#include "tests/cli/cli_util.h"
#include "tests/cli/gltf_builder.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

// A 4 m floor, a 1 m square ceiling lamp 2 m up, and a box [-0.3, 0.3] x [0, 0.6] x [-0.3, 0.3]
// whose scale goes from 1 to (1.6, 0.5, 1.6) over 1 s (its base stays on the floor), seen from
// the front and above.
std::string writeSquash(const fs::path& dir) {
  GltfBuilder g;
  g.doc()["extensionsUsed"] = {"KHR_materials_emissive_strength"};
  const int grey = g.addMaterial(
      {{"name", "Grey"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.6, 0.6, 0.6, 1}}}}});
  const int red = g.addMaterial(
      {{"name", "Red"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.7, 0.2, 0.1, 1}}}}});
  const int lamp = g.addMaterial(
      {{"name", "Lamp"},
       {"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}}},
       {"emissiveFactor", {1, 1, 1}},
       {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 8}}}}}});
  g.addNode({{"name", "Floor"},
             {"mesh", g.addMesh("Floor", {{-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}},
                                {0, 1, 2, 0, 2, 3}, grey)}});
  g.addNode(
      {{"name", "Lamp"},
       {"mesh", g.addMesh("Lamp", {{-0.5, 2, -0.5}, {0.5, 2, -0.5}, {0.5, 2, 0.5}, {-0.5, 2, 0.5}},
                          {0, 1, 2, 0, 2, 3}, lamp)}});
  std::vector<glm::vec3> box;
  std::vector<uint32_t> indices;
  boxTriangles({-0.3, 0.0, -0.3}, {0.3, 0.6, 0.3}, box, indices);
  const int squash = g.addNode({{"name", "Squash"}, {"mesh", g.addMesh("Box", box, indices, red)}});
  g.addAnimation(squash, "scale", {0.0f, 1.0f}, {1, 1, 1, 1.6f, 0.5f, 1.6f});
  // 2.6 m in front, 1.4 m up, looking 0.45 rad down.
  g.addCamera({{"yfov", 0.9}, {"znear", 0.05}}, {{"name", "Camera"},
                                                 {"translation", {0, 1.4, 2.6}},
                                                 {"rotation", {-0.2231154, 0, 0, 0.9747902}}});
  fs::create_directories(dir);
  return g.write((dir / "squash.gltf").string());
}

class AnimatedScale : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("rad_animated_scale_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    scene = writeSquash(dir);
  }
  void TearDown() override {
    if (!std::getenv("RAD_KEEP_TEST_DIR")) fs::remove_all(dir);
  }
  void run(const std::string& cmd) {
    const CommandResult r = runCommand(cmd);
    ASSERT_EQ(r.exitCode, 0) << cmd << "\n" << r.err;
  }
  fs::path dir;
  std::string scene;
};

TEST_F(AnimatedScale, PipelineAgreesWithTheReferenceWhileTheBoxSquashes) {
  const std::string d = dir.string(), frames = " --frames 0-23", size = " --size 88x60";
  run(tool("rad-global") + " " + scene + " -o " + d + "/global.rlh" + frames);
  run(tool("rad-intervals") + " " + scene + " -o " + d + "/intervals.rti" + frames + size +
      " --pixel-filter none");
  run(tool("rad-movies") + " " + scene + " " + d + "/global.rlh " + d + "/intervals.rti -o " + d +
      "/movies");
  run(tool("rad-compose") + " " + scene + " " + d + "/global.rlh " + d + "/intervals.rti " + d +
      "/movies -o " + d + "/frames --frames 5-18x13");
  for (const char* seed : {"1", "2"})
    run(tool("rad-reference") + " " + scene + " -o " + d + "/ref" + seed + " --frames 5-18x13" +
        size + " --pixel-filter none --spp 256 --seed " + seed);
  for (int f : {5, 18}) {
    const std::string test = framePath(d + "/frames", f, ".exr");
    const CommandResult r =
        runCommand(tool("rad-diff") + " " + test + " " + framePath(d + "/ref1", f, ".exr") +
                   " --ref2 " + framePath(d + "/ref2", f, ".exr") + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    const double rmse = j["difference"]["rmse_over_mean"].get<double>();
    const double bias = j["difference"]["bias"].get<double>();
    EXPECT_LT(rmse, 0.06) << "frame " << f << ": " << r.out;
    EXPECT_LT(std::abs(bias), 0.03) << "frame " << f << ": " << r.out;
  }
  // The box squashed: frames 5 and 18 differ (in both renderers, by the same pixels).
  const FloatImage a = readExrImage(framePath(d + "/frames", 5, ".exr"));
  const FloatImage b = readExrImage(framePath(d + "/frames", 18, ".exr"));
  EXPECT_NE(a.pixels, b.pixels);
}

}  // namespace
}  // namespace rad::test
