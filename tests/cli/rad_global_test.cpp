// rad-global as a user runs it on the bundled scene: the link hierarchy and its report, the
// coherent file equal to the --no-coherence one, the same bytes on one core and on all, and
// one-line usage errors for out-of-range parameters (issue 3 items 7-9); without --frames, the
// whole animation (issue 14).
#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "formats/container.h"
#include "formats/gltf_scene.h"
#include "formats/link_hierarchy.h"

namespace rad {
namespace {

namespace fs = std::filesystem;
using test::readWholeFile;
using test::runCommand;
using test::tool;

const std::string kScene = std::string(RAD_SOURCE_DIR) + "/pipelines/scenes/cornell-moving.gltf";
const std::string kFlags = " --frames 0-12 --key-step 4 --eps 3e-3";

fs::path scratchDir() {
  fs::path d = fs::temp_directory_path() / ("rad_global_cli_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

TEST(RadGlobal, BundledSceneLinksReportAndInspect) {
  fs::path d = scratchDir();
  auto r = runCommand(tool("rad-global") + " " + kScene + " -o " + (d / "g.rlh").string() + kFlags +
                      " --report " + (d / "report.json").string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("recomputed"), std::string::npos) << r.err;
  nlohmann::json rep = nlohmann::json::parse(readWholeFile((d / "report.json").string()));
  ASSERT_EQ(rep["key_times"].size(), 4u);  // frames 0, 4, 8, 12
  EXPECT_EQ(rep["key_times"][0]["reused"], 0);
  size_t reused = 0;
  for (size_t k = 1; k < 4; ++k) reused += rep["key_times"][k]["reused"].get<size_t>();
  EXPECT_GT(reused, 0u);
  EXPECT_GT(rep["peak_memory_mb"].get<double>(), 0.0);

  auto inspect = runCommand(tool("rad-inspect") + " " + (d / "g.rlh").string());
  ASSERT_EQ(inspect.exitCode, 0) << inspect.err;
  for (const char* what : {"link", "bad", "rad-global"})
    EXPECT_NE(inspect.out.find(what), std::string::npos) << what << "\n" << inspect.out;
  fs::remove_all(d);
}

// Exact reuse: the coherent file holds what --no-coherence computes, bit for bit.
TEST(RadGlobal, CoherentFileEqualsNoCoherenceFile) {
  fs::path d = scratchDir();
  std::string base = tool("rad-global") + " " + kScene + kFlags;
  ASSERT_EQ(runCommand(base + " -o " + (d / "c.rlh").string()).exitCode, 0);
  ASSERT_EQ(runCommand(base + " --no-coherence -o " + (d / "n.rlh").string()).exitCode, 0);
  Scene scene = readGltfScene(kScene);
  GlobalSolution c = readLinkHierarchy((d / "c.rlh").string(), scene);
  GlobalSolution n = readLinkHierarchy((d / "n.rlh").string(), scene);
  EXPECT_TRUE(c.nodeRadiosity == n.nodeRadiosity);
  EXPECT_TRUE(c.leafVertexGoodIrradiance == n.leafVertexGoodIrradiance);
  EXPECT_TRUE(c.linkSampleValues == n.linkSampleValues);
  EXPECT_TRUE(c.linkSampleVisibility == n.linkSampleVisibility);
  EXPECT_TRUE(c.nodeExposure == n.nodeExposure);
  EXPECT_TRUE(c.linkSampleKeys == n.linkSampleKeys);
  EXPECT_EQ(c.links.size(), n.links.size());
  fs::remove_all(d);
}

// Issue 16: with clustering, on a generated 1k-triangle lecture hall whose car moves, the
// cluster links between static clusters away from the car keep their values from key to key,
// and the coherent file is still what --no-coherence computes, cluster irradiance included;
// --no-clustering links every pair and has no cluster irradiance.
TEST(RadGlobal, ClusteredHallCoherentEqualsNoCoherence) {
  fs::path d = scratchDir();
  const std::string hall = (d / "hall.gltf").string();
  ASSERT_EQ(runCommand("python3 " + std::string(RAD_SOURCE_DIR) +
                       "/pipelines/scenes/make_hall.py " + hall + " --triangles 1000")
                .exitCode,
            0);
  const std::string base = tool("rad-global") + " " + hall + " --frames 0-8 --key-step 8";
  auto c =
      runCommand(base + " -o " + (d / "c.rlh").string() + " --report " + (d / "c.json").string());
  ASSERT_EQ(c.exitCode, 0) << c.err;
  ASSERT_EQ(runCommand(base + " --no-coherence -o " + (d / "n.rlh").string()).exitCode, 0);
  ASSERT_EQ(runCommand(base + " --no-clustering -o " + (d / "a.rlh").string()).exitCode, 0);
  nlohmann::json rep = nlohmann::json::parse(readWholeFile((d / "c.json").string()));
  EXPECT_GT(rep["key_times"][0]["cluster_links"].get<size_t>(), 0u);
  EXPECT_EQ(rep["key_times"][0]["cluster_links_reused"].get<size_t>(), 0u);
  EXPECT_GT(rep["key_times"][1]["cluster_links_reused"].get<size_t>(), 0u);
  EXPECT_LT(rep["key_times"][1]["cluster_links_reused"].get<size_t>(),
            rep["key_times"][1]["cluster_links"].get<size_t>())
      << "links near the car's path are recomputed";
  Scene scene = readGltfScene(hall);
  GlobalSolution gc = readLinkHierarchy((d / "c.rlh").string(), scene);
  GlobalSolution gn = readLinkHierarchy((d / "n.rlh").string(), scene);
  GlobalSolution ga = readLinkHierarchy((d / "a.rlh").string(), scene);
  EXPECT_FALSE(gc.topClusterIrradiance.empty());
  EXPECT_TRUE(gc.topClusterIrradiance == gn.topClusterIrradiance);
  EXPECT_TRUE(gc.nodeRadiosity == gn.nodeRadiosity);
  EXPECT_TRUE(gc.leafVertexGoodIrradiance == gn.leafVertexGoodIrradiance);
  EXPECT_TRUE(gc.linkSampleValues == gn.linkSampleValues);
  EXPECT_TRUE(ga.topClusterIrradiance.empty());
  EXPECT_GT(ga.links.size(), gc.links.size());
  fs::remove_all(d);
}

// Same command line on one core and on every core: the same bytes (provenance included).
TEST(RadGlobal, SameBytesOnOneCoreAndOnAll) {
  if (std::thread::hardware_concurrency() < 2) GTEST_SKIP() << "one core only";
  if (runCommand("taskset -c 0 true").exitCode != 0) GTEST_SKIP() << "no taskset";
  fs::path d = scratchDir();
  std::string cmd = tool("rad-global") + " " + kScene + kFlags + " -o ";
  ASSERT_EQ(runCommand("cd " + d.string() + " && taskset -c 0 " + cmd + "out.rlh").exitCode, 0);
  fs::rename(d / "out.rlh", d / "one.rlh");
  ASSERT_EQ(runCommand("cd " + d.string() + " && " + cmd + "out.rlh").exitCode, 0);
  std::string one = readWholeFile((d / "one.rlh").string());
  EXPECT_GT(one.size(), 1000u);
  EXPECT_TRUE(one == readWholeFile((d / "out.rlh").string()));
  fs::remove_all(d);
}

// Without --frames rad-global covers the scene's whole animation (frame_range.h
// animationFrames): the bundled scene lasts 4 s, so at 24 fps its frames are 0-96. (Before issue
// 14 the default was 0-0, one key time at t = 0.)
TEST(RadGlobal, WithoutFramesCoversTheWholeAnimation) {
  fs::path d = scratchDir();
  const std::string out = (d / "whole.rlh").string();
  auto r =
      runCommand(tool("rad-global") + " " + kScene + " -o " + out +
                 " --fps 24 --key-step 48 --eps 3e-3 --report " + (d / "report.json").string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json meta = ContainerReader::open(out).metadata();
  EXPECT_EQ(meta.at("first_frame"), 0) << meta.dump();
  EXPECT_EQ(meta.at("last_frame"), 96) << meta.dump();
  EXPECT_EQ(meta.at("parameters").at("frames"), "0-96") << meta.dump();
  nlohmann::json rep = nlohmann::json::parse(readWholeFile((d / "report.json").string()));
  ASSERT_EQ(rep["key_times"].size(), 3u);  // frames 0, 48, 96
  EXPECT_DOUBLE_EQ(rep["key_times"][2]["time"].get<double>(), 4.0);
  fs::remove_all(d);
}

// The memory bound: at --max-links refinement stops with one warning line, the report counts
// the key times it stopped, and the file is written from the links it has.
TEST(RadGlobal, LinkBoundWarnsAndIsReported) {
  fs::path d = scratchDir();
  const std::string out = (d / "capped.rlh").string();
  auto r = runCommand(tool("rad-global") + " " + kScene + " -o " + out + kFlags +
                      " --max-links 1000 --report " + (d / "report.json").string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("rad-global: warning: 4 of 4 key times stopped refining at the link bound "
                       "(1000 links)"),
            std::string::npos)
      << r.err;
  nlohmann::json rep = nlohmann::json::parse(readWholeFile((d / "report.json").string()));
  EXPECT_EQ(rep["totals"]["keys_at_link_cap"], 4);
  for (const auto& k : rep["key_times"]) {
    EXPECT_TRUE(k["link_cap_reached"].get<bool>());
    EXPECT_LE(k["links"].get<size_t>(), 1000u);
  }
  EXPECT_EQ(ContainerReader::open(out).metadata().at("parameters").at("max-links"), 1000);
  fs::remove_all(d);
}

TEST(RadGlobal, OutOfRangeParametersAreUsageErrors) {
  for (const char* bad :
       {"--eps -1", "--key-step 0", "--rays 0", "--tol 0", "--oracle fast", "--bad-links some",
        "--partial-threshold 2", "--threads -1", "--frames 9-x", "--max-links 0"}) {
    auto r = runCommand(tool("rad-global") + " " + kScene + " -o /tmp/never.rlh " + bad);
    EXPECT_EQ(r.exitCode, 2) << bad << ": " << r.err;
    EXPECT_EQ(test::countLines(r.err), 1) << bad << ": " << r.err;
    EXPECT_EQ(r.err.rfind("rad-global: ", 0), 0u) << r.err;
  }
  EXPECT_FALSE(fs::exists("/tmp/never.rlh"));
}

}  // namespace
}  // namespace rad
