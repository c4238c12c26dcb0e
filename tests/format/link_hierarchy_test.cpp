// global.rlh: write / read round trip, a truncated file and a file for another scene are
// one-line errors.
#include "formats/link_hierarchy.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "formats/gltf_scene.h"
#include "formats/provenance.h"
#include "libcommon/core/error.h"
#include "libcommon/radiosity/space_time_radiosity.h"

namespace rad {
namespace {

std::string scenePath() {
  return std::string(RAD_SOURCE_DIR) + "/pipelines/scenes/cornell-moving.gltf";
}

std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("rad_linkhier_" + name)).string();
}

GlobalSolution solution(const Scene& scene) {
  SpaceTimeOptions o;
  o.radiosity.eps = 1e-2;
  o.radiosity.minArea = 1e-3;
  o.radiosity.rays = 4;
  return solveSpaceTime(scene, {0.0, 0.25, 0.5}, o);
}

// What both reads give: key times, the hierarchy's ids, the node radiosity and leaf rows.
void expectSameRadiosity(const GlobalSolution& r, const GlobalSolution& g) {
  EXPECT_EQ(r.keyTimes, g.keyTimes);
  ASSERT_EQ(r.hierarchy.size(), g.hierarchy.size());
  for (int i = 0; i < g.hierarchy.size(); ++i)
    EXPECT_EQ(r.hierarchy.node(i).id, g.hierarchy.node(i).id);
  EXPECT_EQ(r.nodeRadiosity, g.nodeRadiosity);
  EXPECT_EQ(r.leafRow, g.leafRow);
}

Provenance provenance() {
  const char* argv[] = {"rad-global", "scene.gltf"};
  Provenance p = makeProvenance("rad-global", 2, argv, {{"eps", 1e-2}});
  addInput(p, scenePath());
  return p;
}

TEST(LinkHierarchy, RoundTrip) {
  Scene scene = readGltfScene(scenePath());
  GlobalSolution g = solution(scene);
  std::string path = tempPath("roundtrip.rlh");
  writeLinkHierarchy(path, g, provenance(), {{"note", "test"}});
  GlobalSolution r = readLinkHierarchy(path, scene);
  expectSameRadiosity(r, g);
  EXPECT_EQ(r.leafVertexGoodIrradiance, g.leafVertexGoodIrradiance);
  ASSERT_EQ(r.links.size(), g.links.size());
  for (size_t i = 0; i < g.links.size(); ++i) {
    EXPECT_EQ(r.links[i].receiver, g.links[i].receiver);
    EXPECT_EQ(r.links[i].shooter, g.links[i].shooter);
    EXPECT_EQ(r.links[i].firstKey, g.links[i].firstKey);
    EXPECT_EQ(r.links[i].lastKey, g.links[i].lastKey);
    EXPECT_EQ(r.links[i].sampleOffset, g.links[i].sampleOffset);
    EXPECT_EQ(r.links[i].sampleCount, g.links[i].sampleCount);
    EXPECT_EQ(r.links[i].flags, g.links[i].flags);
  }
  EXPECT_EQ(r.linkSampleKeys, g.linkSampleKeys);
  EXPECT_EQ(r.linkSampleValues, g.linkSampleValues);
  EXPECT_EQ(r.linkSampleVisibility, g.linkSampleVisibility);
  EXPECT_EQ(r.nodeExposure, g.nodeExposure);
  EXPECT_EQ(r.badPairs, g.badPairs);
  EXPECT_GT(g.hierarchy.size(), g.hierarchy.topCount());
  // Queries answer the same.
  EXPECT_EQ(r.goodIrradiance(0, {0.3, 0.6}, 0.1), g.goodIrradiance(0, {0.3, 0.6}, 0.1));

  // rad-compose's read: the same hierarchy and radiosity, nothing of the links.
  GlobalSolution c = readLinkHierarchyRadiosity(ContainerReader::open(path), scene);
  expectSameRadiosity(c, g);
  EXPECT_EQ(c.radiosity(3, 0.1), g.radiosity(3, 0.1));
  EXPECT_FALSE(g.links.empty());
  EXPECT_TRUE(c.links.empty());
  EXPECT_TRUE(c.linkSampleKeys.empty());
  EXPECT_TRUE(c.linkSampleValues.empty());
  EXPECT_TRUE(c.leafVertexGoodIrradiance.empty());
  std::filesystem::remove(path);
}

TEST(LinkHierarchy, TruncatedFileIsOneLineError) {
  Scene scene = readGltfScene(scenePath());
  GlobalSolution g = solution(scene);
  std::string path = tempPath("trunc.rlh");
  writeLinkHierarchy(path, g, provenance(), {});
  auto size = std::filesystem::file_size(path);
  for (auto keep : {size - 1, size / 2, uintmax_t(20)}) {
    std::filesystem::resize_file(path, keep);
    try {
      readLinkHierarchy(path, scene);
      FAIL() << "no error for a file truncated to " << keep;
    } catch (const Error& e) {
      std::string m = e.what();
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
      EXPECT_NE(m.find(path), std::string::npos) << m;
      EXPECT_EQ(e.code(), ExitCode::kBadInput);
    }
  }
  std::filesystem::remove(path);
}

TEST(LinkHierarchy, WrongSceneIsError) {
  Scene scene = readGltfScene(scenePath());
  GlobalSolution g = solution(scene);
  std::string path = tempPath("wrong.rlh");
  writeLinkHierarchy(path, g, provenance(), {});
  Scene other = scene;
  other.nodes[size_t(other.meshNodes().back())].mesh = -1;  // one object fewer
  try {
    readLinkHierarchy(path, other);
    FAIL() << "no error for another scene";
  } catch (const Error& e) {
    std::string m = e.what();
    EXPECT_NE(m.find("top-level patches"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace rad
