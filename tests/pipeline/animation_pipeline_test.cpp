// The whole pipeline through the real Makefile (issue 6, docs/design.md §7): the bundled scene at a
// small size and a few frames; frames are finite and close to a stored reference; a change of
// one stage's parameters re-runs exactly the stages downstream of it; a killed stage leaves
// nothing Make would take as done.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "formats/exr_image.h"
#include "libcommon/reference/image_difference.h"
#include "tests/cli/cli_util.h"
#include "tests/pipeline/pipeline_util.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

FloatImage readImage(const fs::path& path) {
  return readExrImage(path.string(), {"R", "G", "B"});
}

class AnimationPipeline : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(missingStages().empty()) << "stage not built: " << missingStages().front();
  }
};

TEST_F(AnimationPipeline, ProducesFiniteFramesMovieAndContactSheet) {
  fs::path out = freshDir("full");
  CommandResult r = runCommand(makeCommand(out));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (int f = 0; f <= 7; ++f) {
    char name[16];
    std::snprintf(name, sizeof name, "%04d", f);
    fs::path exr = out / "frames" / (std::string(name) + ".exr");
    ASSERT_TRUE(fs::exists(exr)) << exr;
    ASSERT_TRUE(fs::exists(out / "frames" / (std::string(name) + ".png")));
    FloatImage im = readImage(exr);
    ASSERT_EQ(im.width, 88);
    ASSERT_EQ(im.height, 60);
    double sum = 0.0;
    for (size_t p = 0; p < im.pixels.size(); ++p) {
      ASSERT_TRUE(std::isfinite(im.pixels[p])) << exr << " pixel value " << p;
      ASSERT_GE(im.pixels[p], 0.0f) << exr;
      sum += im.pixels[p];
    }
    EXPECT_GT(sum, 0.0) << exr;
  }
  // Plausible energy: frame 4 against the stored output of this pipeline (pixels only, so
  // volatile header keys such as provenance and dates do not matter). Regenerate the
  // reference with the command in tests/data/pipeline/README.md after a deliberate change.
  {
    FloatImage ref =
        readImage(fs::path(RAD_TEST_DATA) / "pipeline" / "cornell-moving-88x60-0004.exr");
    FloatImage im = readImage(out / "frames" / "0004.exr");
    ASSERT_EQ(ref.pixels.size(), im.pixels.size());
    DifferenceStats d = compareImages(im, ref);
    double sumRef = 0.0, sumIm = 0.0;
    for (size_t p = 0; p < im.pixels.size(); ++p) {
      sumRef += ref.pixels[p];
      sumIm += im.pixels[p];
    }
    EXPECT_LT(d.relativeL2(), 0.02) << "relative L2 against the stored frame";
    EXPECT_NEAR(sumIm / sumRef, 1.0, 0.01) << "total energy against the stored frame";
    EXPECT_LT(d.maxAbsDifference, 0.5) << "largest pixel difference (W/m^2/sr)";
    // Pixel (49, 7) lies on the lamp's silhouette: its centre's ray meets the lamp (17.1; the
    // rasterizer's item buffer gave it the ceiling behind, 0.094, until rad-compose decided
    // silhouettes by the ray, refineSilhouettes). The pixel filter (Blackman-Harris 1.5 by
    // default) makes it a blend of the two, nearer the lamp, whose side its centre is on.
    const float silhouette = im.pixels[(size_t(7) * size_t(im.width) + 49) * im.channels.size()];
    EXPECT_GT(silhouette, 5.0f) << "the lamp's silhouette pixel";
    EXPECT_LT(silhouette, 16.0f) << "the lamp's silhouette pixel is anti-aliased";
  }
  EXPECT_GT(fs::file_size(out / "movie.mp4"), 1000u);
  EXPECT_TRUE(fs::exists(out / "contact-sheet.png"));

  // Nothing to do on a second run.
  EXPECT_TRUE(stagesMakeWouldRun(makeCommand(out)).empty());
  // A change of one stage's parameters re-runs exactly that stage and what depends on it.
  // `make -n` writes no stamp; each check is followed by a real run with the default
  // parameters all the same, which must find nothing to do.
  auto expectRerun = [&](const std::string& change, std::vector<std::string> expected) {
    EXPECT_EQ(stagesMakeWouldRun(makeCommand(out, RAD_BIN_DIR, change)), expected) << change;
    ASSERT_EQ(runCommand(makeCommand(out)).exitCode, 0);
    EXPECT_TRUE(stagesMakeWouldRun(makeCommand(out)).empty()) << "after restoring " << change;
  };
  expectRerun("MOVIES_FLAGS=--max-samples=8", {"rad-movies", "rad-compose"});
  expectRerun("COMPOSE_FLAGS=--exposure=1", {"rad-compose"});
  expectRerun("INTERVALS_FLAGS=--texel-density=2", {"rad-intervals", "rad-movies", "rad-compose"});
  expectRerun("GLOBAL_FLAGS=--eps=0.5", {"rad-global", "rad-movies", "rad-compose"});
  fs::remove_all(out);
}

