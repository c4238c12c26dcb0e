// global.rlh: write / read round trip, a truncated file and a file for another scene are
// one-line errors; the cluster irradiance (1.3) round trips, is optional, and a wrong-size or
// non-finite one is a one-line error.
#include "formats/link_hierarchy.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>

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

// A distinct H_cluster per (top, key): top t at key k is (t + 1, 2 k + 1, 0.5 t + k) / 8.
void setClusterIrradiance(GlobalSolution& g) {
  const int T = g.hierarchy.topCount(), K = g.keyCount();
  g.topClusterIrradiance.resize(size_t(T) * K);
  for (int t = 0; t < T; ++t)
    for (int k = 0; k < K; ++k)
      g.topClusterIrradiance[size_t(t) * K + k] =
          glm::vec3(float(t + 1), float(2 * k + 1), float(0.5 * t + k)) / 8.0f;
}

// The container at `path` as bytes in memory (error messages name `path`), with its kind
// version set to `kindVersion` and the array `name` replaced by `values` (dropped when null).
ContainerReader rewritten(const std::string& path, std::pair<int, int> kindVersion,
                          const std::string& name, const std::vector<float>* values) {
  ContainerReader r = ContainerReader::open(path);
  ContainerWriter w(r.kind(), kindVersion.first, kindVersion.second);
  w.setProvenance(r.provenance());
  w.metadata() = r.metadata();
  for (const ArrayInfo& a : r.arrays())
    if (a.name != name) w.addRaw(a.name, a.dtype, a.shape, r.data(a), a.nbytes);
  if (values) w.addArray(name, *values);
  return ContainerReader::fromBytes(w.serialize(), path);
}

// A one-line input error naming the file and `what`.
void expectOneLineError(const std::function<void()>& f, const std::string& path,
                        const std::string& what) {
  try {
    f();
    FAIL() << "no error; expected one about " << what;
  } catch (const Error& e) {
    std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    EXPECT_NE(m.find(path), std::string::npos) << m;
    EXPECT_NE(m.find(what), std::string::npos) << m;
    EXPECT_EQ(e.code(), ExitCode::kBadInput) << m;
  }
}

TEST(LinkHierarchy, ClusterIrradianceRoundTripsAndInterpolatesBetweenKeys) {
  Scene scene = readGltfScene(scenePath());
  GlobalSolution g = solution(scene);
  ASSERT_EQ(g.keyCount(), 3);
  setClusterIrradiance(g);
  std::string path = tempPath("cluster.rlh");
  writeLinkHierarchy(path, g, provenance(), {});
  ContainerReader reader = ContainerReader::open(path);
  EXPECT_EQ(reader.kindVersion(), std::make_pair(1, 3));
  ASSERT_TRUE(reader.has("top_cluster_irradiance"));
  EXPECT_EQ(reader.info("top_cluster_irradiance").shape,
            (std::vector<uint64_t>{uint64_t(g.hierarchy.topCount()), 3, 3}));
  GlobalSolution r = readLinkHierarchy(reader, scene);
  EXPECT_EQ(r.topClusterIrradiance, g.topClusterIrradiance);
  // Keys 0, 0.25, 0.5: linear between them, held outside.
  const int top = 2;
  const glm::dvec3 k0 = r.clusterIrradianceAtKey(top, 0), k1 = r.clusterIrradianceAtKey(top, 1),
                   k2 = r.clusterIrradianceAtKey(top, 2);
  EXPECT_EQ(k1, glm::dvec3(3.0, 3.0, 2.0) / 8.0);
  EXPECT_EQ(r.clusterIrradiance(top, 0.0), k0);
  EXPECT_EQ(r.clusterIrradiance(top, -1.0), k0);
  EXPECT_EQ(r.clusterIrradiance(top, 0.5), k2);
  EXPECT_EQ(r.clusterIrradiance(top, 7.0), k2);
  const glm::dvec3 mid = r.clusterIrradiance(top, 0.35);  // 40 % of the way from key 1 to key 2
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(mid[c], 0.6 * k1[c] + 0.4 * k2[c], 1e-12);
  // rad-inspect's summary: max and mean of the values.
  nlohmann::json summary = summarizeLinkHierarchy(reader);
  ASSERT_TRUE(summary.contains("cluster_irradiance")) << summary.dump();
  double maxH = 0.0, sum = 0.0;
  for (const glm::vec3& h : g.topClusterIrradiance)
    for (int c = 0; c < 3; ++c) maxH = std::max(maxH, double(h[c])), sum += h[c];
  EXPECT_EQ(summary["cluster_irradiance"]["max"].get<double>(), maxH);
  EXPECT_NEAR(summary["cluster_irradiance"]["mean"].get<double>(),
              sum / double(3 * g.topClusterIrradiance.size()), 1e-9);
  // rad-compose's read leaves it out.
  EXPECT_TRUE(readLinkHierarchyRadiosity(reader, scene).topClusterIrradiance.empty());
  std::filesystem::remove(path);
}

