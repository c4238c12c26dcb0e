// rad-intervals as a user runs it: output, report, item buffers, determinism, bad flags.
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "formats/item_buffer_exr.h"
#include "formats/texture_intervals.h"
#include "tests/cli/cli_util.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

const std::string kScene = RAD_SOURCE_DIR "/pipelines/scenes/cornell-moving.gltf";

fs::path freshDir(const std::string& name) {
  fs::path d = fs::temp_directory_path() / ("rad_cli_intervals_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TEST(RadIntervalsCli, WritesIntervalsReportAndItemBuffers) {
  fs::path d = freshDir("full");
  CommandResult r = runCommand("cd " + d.string() + " && " + tool("rad-intervals") + " " + kScene +
                               " -o i.rti --frames 0-11 --size 176x120 --item-buffers ib "
                               "--report report.json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find("movies"), std::string::npos) << r.err;
  TextureIntervals iv = readTextureIntervals((d / "i.rti").string());
  EXPECT_EQ(iv.firstFrame, 0);
  EXPECT_EQ(iv.lastFrame, 11);
  EXPECT_EQ(iv.imageWidth, 176);
  EXPECT_FALSE(iv.movies.empty());
  nlohmann::json rep = nlohmann::json::parse(readWholeFile((d / "report.json").string()));
  EXPECT_EQ(rep["frames"], 12);
  EXPECT_EQ(rep["movies"], iv.movies.size());
  EXPECT_GT(rep["item_buffer_ms_per_frame"].get<double>(), 0.0);
  EXPECT_GT(rep["texels_per_frame"].get<double>(), 0.0);
  EXPECT_GT(rep["peak_memory_mb"].get<double>(), 1.0);
  for (int f = 0; f < 12; ++f) {
    char name[16];
    std::snprintf(name, sizeof name, "%04d.exr", f);
    ItemBuffer b = readItemBufferExr((d / "ib" / name).string());
    EXPECT_EQ(b.width, 176);
    EXPECT_EQ(b.height, 120);
  }
  // Nothing but the outputs (no temporaries left behind).
  int entries = 0;
  for (const auto& e : fs::directory_iterator(d)) entries += e.path().filename().string()[0] != '.';
  EXPECT_EQ(entries, 3);
}

TEST(RadIntervalsCli, IdenticalRunsGiveIdenticalFiles) {
  fs::path a = freshDir("a"), b = freshDir("b");
  std::string args = " " + kScene + " -o i.rti --frames 0-23x2 --size 176x120 --max-length 5";
  ASSERT_EQ(runCommand("cd " + a.string() + " && " + tool("rad-intervals") + args).exitCode, 0);
  ASSERT_EQ(runCommand("cd " + b.string() + " && " + tool("rad-intervals") + args).exitCode, 0);
  std::string fa = readWholeFile((a / "i.rti").string());
  EXPECT_GT(fa.size(), 200u);
  EXPECT_EQ(fa, readWholeFile((b / "i.rti").string()));
}

TEST(RadIntervalsCli, WindowsMergedGiveTheOneRunsBytes) {
  // The farm (docs/design.md §7): item buffers by windows of frames, then the sequential pass
  // over their counts writes the one run's intervals.rti, provenance included. Uneven windows
  // and a frame step, so a window's edge falls between frames of --frames.
  fs::path d = freshDir("windows");
  const std::string run = "cd " + d.string() + " && " + tool("rad-intervals") + " " + kScene +
                          " --frames 0-23x2 --size 176x120";
  ASSERT_EQ(runCommand(run + " -o i.rti").exitCode, 0);
  const std::string whole = readWholeFile((d / "i.rti").string());
  fs::remove(d / "i.rti");
  for (const char* w : {"0-6 -o a.rvs", "7-17 -o b.rvs", "18-23 -o c.rvs"}) {
    CommandResult r = runCommand(run + " --window " + w);
    ASSERT_EQ(r.exitCode, 0) << w << ": " << r.err;
  }
  EXPECT_FALSE(fs::exists(d / "i.rti"));  // a window writes its counts, not intervals
  CommandResult merged = runCommand(run + " -o i.rti --merge c.rvs a.rvs b.rvs");
  ASSERT_EQ(merged.exitCode, 0) << merged.err;
  EXPECT_EQ(readWholeFile((d / "i.rti").string()), whole);

  // A missing window, and a window of other parameters, are refused on one line.
  CommandResult missing = runCommand(run + " -o i.rti --merge a.rvs c.rvs");
  EXPECT_EQ(missing.exitCode, 2) << missing.err;
  EXPECT_NE(missing.err.find("no file holds frame 8"), std::string::npos) << missing.err;
  ASSERT_EQ(runCommand(run + " --max-level 1 --window 7-17 -o other.rvs").exitCode, 0);
  CommandResult other = runCommand(run + " -o i.rti --merge a.rvs other.rvs c.rvs");
  EXPECT_NE(other.exitCode, 0);
  EXPECT_NE(other.err.find("other.rvs: made with another max-level"), std::string::npos)
      << other.err;
  EXPECT_EQ(countLines(other.err), 1) << other.err;
}

// A floor of furnished rooms (issue 58): the camera sees one classroom and the corridor, so most
// tops no frame shows get no patch nodes below them (the report's patch_nodes_made against the
// full subdivision's patch_nodes, which intervals.rti still records), and the windows merged
// still give the one run's bytes.
TEST(RadIntervalsCli, FloorOfRoomsSubdividesOnlyTheTopsSeen) {
  fs::path d = freshDir("floor");
  const std::string make = "python3 " RAD_SOURCE_DIR "/pipelines/scenes/make_floor.py " +
                           (d / "floor.gltf").string() + " --triangles 10000";
  ASSERT_EQ(runCommand(make).exitCode, 0);
  const std::string run = "cd " + d.string() + " && " + tool("rad-intervals") +
                          " floor.gltf --frames 0-40x8 --size 176x120";
  CommandResult r = runCommand(run + " -o i.rti --report report.json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  nlohmann::json rep = nlohmann::json::parse(readWholeFile((d / "report.json").string()));
  const long tops = rep["top_patches"], seen = rep["top_patches_seen"];
  EXPECT_EQ(rep["patch_nodes"].get<long>(), 21 * tops);
  EXPECT_EQ(rep["patch_nodes_made"].get<long>(), tops + 20 * seen);
  EXPECT_GT(seen, 0);
  EXPECT_LT(4 * seen, tops) << "most rooms are out of sight";
  const std::string whole = readWholeFile((d / "i.rti").string());
  fs::remove(d / "i.rti");  // the merge records the same command line
  ASSERT_EQ(runCommand(run + " --window 0-16 -o a.rvs").exitCode, 0);
  ASSERT_EQ(runCommand(run + " --window 17-40 -o b.rvs").exitCode, 0);
  ASSERT_EQ(runCommand(run + " -o i.rti --report report.json --merge a.rvs b.rvs").exitCode, 0);
  EXPECT_TRUE(readWholeFile((d / "i.rti").string()) == whole) << "the merge's bytes differ";
}

TEST(RadIntervalsCli, BadValuesAreUsageErrors) {
  fs::path d = freshDir("bad");
  for (std::string flags : {"--max-level -1", "--min-visible-fraction 2", "--size 0x5",
                            "--frames 5-2", "--texel-density 0", "--max-level 9"}) {
    CommandResult r = runCommand(tool("rad-intervals") + " " + kScene + " -o " +
                                 (d / "x.rti").string() + " " + flags);
    EXPECT_EQ(r.exitCode, 2) << flags << ": " << r.err;
    EXPECT_EQ(countLines(r.err), 1) << flags << ": " << r.err;
    EXPECT_EQ(r.err.rfind("rad-intervals: ", 0), 0u) << r.err;
  }
  CommandResult r = runCommand(tool("rad-intervals") + " " + kScene + " -o " +
                               (d / "x.rti").string() + " --camera nope");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find("no camera named 'nope'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(d / "x.rti"));
}

}  // namespace
}  // namespace rad::test