// A stage binary that is missing stops the pipeline with one line naming it, before any stage
// runs; nothing is skipped quietly.
TEST_F(AnimationPipeline, MissingStageIsAnError) {
  fs::path dir = freshDir("missing");
  fs::path bin = dir / "bin", out = dir / "out";
  fs::create_directories(bin);
  for (const std::string& s : kStages)
    if (s != "rad-movies") fs::create_symlink(tool(s), bin / s);
  fs::create_symlink(tool("rad-inspect"), bin / "rad-inspect");
  CommandResult r = runCommand(makeCommand(out, bin.string()));
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find("animation.mk: " + (bin / "rad-movies").string() + " is not built"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out / "frames" / ".done"));
  fs::remove_all(dir);
}

// The stage command lines are written once, in animation.mk; `stage-commands` prints exactly
// what the rules run (bench.py and tradeoff.py take them from there).
TEST_F(AnimationPipeline, StageCommandsAreTheOnesTheRulesRun) {
  fs::path out = freshDir("commands");
  CommandResult printed = runCommand(makeCommand(out, RAD_BIN_DIR, "-s stage-commands"));
  ASSERT_EQ(printed.exitCode, 0) << printed.err;
  CommandResult planned = runCommand(makeCommand(out, RAD_BIN_DIR, "frames -n"));
  ASSERT_EQ(planned.exitCode, 0) << planned.err;
  for (const std::string stage : {"global", "intervals", "movies", "compose"}) {
    const size_t at = printed.out.find(stage + "\t");
    ASSERT_NE(at, std::string::npos) << stage << " missing in:\n" << printed.out;
    const size_t begin = at + stage.size() + 1;
    const std::string command = printed.out.substr(begin, printed.out.find('\n', begin) - begin);
    EXPECT_NE(command.find("/rad-" + stage + " "), std::string::npos) << command;
    EXPECT_NE(planned.out.find(command), std::string::npos)
        << "the rule does not run what stage-commands prints: " << command << "\n"
        << planned.out;
  }
  fs::remove_all(out);
}

// A stage killed after it wrote its output (the worst case for Make: a complete-looking file
// from a failed run) leaves nothing Make takes as done, and the next run redoes it.
TEST_F(AnimationPipeline, KilledStageIsRedoneOnTheNextRun) {
  fs::path dir = freshDir("killed");
  fs::path bin = dir / "bin", out = dir / "out";
  fs::create_directories(bin);
  for (const std::string& s : kStages) fs::create_symlink(tool(s), bin / s);
  fs::create_symlink(tool("rad-inspect"), bin / "rad-inspect");
  // rad-global and rad-movies run to completion, then the process is killed with SIGKILL.
  for (const std::string& s : {std::string("rad-global"), std::string("rad-movies")}) {
    fs::remove(bin / s);
    std::ofstream script(bin / s);
    script << "#!/bin/sh\n" << tool(s) << " \"$@\"\nkill -9 $$\n";
    script.close();
    fs::permissions(bin / s, fs::perms::owner_all);
  }
  CommandResult r = runCommand(makeCommand(out, bin.string(), "-k"));
  EXPECT_NE(r.exitCode, 0);
  EXPECT_FALSE(fs::exists(out / "global.rlh")) << "Make deletes the target of a killed stage";
  EXPECT_TRUE(fs::exists(out / "intervals.rti")) << "the sibling stage is unaffected";
  EXPECT_FALSE(fs::exists(out / "frames" / ".done"));
  // Second run with the real tools: global and everything after it, not intervals.
  EXPECT_EQ(stagesMakeWouldRun(makeCommand(out)),
            (std::vector<std::string>{"rad-global", "rad-movies", "rad-compose"}));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rad::test