TEST(LinkHierarchy, FileWithoutClusterIrradianceReadsAsNone) {
  Scene scene = readGltfScene(scenePath());
  GlobalSolution g = solution(scene);
  g.topClusterIrradiance.clear();  // none
  std::string path = tempPath("nocluster.rlh");
  writeLinkHierarchy(path, g, provenance(), {});
  ContainerReader reader = ContainerReader::open(path);
  EXPECT_FALSE(reader.has("top_cluster_irradiance")) << "written only when there is some";
  EXPECT_FALSE(summarizeLinkHierarchy(reader).contains("cluster_irradiance"));
  // A 1.2 file (no such array) reads with none.
  for (const ContainerReader& r : {reader, rewritten(path, {1, 2}, "", nullptr)}) {
    GlobalSolution s = readLinkHierarchy(r, scene);
    EXPECT_TRUE(s.topClusterIrradiance.empty());
    EXPECT_EQ(s.clusterIrradianceAtKey(1, 2), glm::dvec3(0.0));
    EXPECT_EQ(s.clusterIrradiance(1, 0.1), glm::dvec3(0.0));
  }
  std::filesystem::remove(path);
}

TEST(LinkHierarchy, WrongSizeOrNonFiniteClusterIrradianceIsOneLineError) {
  Scene scene = readGltfScene(scenePath());
  GlobalSolution g = solution(scene);
  setClusterIrradiance(g);
  std::string path = tempPath("badcluster.rlh");
  writeLinkHierarchy(path, g, provenance(), {});
  const size_t n = g.topClusterIrradiance.size() * 3;
  // The reader's own check (before validate), one top short and one value too many.
  for (size_t size : {n - 3, n + 1}) {
    const std::vector<float> values(size, 0.25f);
    SCOPED_TRACE(size);
    expectOneLineError(
        [&] {
          readLinkHierarchy(rewritten(path, {1, 3}, "top_cluster_irradiance", &values), scene);
        },
        path,
        "top_cluster_irradiance has " + std::to_string(size) + " values; expected " +
            std::to_string(n));
  }
  // Non-finite and negative values: refused on read and on write.
  for (float v : {std::nanf(""), std::numeric_limits<float>::infinity(), -0.5f}) {
    SCOPED_TRACE(v);
    std::vector<float> values(n, 0.25f);
    values[n / 2] = v;
    expectOneLineError(
        [&] {
          readLinkHierarchy(rewritten(path, {1, 3}, "top_cluster_irradiance", &values), scene);
        },
        path, "top cluster irradiance is negative or not finite");
    GlobalSolution bad = g;
    bad.topClusterIrradiance[g.topClusterIrradiance.size() / 2].y = v;
    const std::string out = tempPath("badcluster_write.rlh");
    expectOneLineError([&] { writeLinkHierarchy(out, bad, provenance(), {}); }, out,
                       "top cluster irradiance is negative or not finite");
    EXPECT_FALSE(std::filesystem::exists(out));
  }
  // validate() on its own: the size must be T * K.
  GlobalSolution shorter = g;
  shorter.topClusterIrradiance.pop_back();
  expectOneLineError([&] { shorter.validate("memory"); }, "memory",
                     "top_cluster_irradiance has the wrong size");
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace rad
