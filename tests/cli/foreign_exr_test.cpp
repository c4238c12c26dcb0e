// EXR files rad did not write (issue 55): a rendered frame re-saved by oiiotool as half floats
// with DWAA compression keeps the frame's rad.* attributes, rad.pixelChecksum included, but not
// its pixels. rad-diff reads it like any valid OpenEXR file; rad-inspect names it "EXR not
// written by rad" and summarises it; a truncated one is still an error (exit 1, one line).
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/cli/cli_util.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

class ForeignExr : public ::testing::Test {
 protected:
  // One frame of the bundled scene through the four stages, and its oiiotool re-save.
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("rad_foreign_exr_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    if (runCommand("command -v oiiotool").exitCode != 0) return;
    const std::string scene = RAD_SOURCE_DIR "/pipelines/scenes/cornell-moving.gltf";
    const std::string d = dir_.string();
    for (const std::string& command :
         {tool("rad-global") + " " + scene + " -o " + d + "/global.rlh --frames 0-1 --eps 0.05",
          tool("rad-intervals") + " " + scene + " -o " + d + "/intervals.rti --frames 0-1" +
              " --size 88x60",
          tool("rad-movies") + " " + scene + " " + d + "/global.rlh " + d + "/intervals.rti -o " +
              d + "/movies",
          tool("rad-compose") + " " + scene + " " + d + "/global.rlh " + d + "/intervals.rti " + d +
              "/movies -o " + d + "/frames --frames 0-0 --no-png",
          "oiiotool " + d + "/frames/0000.exr -d half --compression dwaa -o " + d +
              "/foreign.exr"}) {
      CommandResult r = runCommand(command);
      if (r.exitCode != 0) {
        setUpError_ = command + ": exit " + std::to_string(r.exitCode) + " " + r.err;
        return;
      }
    }
    ready_ = true;
  }
  static void TearDownTestSuite() {
    if (!std::getenv("RAD_KEEP_TEST_DIR")) fs::remove_all(dir_);
  }
  void SetUp() override {
    if (runCommand("command -v oiiotool").exitCode != 0) GTEST_SKIP() << "no oiiotool";
    ASSERT_TRUE(ready_) << setUpError_;
  }
  static std::string original() { return (dir_ / "frames/0000.exr").string(); }
  static std::string foreign() { return (dir_ / "foreign.exr").string(); }

  static fs::path dir_;
  static bool ready_;
  static std::string setUpError_;
};
fs::path ForeignExr::dir_;
bool ForeignExr::ready_ = false;
std::string ForeignExr::setUpError_;

TEST_F(ForeignExr, RadDiffReadsAHalfDwaaResaveOfARenderedFrame) {
  CommandResult r = runCommand(tool("rad-diff") + " " + foreign() + " " + original() + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const double rel = j["difference"]["relative_l2"].get<double>();
  EXPECT_GT(j["difference"]["rmse"].get<double>(), 0.0) << r.out;  // lossy: not the same pixels
  EXPECT_LT(rel, 0.02) << r.out;
  // The other way round, in text.
  r = runCommand(tool("rad-diff") + " " + original() + " " + foreign());
  EXPECT_EQ(r.exitCode, 0) << r.err;
}

TEST_F(ForeignExr, RadInspectNamesItForeignAndSummarisesIt) {
  CommandResult r = runCommand(tool("rad-inspect") + " " + foreign());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const std::string first = r.out.substr(0, r.out.find('\n'));
  EXPECT_EQ(first.rfind(foreign() + ": EXR not written by rad (OpenImageIO", 0), 0u) << first;
  EXPECT_NE(r.out.find("88x60"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("compression dwaa"), std::string::npos) << r.out;
  r = runCommand(tool("rad-inspect") + " --json " + foreign());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_FALSE(j["written_by_rad"].get<bool>());
  EXPECT_EQ(j["pixels"]["checksummed_parts"], 0);
  EXPECT_EQ(j["parts"][0]["channels"][0]["type"], "half");
  r = runCommand(tool("rad-inspect") + " --check " + foreign());
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.out, foreign() + ": ok\n");
  // The frame it was made from is still rad's, its checksum verified.
  r = runCommand(tool("rad-inspect") + " --json " + original());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::parse(r.out)["written_by_rad"].get<bool>());
  EXPECT_EQ(nlohmann::json::parse(r.out)["pixels"]["checksummed_parts"], 1);
}

TEST_F(ForeignExr, TruncatedForeignExrIsStillAnError) {
  const std::string bytes = readWholeFile(foreign());
  const std::string cut = (dir_ / "cut.exr").string();
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() * 2 / 3);
  for (const std::string& command :
       {tool("rad-inspect") + " " + cut, tool("rad-inspect") + " --check " + cut,
        tool("rad-diff") + " " + cut + " " + original()}) {
    CommandResult r = runCommand(command);
    EXPECT_EQ(r.exitCode, 1) << command << "\n" << r.out << r.err;
    EXPECT_EQ(countLines(r.err), 1) << command << "\n" << r.err;
    EXPECT_NE(r.err.find(cut + ": "), std::string::npos) << command << "\n" << r.err;
  }
}

}  // namespace
}  // namespace rad::test
