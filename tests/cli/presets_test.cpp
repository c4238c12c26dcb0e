// Quality presets (issue 55): --preset draft|default|final on every stage tool sets that stage's
// quality knobs (README "Recommended settings"), explicit flags override it, --print-defaults
// prints what it sets, and the provenance records the preset beside the values in effect.
#include <unistd.h>

#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "formats/container.h"
#include "tests/cli/cli_util.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

const std::string kScene = RAD_SOURCE_DIR "/pipelines/scenes/cornell-moving.gltf";

nlohmann::json defaultsOf(const std::string& command) {
  CommandResult r = runCommand(command + " --print-defaults");
  EXPECT_EQ(r.exitCode, 0) << command << ": " << r.err;
  return nlohmann::json::parse(r.out, nullptr, false);
}

// The keys whose values differ between two --print-defaults objects.
std::vector<std::string> differences(const nlohmann::json& a, const nlohmann::json& b) {
  std::vector<std::string> keys;
  for (const auto& [key, value] : a.items())
    if (!b.contains(key) || b[key] != value) keys.push_back(key);
  return keys;
}

TEST(Presets, FinalDiffersFromDefaultInItsKnobsOnly) {
  const nlohmann::json base = defaultsOf(tool("rad-global"));
  const nlohmann::json def = defaultsOf(tool("rad-global") + " --preset default");
  const nlohmann::json final = defaultsOf(tool("rad-global") + " --preset final");
  const nlohmann::json draft = defaultsOf(tool("rad-global") + " --preset=draft");
  EXPECT_EQ(base, def);
  EXPECT_NE(final, def);
  EXPECT_EQ(differences(final, def),
            (std::vector<std::string>{"eps", "key-step", "preset", "rays"}));
  EXPECT_EQ(final["eps"], 1e-5);
  EXPECT_EQ(final["key-step"], 4);
  EXPECT_EQ(final["rays"], 64);
  EXPECT_EQ(differences(draft, def), (std::vector<std::string>{"eps", "preset"}));
  EXPECT_EQ(draft["eps"], 0.02);

  const nlohmann::json movies = defaultsOf(tool("rad-movies") + " --preset final");
  EXPECT_EQ(differences(movies, defaultsOf(tool("rad-movies"))),
            (std::vector<std::string>{"gather-partial-share", "min-samples", "movie-key-step",
                                      "near-shooter-levels", "preset"}));
  EXPECT_EQ(movies["min-samples"], 64);
  EXPECT_EQ(movies["gather-partial-share"], 0.001);
  // The final frames sample more (rad-compose takes the intervals' grid) and weigh every edge
  // cell by coverage.
  const nlohmann::json intervals = defaultsOf(tool("rad-intervals") + " --preset final");
  EXPECT_EQ(differences(intervals, defaultsOf(tool("rad-intervals"))),
            (std::vector<std::string>{"pixel-samples", "preset"}));
  EXPECT_EQ(intervals["pixel-samples"], 5);
  const nlohmann::json compose = defaultsOf(tool("rad-compose") + " --preset final");
  EXPECT_EQ(differences(compose, defaultsOf(tool("rad-compose"))),
            (std::vector<std::string>{"edge-contrast", "preset"}));
  EXPECT_EQ(compose["edge-contrast"], 0.0);
}

TEST(Presets, AnExplicitFlagOverridesThePreset) {
  for (const std::string order : {" --preset final --eps 0.5", " --eps 0.5 --preset final"}) {
    // --print-defaults shows the preset's values; the run uses the flag's.
    EXPECT_EQ(defaultsOf(tool("rad-global") + order)["eps"], 1e-5);
    const fs::path d = fs::temp_directory_path() / ("rad_presets_" + std::to_string(::getpid()));
    fs::create_directories(d);
    const std::string out = (d / "global.rlh").string();
    CommandResult r =
        runCommand(tool("rad-global") + " " + kScene + " -o " + out + " --frames 0-0" + order);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json p = ContainerReader::open(out).provenance().parameters;
    EXPECT_EQ(p.at("preset"), "final");
    EXPECT_EQ(p.at("eps"), 0.5) << order;
    EXPECT_EQ(p.at("rays"), 64);
    EXPECT_EQ(p.at("key-step"), 4);
    fs::remove_all(d);
  }
}

TEST(Presets, AnUnknownPresetIsAUsageError) {
  for (const char* t : {"rad-global", "rad-intervals", "rad-movies", "rad-compose"}) {
    CommandResult r = runCommand(tool(t) + " a b c d -o e --preset best");
    EXPECT_EQ(r.exitCode, 2) << t;
    EXPECT_NE(r.err.find(std::string(t) + ": --preset: best not in {draft,default,final}"),
              std::string::npos)
        << r.err;
  }
}

// Each flag name means one thing: rad-movies' occlusion merge is --occlusion-merge; --merge,
// rad-global's key-window merge, is a deprecated spelling there with one warning line.
TEST(Presets, MoviesMergeIsADeprecatedSpellingOfOcclusionMerge) {
  const nlohmann::json d = defaultsOf(tool("rad-movies"));
  EXPECT_EQ(d.at("occlusion-merge"), "exact");
  CommandResult r = runCommand(tool("rad-movies") + " --merge max --print-defaults");
  EXPECT_EQ(r.exitCode, 0);
  r = runCommand(tool("rad-movies") + " s.gltf g.rlh i.rti -o m --merge max");
  EXPECT_EQ(r.exitCode, 1) << r.err;  // the missing scene, after the warning
  EXPECT_EQ(r.err.rfind("rad-movies: warning: --merge is deprecated; use --occlusion-merge\n", 0),
            0u)
      << r.err;
  r = runCommand(tool("rad-movies") + " s.gltf g.rlh i.rti -o m --merge max --occlusion-merge sum");
  EXPECT_EQ(r.exitCode, 2) << r.err;
}

// --help lists the groups in this order.
TEST(Presets, HelpGroupsComeInOrder) {
  for (const char* t : {"rad-global", "rad-movies"}) {
    const std::string help = runCommand(tool(t) + " --help").out;
    size_t at = 0;
    for (const char* group :
         {"Common:", "Quality (set by --preset):", "Advanced:", "Baselines for comparison:"}) {
      const size_t found = help.find(std::string("\n") + group + "\n");
      ASSERT_NE(found, std::string::npos) << t << ": " << group;
      EXPECT_GT(found, at) << t << ": " << group;
      at = found;
    }
  }
  const std::string global = runCommand(tool("rad-global") + " --help").out;
  const size_t baselines = global.find("Baselines for comparison:");
  for (const char* flag : {"--no-coherence", "--no-clustering", "--no-closure"})
    EXPECT_GT(global.find(flag), baselines) << flag;
}

}  // namespace
}  // namespace rad::test
