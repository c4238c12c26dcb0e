// Issue 18, command lines and environment: hostile flags and broken environments end in the
// documented exit code and one line on stderr, never a signal, a silent NaN or a black frame
// without a word. The tools run as a user runs them, on the bundled scene at a tiny size.
#include <filesystem>
#include <fstream>
#include <regex>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/cli/cli_util.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

const std::string kScene = RAD_SOURCE_DIR "/pipelines/scenes/cornell-moving.gltf";

// The documented failure: exit `code` (not a signal) and exactly one line `tool: ...` on stderr.
void expectOneLine(const CommandResult& r, int code, const std::string& toolName,
                   const std::string& context) {
  EXPECT_EQ(r.exitCode, code) << context << ": " << r.err;
  EXPECT_EQ(countLines(r.err), 1) << context << ": " << r.err;
  EXPECT_EQ(r.err.rfind(toolName + ": ", 0), 0u) << context << ": " << r.err;
}

// The four stages on the bundled scene at 32x24, frames 0-1, made once for the suite: the inputs
// the later stages need to get as far as the code under test.
class CommandLineEnvironment : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir = fs::temp_directory_path() / ("rad_cli_environment_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    runStages(kScene, "", "fast");
  }
  static void TearDownTestSuite() {
    if (!std::getenv("RAD_KEEP_TEST_DIR")) fs::remove_all(dir);
  }

  // rad-global, rad-intervals, rad-movies, rad-compose of `scene` into dir/TAG.*; `env` is put
  // before the GL stages' commands. Returns the four results.
  static std::vector<CommandResult> runStages(const std::string& scene, const std::string& env,
                                              const std::string& tag) {
    const std::string p = (dir / tag).string();
    std::vector<CommandResult> r;
    r.push_back(
        runCommand(tool("rad-global") + " " + scene + " -o " + p + ".rlh --frames 0-1 --eps 0.05"));
    r.push_back(runCommand(env + tool("rad-intervals") + " " + scene + " -o " + p +
                           ".rti --frames 0-1 --size 32x24 --report " + p + ".intervals.json"));
    r.push_back(runCommand(env + tool("rad-movies") + " " + scene + " " + p + ".rlh " + p +
                           ".rti -o " + p + ".movies --ray-cast-budget 0"));
    r.push_back(runCommand(env + tool("rad-compose") + " " + composeArgs(scene, tag) +
                           " --report " + p + ".compose.json"));
    return r;
  }
  static std::string composeArgs(const std::string& scene, const std::string& tag) {
    const std::string p = (dir / tag).string();
    return scene + " " + p + ".rlh " + p + ".rti " + p + ".movies -o " + p + ".frames";
  }
  static std::string frame(const std::string& tag) {
    return (dir / tag).string() + ".frames/0000.exr";
  }

  static fs::path dir;
};
fs::path CommandLineEnvironment::dir;

// `command` with its stdout on a full disk (/dev/full), its stderr captured.
CommandResult runToFullDisk(const std::string& command) {
  return runCommand("(" + command + " >/dev/full)");
}

TEST_F(CommandLineEnvironment, StdoutOnAFullDiskIsExit3) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const std::string exr = frame("fast");
  ASSERT_TRUE(fs::exists(exr));
  const std::vector<std::pair<std::string, std::string>> runs = {
      {"rad-inspect", "--json " + kScene},
      {"rad-inspect", kScene},
      {"rad-inspect", kScene + " " + exr + " " + kScene},
      {"rad-diff", "--json " + exr + " " + exr},
      {"rad-diff", exr + " " + exr},
      {"rad-reference",
       kScene + " -o " + (dir / "ref").string() + " --frames 0-0 --size 8x6 --spp 1"},
  };
  for (const auto& [t, args] : runs) {
    const CommandResult r = runToFullDisk(tool(t) + " " + args);
    expectOneLine(r, 3, t, args);
    EXPECT_NE(r.err.find("stdout: write failed"), std::string::npos) << r.err;
  }
  // What every tool prints and exits on.
  for (const std::string& t : builtTools())
    for (const char* flag : {"--help", "--version", "--print-defaults"})
      expectOneLine(runToFullDisk(tool(t) + " " + flag), 3, t, flag);
  // The same to a working stdout is still 0.
  EXPECT_EQ(runCommand(tool("rad-inspect") + " --json " + kScene).exitCode, 0);
}

