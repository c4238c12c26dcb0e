// rad-global's peak memory does not grow with the animation's length: the links' activity
// intervals are compacted as each key time finishes (only the compact result is held, not every
// key's links) and global.rlh is streamed from the solution's arrays. rad-global runs on the
// bundled moving Cornell box for frames 0-47 and 0-95 (13 and 25 key times); its
// peak_memory_mb (--report) must stay within 20 %. Before, with every key's link samples held
// until the merge and the file assembled in memory, the figures were 15.4 and 18.9 MiB (+23 %);
// then 14.9 and 15.1 (+1 %). Since, the base has grown (21-22 MiB) and the two runs move by up to
// 1 MiB from run to run: 2d1bfbe's binaries gave +14.3 % in one run, 6445953's +8.4 % and
// +10.6 % in two (the lamp's cuts add links, and the written result grows by 0.46 MB). The bound
// is 20 %: it catches a run that keeps every key's links again, not a few hundred kB.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "tests/cli/cli_util.h"

namespace fs = std::filesystem;

namespace rad::test {
namespace {

const std::string kScene = std::string(RAD_SOURCE_DIR) + "/pipelines/scenes/cornell-moving.gltf";

struct GlobalRun {
  double peakMb = 0;
  long keys = 0, links = 0;
};

GlobalRun runGlobal(const fs::path& dir, const std::string& frames) {
  fs::create_directories(dir);
  const std::string g = (dir / "global.rlh").string(), report = (dir / "global.json").string();
  // --eps 1e-3: the compact result (every key's link intervals) grows with the animation as it
  // must; at the default eps (2e-4) it is a larger share of the peak (+10.8 % over 48 more
  // frames) and hides what this test is about, that no key's working links are kept.
  // --key-step 8 (the default is 16): 13 and 25 key times, as the figures above were measured.
  CommandResult r = runCommand(tool("rad-global") + " " + kScene + " -o " + g + " --frames " +
                               frames + " --key-step 8 --threads 1 --eps 1e-3 --report " + report);
  EXPECT_EQ(r.exitCode, 0) << r.err;
  GlobalRun run;
  if (r.exitCode != 0) return run;
  nlohmann::json j = nlohmann::json::parse(readWholeFile(report));
  run.peakMb = j["peak_memory_mb"].get<double>();
  run.keys = long(j["key_times"].size());
  run.links = j["totals"]["links"].get<long>();
  return run;
}

TEST(RadGlobalMemory, PeakMemoryForATwiceLongerAnimationIsWithinTwentyPercent) {
  const fs::path dir =
      fs::path(::testing::TempDir()) / ("rad_global_memory_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  GlobalRun shortRun = runGlobal(dir / "short", "0-47");
  GlobalRun longRun = runGlobal(dir / "long", "0-95");
  std::printf(
      "rad-global peak memory: frames 0-47 %.1f MiB (%ld keys, %ld links), 0-95 %.1f MiB "
      "(%ld keys, %ld links): %+.1f %%\n",
      shortRun.peakMb, shortRun.keys, shortRun.links, longRun.peakMb, longRun.keys, longRun.links,
      100.0 * (longRun.peakMb / shortRun.peakMb - 1.0));
  ASSERT_GT(shortRun.peakMb, 0.0);
  ASSERT_GT(longRun.peakMb, 0.0);
  // The longer animation really has about twice the key times' links (could not fail else).
  EXPECT_GE(longRun.keys, 2 * shortRun.keys - 1);
  EXPECT_GE(longRun.links, 18 * shortRun.links / 10);
  EXPECT_LE(longRun.peakMb, 1.20 * shortRun.peakMb);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rad::test
