// docs/conventions.md §3 "Small tools": --help, --version, an unknown flag and a missing file give
// the documented output and exit code, for every tool that is built.
#include <algorithm>
#include <map>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/cli/cli_util.h"

namespace rad::test {
namespace {

// The pipeline's four stages and the three tools around them.
const char* const kExpectedTools[] = {"rad-global",  "rad-intervals", "rad-movies", "rad-compose",
                                      "rad-inspect", "rad-reference", "rad-diff"};

TEST(ToolsCli, EveryExpectedToolIsBuilt) {
  std::vector<std::string> tools = builtTools();
  for (const char* t : kExpectedTools)
    EXPECT_NE(std::find(tools.begin(), tools.end(), t), tools.end()) << t << " is not built";
}

// --print-defaults: one JSON object of long option names (without "--") and their defaults,
// numbers as numbers, flags false, no default null; the pipeline scripts read it.
TEST(ToolsCli, PrintDefaultsIsOneJsonObject) {
  // One option per tool whose default the tool documents in --help.
  const std::map<std::string, std::pair<std::string, nlohmann::json>> known = {
      {"rad-global", {"eps", 0.0002}},     {"rad-intervals", {"size", "352x240"}},
      {"rad-movies", {"max-samples", 64}}, {"rad-compose", {"compression", "none"}},
      {"rad-inspect", {"json", false}},    {"rad-reference", {"spp", 256}},
      {"rad-diff", {"json", false}}};
  for (const char* t : kExpectedTools) {
    CommandResult r = runCommand(tool(t) + " --print-defaults");
    EXPECT_EQ(r.exitCode, 0) << t << ": " << r.err;
    EXPECT_TRUE(r.err.empty()) << t << ": " << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out, nullptr, false);
    ASSERT_TRUE(j.is_object()) << t << ": " << r.out;
    EXPECT_EQ(j.value("threads", nlohmann::json()), 0) << t;
    for (const char* absent : {"help", "version", "print-defaults", "h", "--threads"})
      EXPECT_FALSE(j.contains(absent)) << t << ": " << absent;
    const auto& [key, value] = known.at(t);
    ASSERT_TRUE(j.contains(key)) << t << ": " << r.out;
    EXPECT_EQ(j[key], value) << t << ": " << key;
  }
  // An option without a default is null; an option bound to a string is a string.
  const nlohmann::json intervals =
      nlohmann::json::parse(runCommand(tool("rad-intervals") + " --print-defaults").out);
  EXPECT_TRUE(intervals.at("frames").is_null());
  EXPECT_TRUE(intervals.at("camera").is_null());
  EXPECT_EQ(intervals.at("fps"), 24);
  const nlohmann::json compose =
      nlohmann::json::parse(runCommand(tool("rad-compose") + " --print-defaults").out);
  EXPECT_TRUE(compose.at("fps").is_null());  // default: the intervals'
  EXPECT_EQ(compose.at("auto-exposure"), false);
  EXPECT_EQ(compose.at("output"), nullptr);
  // The defaults, not the values given on the same command line.
  const nlohmann::json global =
      nlohmann::json::parse(runCommand(tool("rad-global") + " --eps 0.5 --print-defaults").out);
  EXPECT_EQ(global.at("eps"), 0.0002);
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
