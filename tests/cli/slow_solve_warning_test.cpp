// rad-global warns, naming the material by its glTF name and index, when a reflectance is
// clamped and when a closed double-sided mesh makes a cavity that slows the solve, with what it
// costs (issue 57: a white, closed lamp shade, double-sided as Blender exports every material,
// took the solve from tens of sweeps to thousands, and only rad-inspect mentioned the clamp).
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/cli/cli_util.h"
#include "tests/cli/gltf_builder.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

// A grey floor lit by a ceiling panel, a closed white box (the shade, base colour 1.0 unless
// `shadeColour` says otherwise) on it with an emissive bulb inside, and a camera.
std::string writeShadeScene(const fs::path& dir, bool doubleSided, double shadeColour = 1.0,
                            bool openBottom = false) {
  GltfBuilder g;
  const int grey =
      g.addMaterial({{"name", "Floor"},
                     {"doubleSided", true},
                     {"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1}}}}});
  nlohmann::json white = {{"name", "White"}, {"doubleSided", doubleSided}};
  if (shadeColour != 1.0)
    white["pbrMetallicRoughness"] = {
        {"baseColorFactor", {shadeColour, shadeColour, shadeColour, 1}}};
  const int shade = g.addMaterial(white);
  const int glow = g.addMaterial({{"name", "Bulb"},
                                  {"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}}},
                                  {"emissiveFactor", {1, 1, 1}}});
  const std::vector<glm::vec3> floor = {{-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}};
  g.addNode({{"name", "Floor"}, {"mesh", g.addMesh("Floor", floor, {0, 1, 2, 0, 2, 3}, grey)}});
  const std::vector<glm::vec3> panel = {
      {-0.5, 2.5, -0.5}, {0.5, 2.5, -0.5}, {0.5, 2.5, 0.5}, {-0.5, 2.5, 0.5}};
  g.addNode({{"name", "Panel"}, {"mesh", g.addMesh("Panel", panel, {0, 1, 2, 0, 2, 3}, glow)}});
  std::vector<glm::vec3> box;
  std::vector<uint32_t> boxIndices;
  boxTriangles({-0.25, 0.3, -0.25}, {0.25, 0.7, 0.25}, box, boxIndices);
  if (openBottom) boxIndices.erase(boxIndices.begin() + 12, boxIndices.begin() + 18);  // y = lo
  g.addNode({{"name", "Shade"}, {"mesh", g.addMesh("ShadeMesh", box, boxIndices, shade)}});
  std::vector<glm::vec3> bulb;
  std::vector<uint32_t> bulbIndices;
  boxTriangles({-0.03, 0.47, -0.03}, {0.03, 0.53, 0.03}, bulb, bulbIndices);
  g.addNode({{"name", "Bulb"}, {"mesh", g.addMesh("Bulb", bulb, bulbIndices, glow)}});
  g.addCamera({{"yfov", 0.8}, {"znear", 0.05}}, {{"name", "Camera"}, {"translation", {0, 1, 4}}});
  fs::create_directories(dir);
  return g.write((dir / "shade.gltf").string());
}

// rad-global's messages before its solve (--print-windows reads the scene and stops).
std::string globalMessages(const std::string& scene, const fs::path& dir) {
  CommandResult r = runCommand(tool("rad-global") + " " + scene + " -o " +
                               (dir / "g.rlh").string() + " --print-windows 1");
  EXPECT_EQ(r.exitCode, 0) << r.err;
  return r.err;
}

class SlowSolveWarning : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("rad_slow_solve_" + std::to_string(::getpid()));
    fs::remove_all(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  fs::path dir;
};

TEST_F(SlowSolveWarning, ClosedWhiteDoubleSidedShadeIsNamedWithItsCost) {
  const std::string scene = writeShadeScene(dir, true);
  const std::string err = globalMessages(scene, dir);
  // The clamp, naming the material.
  EXPECT_NE(err.find("rad-global: " + scene +
                     ": warning: material \"White\" (1): reflectance 1 clamped to 0.999"),
            std::string::npos)
      << err;
  // The cavity, naming mesh, node and material, with its cost.
  EXPECT_NE(err.find("rad-global: " + scene +
                     ": warning: mesh \"ShadeMesh\" (2) of node \"Shade\" "
                     "(2) is closed around a light and its inside reflects 0.982673 (material "
                     "\"White\" (1) is double-sided): light inside it bounces about 1/(1 - rho) "
                     "= 58 times, and the solve needs about 759 sweeps where reflectance 0.8 "
                     "needs 48; "),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("tick \"Backface Culling\""), std::string::npos) << err;
  EXPECT_EQ(countLines(err), 2) << err;  // the two warnings, then the windows on stdout
}

TEST_F(SlowSolveWarning, NoCavityNoWarning) {
  // One-sided: the inside absorbs. Open: light leaves. Blender's default 0.8: a few tens of sweeps.
  for (const std::string& scene :
       {writeShadeScene(dir / "one-sided", false), writeShadeScene(dir / "open", true, 1.0, true),
        writeShadeScene(dir / "grey", true, 0.8)}) {
    const std::string err = globalMessages(scene, dir);
    EXPECT_EQ(err.find("is closed"), std::string::npos) << scene << "\n" << err;
  }
}

}  // namespace
}  // namespace rad::test
