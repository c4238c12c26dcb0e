// pipelines/scenes/make_paper_scenes.py's command line (issue 54): --help wrote 13 scenes into a
// folder named `--help`.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "tests/cli/cli_util.h"

namespace fs = std::filesystem;

namespace {

const std::string kScript = RAD_SOURCE_DIR "/pipelines/scenes/make_paper_scenes.py";

TEST(PaperScenesCli, HelpPrintsUsageAndWritesNothing) {
  const fs::path dir = fs::temp_directory_path() / ("rad_paper_scenes_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string in = "cd " + dir.string() + " && python3 " + kScript;
  const auto help = rad::test::runCommand(in + " --help");
  EXPECT_EQ(help.exitCode, 0) << help.err;
  EXPECT_NE(help.out.find("usage:"), std::string::npos) << help.out;
  const auto dashed = rad::test::runCommand(in + " -- -x cubic");
  EXPECT_EQ(dashed.exitCode, 2) << dashed.err;
  EXPECT_NE(dashed.err.find("starts with '-'"), std::string::npos) << dashed.err;
  const auto unknown = rad::test::runCommand(in + " out no-such-scene");
  EXPECT_EQ(unknown.exitCode, 2) << unknown.err;
  EXPECT_TRUE(fs::is_empty(dir)) << "a usage error or --help wrote into " << dir;
  fs::remove_all(dir);
}

}  // namespace
