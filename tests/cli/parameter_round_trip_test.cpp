// Each parameter declared once (issue 55): for every stage tool, every option --print-defaults
// lists is recorded in the provenance of the file the tool writes, under the same name and with
// the value the command line gave. Each tool runs as a user would on the bundled scene, one
// frame at a tiny size, with every option written out explicitly: its default, or where that
// is unset (frames, camera) or slow (size) a value of this test's choosing. A flag (default
// false) is left off and must be recorded as false. The provenance is read back with
// rad-inspect --json: a container's header, an EXR's rad.provenance attribute.
#include <unistd.h>

#include <filesystem>
#include <map>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/cli/cli_util.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

const std::string kScene = RAD_SOURCE_DIR "/pipelines/scenes/cornell-moving.gltf";

// What --print-defaults lists that is no parameter of an output's content: it is the run's
// plumbing, so the provenance does not record it (docs/design.md §5).
const std::set<std::string> kPlumbing = {
    "threads",             // results never depend on it (docs/design.md §11)
    "max-texture-pixels",  // the scene reader's bound; the scene digests record what was read
    "light-units",         // the scene reader's; the lights digest records the lamps as read
    "report",              // the run report's file
    "window",
    "merge",
    "print-windows",  // rad-global's render farm: same bytes either way
    "piece-keys",
    "merge-pieces",  // rad-movies' render farm: the merged movies are the one task's bytes
    "merge-ready",   // the same merge inside the piece tasks
    "piece-costs",   // the cut by known cost: which task bakes which keys, not their bytes
    "piece-seconds",
};

// Values for the options whose default is unset, or too slow for a test.
std::map<std::string, nlohmann::json> chosenValues(const fs::path& dir) {
  return {{"frames", "0-0"},
          {"size", "44x30"},
          {"camera", "camera"},
          {"fps", 24.0},
          {"exposure", 0.5},
          {"item-buffers", (dir / "items").string()},
          {"output", nullptr},  // -o: given by the stage's own command line
          {"spp", 2},
          {"max-depth", 2},
          {"min-area", 1e-3},  // 0 stands for a value resolved from the scene
          // rad-compose's pixel sampling is unset (the intervals'): the shared default here.
          {"pixel-filter", "blackman-harris"},
          {"filter-width", 1.5},
          {"pixel-samples", 3}};
}

struct Stage {
  std::string tool;
  std::string args;                // positionals and -o
  std::string output;              // the file whose provenance is read
  std::set<std::string> plumbing;  // also not recorded by this tool
};

std::vector<Stage> stages(const fs::path& d) {
  const std::string s = d.string();
  const std::string inputs = kScene + " " + s + "/global.rlh " + s + "/intervals.rti ";
  return {
      {"rad-global", kScene + " -o " + s + "/global.rlh", s + "/global.rlh", {"output"}},
      {"rad-intervals", kScene + " -o " + s + "/intervals.rti", s + "/intervals.rti", {"output"}},
      {"rad-movies",
       inputs + "-o " + s + "/movies",
       s + "/movies/000000.exr",
       {"key-step"}},  // the deprecated spellings of --movie-key-step, --occlusion-merge
      {"rad-compose", inputs + s + "/movies -o " + s + "/frames", s + "/frames/0000.exr", {}},
      {"rad-reference",
       kScene + " -o " + s + "/reference",
       s + "/reference/0000.exr",
       {"output", "pixel-centres"}}};  // the deprecated spelling of --pixel-filter none
}

// The stage's command line with every option of `defaults` written out; `given` receives the
// value each recorded option must have.
std::string commandLine(const Stage& stage, const nlohmann::json& defaults, const fs::path& d,
                        nlohmann::json& given) {
  const std::map<std::string, nlohmann::json> chosen = chosenValues(d);
  std::string cmd = tool(stage.tool) + " " + stage.args;
  for (const auto& [name, value] : defaults.items()) {
    if (kPlumbing.count(name) || stage.plumbing.count(name)) continue;
    nlohmann::json v = chosen.count(name) ? chosen.at(name) : value;
    if (name == "output") v = nullptr;
    if (name == "fps" && !value.is_null()) v = value;
    if (name == "size" || name == "frames" || !v.is_null()) given[name] = v;
    if (v.is_boolean()) {
      EXPECT_FALSE(v.get<bool>()) << stage.tool << " --" << name << ": a flag's default";
      continue;
    }
    if (v.is_null()) continue;
    cmd += " --" + name + " '" + (v.is_string() ? v.get<std::string>() : v.dump()) + "'";
  }
  return cmd;
}

// The provenance parameters of `path`, as rad-inspect --json prints them.
nlohmann::json recordedParameters(const std::string& path) {
  CommandResult r = runCommand(tool("rad-inspect") + " --json " + path);
  EXPECT_EQ(r.exitCode, 0) << path << ": " << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out, nullptr, false);
  std::function<nlohmann::json(const nlohmann::json&)> find = [&](const nlohmann::json& n) {
    if (!n.is_structured()) return nlohmann::json();
    if (n.is_object() && n.contains("provenance") && n["provenance"].is_object() &&
        n["provenance"].contains("parameters"))
      return n["provenance"]["parameters"];  // a container's header
    if (n.is_object() && n.contains("rad.provenance") && n["rad.provenance"].is_string())
      return nlohmann::json::parse(n["rad.provenance"].get<std::string>())["parameters"];  // EXR
    for (const auto& child : n) {
      nlohmann::json found = find(child);
      if (!found.is_null()) return found;
    }
    return nlohmann::json();
  };
  return find(j);
}

TEST(ParameterRoundTrip, EveryStageFlagIsRecordedInTheProvenance) {
  const fs::path d = fs::temp_directory_path() / ("rad_round_trip_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  for (const Stage& stage : stages(d)) {
    CommandResult defaults = runCommand(tool(stage.tool) + " --print-defaults");
    ASSERT_EQ(defaults.exitCode, 0) << stage.tool << ": " << defaults.err;
    nlohmann::json given = nlohmann::json::object();
    const std::string cmd = commandLine(stage, nlohmann::json::parse(defaults.out), d, given);
    CommandResult r = runCommand(cmd);
    ASSERT_EQ(r.exitCode, 0) << cmd << "\n" << r.err;
    const nlohmann::json recorded = recordedParameters(stage.output);
    ASSERT_TRUE(recorded.is_object()) << stage.output;
    for (const auto& [name, value] : given.items()) {
      ASSERT_TRUE(recorded.contains(name)) << stage.tool << " --" << name << " is not recorded";
      EXPECT_EQ(recorded[name], value) << stage.tool << " --" << name;
    }
    // And nothing is recorded under a name that is not an option (scene digests aside).
    for (const auto& [name, value] : recorded.items())
      EXPECT_TRUE(given.contains(name) || name == "scene_digests" || name == "output" ||
                  name == "shard")
          << stage.tool << " records " << name << ", which is no option it lists";
  }
  fs::remove_all(d);
}

}  // namespace
}  // namespace rad::test
