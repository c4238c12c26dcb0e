// rad-diff as a user runs it: two EXR files or two frame directories, text and --json output,
// and the one-line error on a size mismatch.
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "formats/exr_image.h"
#include "tests/cli/cli_util.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

// Removes this process's scratch directory when the test program ends.
struct TempRootCleanup {
  ~TempRootCleanup() {
    std::error_code ec;
    fs::remove_all(fs::temp_directory_path() / ("rad_diff_test_" + std::to_string(::getpid())), ec);
  }
} cleanupAtExit;

fs::path freshDir(const std::string& name) {
  fs::path d = fs::temp_directory_path() / ("rad_diff_test_" + std::to_string(::getpid())) / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

FloatImage constant(int w, int h, float value) {
  FloatImage im(w, h, {"R", "G", "B"});
  for (float& v : im.pixels) v = value;
  return im;
}

TEST(RadDiff, TwoFilesJson) {
  fs::path d = freshDir("files");
  writeExrImage((d / "a.exr").string(), constant(5, 3, 1.25f));
  writeExrImage((d / "b.exr").string(), constant(5, 3, 1.0f));
  CommandResult r = runCommand(tool("rad-diff") + " " + (d / "a.exr").string() + " " +
                               (d / "b.exr").string() + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_DOUBLE_EQ(j["difference"]["rmse"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(j["difference"]["relative_l2"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(j["difference"]["max_abs"].get<double>(), 0.25);
  EXPECT_NEAR(j["difference"]["psnr_db"].get<double>(), 20.0 * std::log10(4.0), 1e-12);
  EXPECT_EQ(j["difference"]["samples"].get<int>(), 45);

  // Identical: zero error, infinite PSNR (null in JSON, "inf" in text).
  r = runCommand(tool("rad-diff") + " " + (d / "a.exr").string() + " " + (d / "a.exr").string() +
                 " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["difference"]["rmse"].get<double>(), 0.0);
  EXPECT_TRUE(j["difference"]["psnr_db"].is_null());
  r = runCommand(tool("rad-diff") + " " + (d / "a.exr").string() + " " + (d / "a.exr").string());
  EXPECT_NE(r.out.find("psnr inf"), std::string::npos) << r.out;

  // One channel only.
  FloatImage g = constant(5, 3, 1.0f);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) g.at(x, y, 1) = 3.0f;
  writeExrImage((d / "g.exr").string(), g);
  r = runCommand(tool("rad-diff") + " " + (d / "g.exr").string() + " " + (d / "b.exr").string() +
                 " --json --channels R,B");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["difference"]["rmse"].get<double>(), 0.0);
}

TEST(RadDiff, SizeMismatchIsOneLineExit1) {
  fs::path d = freshDir("mismatch");
  writeExrImage((d / "a.exr").string(), constant(5, 3, 1.0f));
  writeExrImage((d / "b.exr").string(), constant(4, 3, 1.0f));
  CommandResult r =
      runCommand(tool("rad-diff") + " " + (d / "a.exr").string() + " " + (d / "b.exr").string());
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_EQ(countLines(r.err), 1) << r.err;
  EXPECT_EQ(r.err, "rad-diff: " + (d / "a.exr").string() +
                       ": size 5x3 differs from the reference's 4x3\n");
  // A missing channel names the channels the file has.
  r = runCommand(tool("rad-diff") + " " + (d / "a.exr").string() + " " + (d / "a.exr").string() +
                 " --channels Z");
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.err.find("no channel 'Z' (channels: B,G,R)"), std::string::npos) << r.err;
}

TEST(RadDiff, DirectoriesMatchFramesByNameAndMeasureFlicker) {
  fs::path test = freshDir("seq/test"), ref = freshDir("seq/ref");
  // Reference static everywhere; test alternates 1, 1.5, 1, 1.5: flicker exactly 0.5.
  for (int f = 1; f <= 4; ++f) {
    char name[16];
    std::snprintf(name, sizeof name, "%04d.exr", f);
    writeExrImage((ref / name).string(), constant(3, 2, 1.0f));
    writeExrImage((test / name).string(), constant(3, 2, f % 2 ? 1.0f : 1.5f));
  }
  writeExrImage((test / "0005.exr").string(), constant(3, 2, 1.0f));  // no reference: skipped
  writeExrImage((ref / "other.exr").string(), constant(9, 9, 1.0f));  // not a frame name
  CommandResult r =
      runCommand(tool("rad-diff") + " " + test.string() + " " + ref.string() + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["frames_compared"].get<int>(), 4);
  EXPECT_EQ(j["frames_only_in_test"].get<int>(), 1);
  EXPECT_DOUBLE_EQ(j["flicker"]["mean_abs"].get<double>(), 0.5);
  EXPECT_EQ(j["flicker"]["frame_pairs"].get<int>(), 3);
  EXPECT_EQ(j["flicker"]["static_pixels"].get<int>(), 3 * 6);
  EXPECT_DOUBLE_EQ(j["difference"]["rmse"].get<double>(), std::sqrt(0.125));
  ASSERT_EQ(j["per_frame"].size(), 4u);
  EXPECT_EQ(j["per_frame"][1]["rmse"].get<double>(), 0.5);

  r = runCommand(tool("rad-diff") + " " + test.string() + " " + ref.string());
  EXPECT_EQ(r.exitCode, 0);
  EXPECT_NE(r.out.find("flicker: mean |test(n+1)-test(n)| 0.5"), std::string::npos) << r.out;

  // File against directory is a usage error.
  r = runCommand(tool("rad-diff") + " " + (test / "0001.exr").string() + " " + ref.string());
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(countLines(r.err), 1);
}

}  // namespace
}  // namespace rad::test
