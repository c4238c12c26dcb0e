// Messages name glTF items by their glTF name and index (issue 57): `node "Lamp.001" (8)`, so a
// Blender user finds the item in the outliner; the reader's errors said `node 8`.
#include "libcommon/scene/gltf_item_label.h"

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "formats/gltf_scene.h"
#include "libcommon/core/error.h"
#include "tests/cli/gltf_builder.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

std::string readError(const std::string& path) {
  try {
    readGltfScene(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(GltfItemLabel, NameAndIndexOrIndexAlone) {
  EXPECT_EQ(gltfItemLabel("node", 8, "Lamp.001"), "node \"Lamp.001\" (8)");
  EXPECT_EQ(gltfItemLabel("node", 8, ""), "node 8");
  EXPECT_EQ(gltfItemLabel("material", 0, "a\nb"), "material \"a b\" (0)");  // one line
  EXPECT_EQ(gltfItemLabel("mesh", 1, std::string(300, 'x')).size(),
            std::string("mesh \"\" (1)").size() + 120 + std::string("…").size());
}

TEST(GltfItemLabel, ReaderErrorsAndWarningsNameTheItem) {
  const fs::path dir = fs::temp_directory_path() / ("rad_item_label_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  GltfBuilder g;
  const int white = g.addMaterial({{"name", "Shade White"}});  // base colour 1: clamped
  const std::vector<glm::vec3> tri = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const int mesh = g.addMesh("Tri", tri, {0, 1, 2}, white);
  g.addNode({{"name", "Floor"}, {"mesh", mesh}});
  const std::string ok = g.write((dir / "ok.gltf").string());
  const Scene scene = readGltfScene(ok);
  ASSERT_EQ(scene.warnings.size(), 1u);
  EXPECT_EQ(scene.warnings[0].rfind("material \"Shade White\" (0): reflectance 1 clamped", 0), 0u)
      << scene.warnings[0];
  EXPECT_EQ(materialLabel(scene, 0), "material \"Shade White\" (0)");
  EXPECT_EQ(nodeLabel(scene, 0), "node \"Floor\" (0)");
  EXPECT_EQ(meshLabel(scene, 0), "mesh \"Tri\" (0)");
  // A skinned node, named: refused by its name and index.
  g.doc()["nodes"][0]["skin"] = 0;
  g.doc()["skins"] = {{{"joints", {0}}}};
  const std::string skinned = g.write((dir / "skinned.gltf").string());
  EXPECT_NE(readError(skinned).find(": node \"Floor\" (0) has a skin"), std::string::npos)
      << readError(skinned);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rad::test
