// Emissive textures modulate the emitted radiance (issue 57, libcommon/scene/emission_texture.h):
// a textured screen shows its picture in rad-compose's frame, and emits the power of its
// texture's mean x strength x area (the first pass's B_e). It glowed one flat colour, with a
// warning.
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <stb/stb_image_write.h>
#include <nlohmann/json.hpp>

#include "formats/exr_image.h"
#include "formats/frame_image.h"
#include "tests/cli/cli_util.h"
#include "tests/cli/gltf_builder.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

constexpr double kStrength = 10.0;

void appendBytes(void* context, void* data, int size) {
  static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size));
}

// A screen [-0.5, 0.5]^2 at z = 0 facing +z whose emissive texture is 2 x 1 texels, black then
// white (mean 0.5), strength kStrength; a grey floor under it; a camera 2 m in front.
std::string writeScreen(const fs::path& dir) {
  const unsigned char pixels[6] = {0, 0, 0, 255, 255, 255};
  std::string png;
  stbi_write_png_to_func(&appendBytes, &png, 2, 1, 3, pixels, 6);
  GltfBuilder g;
  g.doc()["extensionsUsed"] = {"KHR_materials_emissive_strength"};
  g.doc()["images"] = {{{"uri", "data:image/png;base64," + base64Encoded(png)}}};
  g.doc()["textures"] = {{{"source", 0}}};
  const int screen = g.addMaterial(
      {{"name", "Screen"},
       {"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}}},
       {"emissiveFactor", {1, 1, 1}},
       {"emissiveTexture", {{"index", 0}}},
       {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", kStrength}}}}}});
  const int grey = g.addMaterial(
      {{"name", "Floor"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1}}}}});
  // glTF's v runs down the image: v = 0.5 - y.
  g.addNode({{"name", "Screen"},
             {"mesh",
              g.addMesh("Screen", {{-0.5, -0.5, 0}, {0.5, -0.5, 0}, {0.5, 0.5, 0}, {-0.5, 0.5, 0}},
                        {0, 1, 2, 0, 2, 3}, screen, {{0, 1}, {1, 1}, {1, 0}, {0, 0}})}});
  g.addNode(
      {{"name", "Floor"},
       {"mesh", g.addMesh("Floor", {{-2, -0.6, -2}, {-2, -0.6, 2}, {2, -0.6, 2}, {2, -0.6, -2}},
                          {0, 1, 2, 0, 2, 3}, grey)}});
  g.addCamera({{"yfov", 0.8}, {"znear", 0.05}}, {{"name", "Camera"}, {"translation", {0, 0, 2}}});
  fs::create_directories(dir);
  return g.write((dir / "screen.gltf").string());
}

class EmissiveTexture : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("rad_emissive_texture_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    scene = writeScreen(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  fs::path dir;
  std::string scene;
};

TEST_F(EmissiveTexture, PowerIsTheTexturesMeanTimesStrengthTimesArea) {
  CommandResult r = runCommand(tool("rad-inspect") + " --json " + scene);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["warnings"].empty()) << j["warnings"].dump();  // no "emissiveTexture ignored"
  ASSERT_EQ(j["emitters"].size(), 1u) << j.dump();
  for (int c = 0; c < 3; ++c)  // pi x L_e mean (0.5 x strength) x 1 m^2
    EXPECT_NEAR(j["emitters"][0]["power_w"][c].get<double>(), M_PI * 0.5 * kStrength * 1.0, 1e-9);
}

TEST_F(EmissiveTexture, FrameShowsTheTexture) {
  const std::string d = dir.string(), size = " --size 88x60 --pixel-filter none";
  for (const std::string& cmd :
       {tool("rad-global") + " " + scene + " -o " + d + "/global.rlh",
        tool("rad-intervals") + " " + scene + " -o " + d + "/intervals.rti" + size,
        tool("rad-movies") + " " + scene + " " + d + "/global.rlh " + d + "/intervals.rti -o " + d +
            "/movies",
        tool("rad-compose") + " " + scene + " " + d + "/global.rlh " + d + "/intervals.rti " + d +
            "/movies -o " + d + "/frames"}) {
    const CommandResult r = runCommand(cmd);
    ASSERT_EQ(r.exitCode, 0) << cmd << "\n" << r.err;
  }
  const FloatImage f = readExrImage(framePath(d + "/frames", 0, ".exr"));
  // The texel centres u = 1/4 (black) and 3/4 (white) at x = -1/4 and 1/4 on the screen, 2 m
  // from the eye: columns 44 (1 + x / (2 tan 0.4 x 88/60)).
  const double halfWidth = 2.0 * std::tan(0.4) * 88.0 / 60.0;
  const auto at = [&](double x) {
    const int col = int(44.0 * (1.0 + x / halfWidth));
    return f.pixels[3 * (size_t(30) * f.width + size_t(col))];
  };
  EXPECT_LT(at(-0.25), 0.1 * kStrength) << "black texel";
  EXPECT_GT(at(0.25), 0.9 * kStrength) << "white texel";
}

}  // namespace
}  // namespace rad::test
