// rad-reference as a user runs it: frames with provenance, deterministic output, one-line
// errors; and rad-diff of its frames (the pair the pipeline's error figures come from).
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "formats/exr_image.h"
#include "formats/exr_info.h"
#include "tests/cli/cli_util.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

// Removes this process's scratch directory when the test program ends.
struct TempRootCleanup {
  ~TempRootCleanup() {
    std::error_code ec;
    fs::remove_all(fs::temp_directory_path() / ("rad_reference_test_" + std::to_string(::getpid())),
                   ec);
  }
} cleanupAtExit;

const std::string kScene = std::string(RAD_SOURCE_DIR) + "/pipelines/scenes/cornell-moving.gltf";

fs::path freshDir(const std::string& name) {
  fs::path d =
      fs::temp_directory_path() / ("rad_reference_test_" + std::to_string(::getpid())) / name;
  fs::remove_all(d);
  fs::create_directories(d.parent_path());
  return d;
}

TEST(RadReference, WritesFramesWithProvenanceDeterministically) {
  fs::path a = freshDir("a"), b = freshDir("b");
  const std::string args = " --frames 3-4 --size 20x14 --spp 4";
  CommandResult r = runCommand(tool("rad-reference") + " " + kScene + " -o " + a.string() + args);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("0003.exr: frame 3"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("s per frame"), std::string::npos) << r.out;
  ASSERT_TRUE(fs::exists(a / "0003.exr"));
  ASSERT_TRUE(fs::exists(a / "0004.exr"));
  EXPECT_EQ(std::distance(fs::directory_iterator(a), fs::directory_iterator()), 2)
      << "no temporaries left behind";

  FloatImage im = readExrImage((a / "0003.exr").string());
  EXPECT_EQ(im.width, 20);
  EXPECT_EQ(im.height, 14);
  double sum = 0.0;
  for (float v : im.pixels) {
    EXPECT_TRUE(std::isfinite(v) && v >= 0.0f);
    sum += v;
  }
  EXPECT_GT(sum, 0.0) << "the lit Cornell box is not black";

  nlohmann::json info = readExrInfo((a / "0003.exr").string());
  const auto& attrs = info["parts"][0]["attributes"];
  ASSERT_TRUE(attrs.contains("rad.provenance"));
  nlohmann::json prov = nlohmann::json::parse(attrs["rad.provenance"].get<std::string>());
  EXPECT_EQ(prov["tool"], "rad-reference");
  EXPECT_EQ(prov["parameters"]["spp"], 4);
  EXPECT_EQ(prov["inputs"][0]["path"], kScene);

  // Same command, same pixels (TBB scheduling does not matter).
  r = runCommand(tool("rad-reference") + " " + kScene + " -o " + b.string() + args);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(readExrImage((b / "0004.exr").string()).pixels,
            readExrImage((a / "0004.exr").string()).pixels);
  r = runCommand(tool("rad-diff") + " " + a.string() + " " + b.string() + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["frames_compared"], 2);
  EXPECT_EQ(j["difference"]["rmse"].get<double>(), 0.0);
}

TEST(RadReference, UnknownCameraIsOneLineExit1) {
  CommandResult r = runCommand(tool("rad-reference") + " " + kScene + " -o " +
                               freshDir("c").string() + " --camera nope --frames 0 --size 8x8");
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_EQ(countLines(r.err), 1) << r.err;
  EXPECT_EQ(r.err, "rad-reference: " + kScene + ": has no camera named 'nope'\n");
}

}  // namespace
}  // namespace rad::test
