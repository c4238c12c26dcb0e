// Scene part digests (libcommon/scene/scene_digest.h): each part changes with what it covers
// and only with that, and a mismatch names the part.
#include "libcommon/scene/scene_digest.h"

#include <gtest/gtest.h>

#include "formats/gltf_scene.h"
#include "libcommon/core/error.h"

namespace rad {
namespace {

const std::string kScene = RAD_SOURCE_DIR "/pipelines/scenes/cornell-moving.gltf";

// The parts whose digests differ between a and b.
std::vector<std::string> changedParts(const Scene& a, const Scene& b) {
  std::vector<std::string> out;
  for (ScenePart p : allSceneParts())
    if (sceneDigest(a, p) != sceneDigest(b, p)) out.push_back(scenePartName(p));
  return out;
}

using Parts = std::vector<std::string>;

TEST(SceneDigest, EachEditChangesItsPartOnly) {
  const Scene base = readGltfScene(kScene);
  EXPECT_EQ(changedParts(base, readGltfScene(kScene)), Parts{});
  Scene s = base;
  s.materials[0].reflectance.x *= 0.5;
  EXPECT_EQ(changedParts(base, s), Parts{"materials"});
  s = base;
  s.materials.back().emission *= 2.0;
  EXPECT_EQ(changedParts(base, s), Parts{"lights"});
  s = base;
  s.meshes[0].triangles[0].p[0].x += 0.01;
  EXPECT_EQ(changedParts(base, s), Parts{"geometry"});
  const int camera = base.cameraNode("");
  ASSERT_GE(camera, 0);
  s = base;
  s.nodes[size_t(camera)].translation.x += 0.1;
  EXPECT_EQ(changedParts(base, s), Parts{"camera"});
  s = base;
  s.cameras[0].yfov *= 0.9;
  EXPECT_EQ(changedParts(base, s), Parts{"camera"});
  s = base;
  ASSERT_FALSE(s.channels.empty());
  s.channels[0].times.back() += 0.5;
  EXPECT_EQ(changedParts(base, s), Parts{"animation"});
}

TEST(SceneDigest, MismatchNamesThePartAndOlderFilesPass) {
  const Scene base = readGltfScene(kScene);
  Scene other = base;
  other.materials[0].reflectance.y *= 0.5;
  const nlohmann::json recorded = sceneDigests(base, {ScenePart::kGeometry, ScenePart::kMaterials});
  EXPECT_EQ(sceneDigestMismatch(recorded, base, "rad-global"), "");
  const std::string m = sceneDigestMismatch(recorded, other, "rad-global");
  EXPECT_EQ(m.rfind("made from a scene whose materials differ (materials digest fnv1a64:", 0), 0u)
      << m;
  EXPECT_NE(m.find("; re-run rad-global"), std::string::npos) << m;
  // Unrecorded parts are not compared; no digests at all (an older file) passes.
  other = base;
  other.cameras[0].yfov *= 0.5;
  EXPECT_EQ(sceneDigestMismatch(recorded, other, "rad-global"), "");
  EXPECT_EQ(sceneDigestMismatch(nullptr, other, "rad-global"), "");
  EXPECT_NO_THROW(requireSceneDigests(nlohmann::json::object(), "old.rlh", "rad-global", other));
  nlohmann::json params = {{kSceneDigestsKey, sceneDigests(base, allSceneParts())}};
  EXPECT_THROW(requireSceneDigests(params, "new.rlh", "rad-global", other), Error);
}

}  // namespace
}  // namespace rad