TEST_F(CommandLineEnvironment, HugeIntegersAreUsageErrorsNamingTheFlag) {
  const std::string huge = "99999999999999999999";
  const std::string out = " -o " + (dir / "unused").string();
  const std::vector<std::tuple<std::string, std::string, std::string>> runs = {
      {"rad-global", kScene + out, "--frames " + huge},
      {"rad-global", kScene + out, "--frames 0-" + huge},
      {"rad-intervals", kScene + out, "--frames 0-1x" + huge},
      {"rad-intervals", kScene + out, "--size " + huge + "x10"},
      {"rad-compose", composeArgs(kScene, "fast"), "--frames " + huge},
      {"rad-compose", composeArgs(kScene, "fast"), "--size 10x" + huge},
      {"rad-reference", kScene + out, "--frames " + huge},
      {"rad-reference", kScene + out, "--size " + huge + "x10"},
      {"rad-global", kScene + out, "--key-step " + huge},
      {"rad-movies", "a b c" + out, "--movie-key-step " + huge},
      {"rad-global", kScene + out, "--threads " + huge},
  };
  for (const auto& [t, args, flag] : runs) {
    const CommandResult r = runCommand(tool(t) + " " + args + " " + flag);
    expectOneLine(r, 2, t, flag);
    EXPECT_NE(r.err.find(flag.substr(0, flag.find(' '))), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
  }
}

// Every floating-point option of every tool: those --help types FLOAT (so a new option is
// covered without a change here) and those whose default comes from the inputs. nan, inf and
// -inf are refused, and so is a negative number: no float option but --exposure means anything
// below 0.
TEST_F(CommandLineEnvironment, NonFiniteOrNegativeFloatOptionsAreUsageErrors) {
  std::vector<std::pair<std::string, std::string>> options = {
      {"rad-compose", "fps"}, {"rad-compose", "exposure"}, {"rad-diff", "emitter-threshold"}};
  const std::regex floatOption("--([a-z0-9-]+) FLOAT");
  for (const std::string& t : builtTools()) {
    const std::string help = runCommand(tool(t) + " --help").out;
    for (std::sregex_iterator m(help.begin(), help.end(), floatOption), end; m != end; ++m)
      options.push_back({t, (*m)[1]});
  }
  ASSERT_GE(options.size(), 20u);  // 20 when this was written
  for (const auto& [t, name] : options) {
    std::vector<std::string> bad = {"nan", "inf", "-inf", "NaN", "1e999"};
    if (name != "exposure") bad.push_back("-1");
    for (const std::string& value : bad) {
      const std::string flag = "--" + name + "=" + value;
      const CommandResult r = runCommand(tool(t) + " a b c d -o x " + flag);
      expectOneLine(r, 2, t, flag);
      EXPECT_EQ(r.err.rfind(t + ": --" + name + ": ", 0), 0u) << r.err;
    }
  }
  // A negative exposure is a darker PNG, not an error.
  const CommandResult dark =
      runCommand(tool("rad-compose") + " " + composeArgs(kScene, "fast") + "-dark --exposure=-2");
  EXPECT_EQ(dark.exitCode, 0) << dark.err;
}

// std::to_string(double) and CLI11's range checks printed DBL_MAX with 309 digits.
TEST_F(CommandLineEnvironment, NumbersInMessagesAreShort) {
  const std::regex longNumber("[0-9]{20}");
  auto expectShort = [&](const CommandResult& r, int code, const std::string& t,
                         const std::string& what) {
    expectOneLine(r, code, t, what);
    EXPECT_LT(r.err.size(), 300u) << what << ": " << r.err;
    EXPECT_FALSE(std::regex_search(r.err, longNumber)) << what << ": " << r.err;
  };
  const std::string out = " -o " + (dir / "unused").string();
  expectShort(runCommand(tool("rad-global") + " " + kScene + out + " --key-step 0"), 2,
              "rad-global", "--key-step 0");
  expectShort(runCommand(tool("rad-global") + " " + kScene + out + " --eps 1.8e308x"), 2,
              "rad-global", "--eps 1.8e308x");
  expectShort(runCommand(tool("rad-movies") + " a b c" + out + " --moving-shadow-key-step -1"), 2,
              "rad-movies", "--moving-shadow-key-step -1");
  // A camera whose clip planes are 1.7e308 and 1e308.
  nlohmann::json gltf = nlohmann::json::parse(readWholeFile(kScene));
  gltf["cameras"][0]["perspective"]["znear"] = 1.7e308;
  gltf["cameras"][0]["perspective"]["zfar"] = 1e308;
  const std::string scene = (dir / "huge-clip.gltf").string();
  std::ofstream(scene) << gltf.dump();
  const CommandResult r =
      runCommand(tool("rad-intervals") + " " + scene + out + " --frames 0-0 --size 32x24");
  expectShort(r, 1, "rad-intervals", "znear 1.7e308");
}

TEST_F(CommandLineEnvironment, UnusableGalliumDriverIsExit4NotASignal) {
  // Mesa 22.3 dereferences a null screen for a driver it cannot load: the tools died of SIGSEGV
  // inside OSMesaCreateContextAttribs.
  const std::vector<CommandResult> r =
      runStages(kScene, "GALLIUM_DRIVER=nonexistent ", "no-driver");
  ASSERT_EQ(r[0].exitCode, 0) << r[0].err;  // no GL in rad-global
  const char* gl[] = {"rad-intervals", "rad-movies", "rad-compose"};
  for (int i = 0; i < 3; ++i) {
    // The later stages are given the working run's inputs, so they get as far as their GL.
    const CommandResult& got =
        i == 0 ? r[1]
        : i == 1
            ? runCommand("GALLIUM_DRIVER=nonexistent " + tool("rad-movies") + " " + kScene + " " +
                         (dir / "fast.rlh").string() + " " + (dir / "fast.rti").string() + " -o " +
                         (dir / "no-driver.movies").string() + " --ray-cast-budget 0")
            : runCommand("GALLIUM_DRIVER=nonexistent " + tool("rad-compose") + " " +
                         composeArgs(kScene, "fast") + "-no-driver");
    expectOneLine(got, 4, gl[i], "GALLIUM_DRIVER=nonexistent");
    EXPECT_NE(got.err.find("GALLIUM_DRIVER=nonexistent"), std::string::npos) << got.err;
  }
  EXPECT_FALSE(fs::exists(dir / "no-driver.rti"));
  EXPECT_FALSE(fs::exists(dir / "fast.frames-no-driver/0000.exr"));
}

// Off a terminal, rad-global printed a table row per key time: 12,505 lines for --frames
// 0-100000. Now at most kTableKeys (20) rows and a line saying how many are left out.
TEST_F(CommandLineEnvironment, RadGlobalLogStaysShortForManyKeyTimes) {
  const std::string report = (dir / "many-keys.json").string();
  const CommandResult r =
      runCommand(tool("rad-global") + " " + kScene + " -o " + (dir / "many-keys.rlh").string() +
                 " --frames 0-1999 --key-step 1 --eps 1 --report " + report);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_LE(countLines(r.err), 30) << r.err;
  EXPECT_NE(r.err.find("1980 more key times"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(" 1999 "), std::string::npos) << "the last key's row: " << r.err;
  const nlohmann::json j = nlohmann::json::parse(readWholeFile(report));
  EXPECT_EQ(j.at("key_times").size(), 2000u);
}

// A camera whose far clip plane is nearer than every surface: black frames, which the tools
// that render the camera's view (rad-intervals, rad-compose) now warn about and count.
TEST_F(CommandLineEnvironment, ClipPlanesThatCutAwayTheSceneWarnAndCount) {
  nlohmann::json gltf = nlohmann::json::parse(readWholeFile(kScene));
  gltf["cameras"][0]["perspective"]["zfar"] = 0.02;  // znear 0.01; the room is metres away
  const std::string scene = (dir / "clipped.gltf").string();
  std::ofstream(scene) << gltf.dump();
  const std::vector<CommandResult> r = runStages(scene, "", "clipped");
  for (const CommandResult& stage : r) ASSERT_EQ(stage.exitCode, 0) << stage.err;
  for (int i : {1, 3}) {
    EXPECT_NE(r[i].err.find("warning: 2 of 2 frames show no surface"), std::string::npos)
        << r[i].err;
    EXPECT_NE(r[i].err.find("zfar 0.02"), std::string::npos) << r[i].err;
  }
  for (const char* report : {"clipped.intervals.json", "clipped.compose.json"})
    EXPECT_EQ(nlohmann::json::parse(readWholeFile((dir / report).string())).at("empty_frames"), 2)
        << report;
  // The uncut scene: no warning, none counted.
  for (const char* report : {"fast.intervals.json", "fast.compose.json"})
    EXPECT_EQ(nlohmann::json::parse(readWholeFile((dir / report).string())).at("empty_frames"), 0)
        << report;
}

}  // namespace
}  // namespace rad::test
