// Flags mean one thing (issues 14, 55): without --frames every tool covers the scene's
// animation, frames 0 .. ceil(end x fps) - 1 (libcommon/scene/frame_range.h animationFrames,
// docs/design.md §1). The bundled scene lasts 4 s; at 24 fps that is frames 0-95, what
// `rad-inspect --default-frames` prints. Each tool runs as a user would, at a
// tiny size so the test is quick, and the range it wrote is read back from its output.
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "formats/container.h"
#include "tests/cli/cli_util.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

const std::string kScene = RAD_SOURCE_DIR "/pipelines/scenes/cornell-moving.gltf";
constexpr int kLastFrame = 95;  // 4 s x 24 fps = 96 frames
const std::string kWholeAnimation = "0-95";

fs::path freshDir(const std::string& name) {
  fs::path d =
      fs::temp_directory_path() / ("rad_frames_default_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string framePath(const fs::path& dir, int frame, const char* ext) {
  char name[32];
  std::snprintf(name, sizeof name, "%04d%s", frame, ext);
  return (dir / name).string();
}

// Frames first..last are present in `dir` and the frames just outside are not.
void expectFrames(const fs::path& dir, const char* ext) {
  for (int f = 0; f <= kLastFrame; ++f) EXPECT_TRUE(fs::exists(framePath(dir, f, ext))) << f;
  EXPECT_FALSE(fs::exists(framePath(dir, kLastFrame + 1, ext)));
}

TEST(FramesDefault, RadGlobalCoversTheAnimation) {
  const fs::path d = freshDir("global");
  const std::string out = (d / "global.rlh").string();
  CommandResult r = runCommand(tool("rad-global") + " " + kScene + " -o " + out + " --eps 0.05");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const ContainerReader g = ContainerReader::open(out);
  EXPECT_EQ(g.metadata().at("first_frame"), 0);
  EXPECT_EQ(g.metadata().at("last_frame"), kLastFrame);
  EXPECT_EQ(g.provenance().parameters.at("frames"), kWholeAnimation);
  fs::remove_all(d);
}

TEST(FramesDefault, RadIntervalsCoversTheAnimation) {
  const fs::path d = freshDir("intervals");
  const std::string out = (d / "intervals.rti").string();
  CommandResult r =
      runCommand(tool("rad-intervals") + " " + kScene + " -o " + out + " --size 44x30");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const ContainerReader iv = ContainerReader::open(out);
  EXPECT_EQ(iv.metadata().at("first_frame"), 0);
  EXPECT_EQ(iv.metadata().at("last_frame"), kLastFrame);
  EXPECT_EQ(iv.provenance().parameters.at("frames"), kWholeAnimation);
  fs::remove_all(d);
}

// The rule on stdout, for a Makefile; --fps changes it.
TEST(FramesDefault, RadInspectPrintsTheRule) {
  CommandResult r = runCommand(tool("rad-inspect") + " --default-frames " + kScene);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.out, kWholeAnimation + "\n");
  r = runCommand(tool("rad-inspect") + " --default-frames " + kScene + " --fps 12");
  EXPECT_EQ(r.out, "0-47\n");
  r = runCommand(tool("rad-inspect") + " --default-frames " + kScene + " --fps 0");
  EXPECT_EQ(r.exitCode, 2) << r.err;
  r = runCommand(tool("rad-inspect") + " --default-frames /nonexistent.gltf");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find("rad-inspect: /nonexistent.gltf: "), std::string::npos) << r.err;
}

TEST(FramesDefault, RadReferenceCoversTheAnimation) {
  const fs::path d = freshDir("reference");
  CommandResult r = runCommand(tool("rad-reference") + " " + kScene + " -o " + d.string() +
                               " --size 4x3 --spp 1 --max-depth 1");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  expectFrames(d, ".exr");
  fs::remove_all(d);
}

// rad-compose's default is the intervals' window, which rad-intervals made the animation; the
// provenance records it.
TEST(FramesDefault, RadComposeCoversTheIntervalsWindow) {
  const fs::path d = freshDir("compose");
  const std::string s = d.string();
  for (const std::string& stage :
       {tool("rad-global") + " " + kScene + " -o " + s + "/global.rlh --frames " + kWholeAnimation +
            " --eps 0.05 --key-step 48",
        tool("rad-intervals") + " " + kScene + " -o " + s + "/intervals.rti --size 44x30",
        tool("rad-movies") + " " + kScene + " " + s + "/global.rlh " + s + "/intervals.rti -o " +
            s + "/movies --min-samples 1 --max-samples 1 --samples-per-form-factor 1",
        tool("rad-compose") + " " + kScene + " " + s + "/global.rlh " + s + "/intervals.rti " + s +
            "/movies -o " + s + "/frames --no-png"}) {
    CommandResult r = runCommand(stage);
    ASSERT_EQ(r.exitCode, 0) << stage << "\n" << r.err;
  }
  expectFrames(d / "frames", ".exr");
  const std::string exr = readWholeFile(framePath(d / "frames", 0, ".exr"));
  EXPECT_NE(exr.find("\"frames\":\"" + kWholeAnimation + "\""), std::string::npos);
  fs::remove_all(d);
}

}  // namespace
}  // namespace rad::test
