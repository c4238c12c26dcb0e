// CONVENTIONS.md "Small tools": --help, --version, an unknown flag and a missing file give the
// documented output and exit code, for every tool that is built.
#include <algorithm>

#include <gtest/gtest.h>

#include "tests/cli/cli_util.h"

namespace rad::test {
namespace {

TEST(ToolsCli, EveryExpectedToolIsBuilt) {
  std::vector<std::string> tools = builtTools();
  EXPECT_NE(std::find(tools.begin(), tools.end(), "rad-inspect"), tools.end());
}

TEST(ToolsCli, HelpGoesToStdoutWithExitCodes) {
  for (const std::string& t : builtTools()) {
    CommandResult r = runCommand(tool(t) + " --help");
    EXPECT_EQ(r.exitCode, 0) << t;
    EXPECT_NE(r.out.find(t), std::string::npos) << t << ": synopsis names the tool";
    EXPECT_NE(r.out.find("Example"), std::string::npos) << t;
    EXPECT_NE(r.out.find("Exit codes"), std::string::npos) << t;
    EXPECT_TRUE(r.err.empty()) << t << ": " << r.err;
  }
}

TEST(ToolsCli, VersionPrintsNameAndVersion) {
  for (const std::string& t : builtTools()) {
    CommandResult r = runCommand(tool(t) + " --version");
    EXPECT_EQ(r.exitCode, 0) << t;
    EXPECT_EQ(r.out.rfind(t + " " RAD_VERSION, 0), 0u) << t << ": " << r.out;
  }
}

TEST(ToolsCli, UnknownFlagIsOneLineAndExit2) {
  for (const std::string& t : builtTools()) {
    CommandResult r = runCommand(tool(t) + " --no-such-flag");
    EXPECT_EQ(r.exitCode, 2) << t;
    EXPECT_EQ(countLines(r.err), 1) << t << ": " << r.err;
    EXPECT_EQ(r.err.rfind(t + ": ", 0), 0u) << t << ": " << r.err;
  }
}

TEST(ToolsCli, MissingInputIsOneLineNamingTheFile) {
  for (const std::string& t : builtTools()) {
    // The missing file comes first; later positional inputs and the output are well formed.
    std::string rest = " -o /tmp/rad_cli_unused";
    if (t == "rad-inspect") rest = "";
    if (t == "rad-movies") rest = " g.rlh i.rti -o /tmp/rad_cli_unused";
    if (t == "rad-compose") rest = " g.rlh i.rti movies -o /tmp/rad_cli_unused";
    if (t == "rad-diff") rest = " /tmp/rad_cli_unused.exr";
    CommandResult r = runCommand(tool(t) + " /nonexistent/scene.gltf" + rest);
    EXPECT_EQ(r.exitCode, 1) << t << ": " << r.err;
    EXPECT_EQ(countLines(r.err), 1) << t << ": " << r.err;
    EXPECT_EQ(r.err.rfind(t + ": /nonexistent/scene.gltf: ", 0), 0u) << t << ": " << r.err;
  }
}

}  // namespace
}  // namespace rad::test
