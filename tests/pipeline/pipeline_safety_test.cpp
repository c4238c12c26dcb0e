// The Makefile layer against a hostile user (issue 54): variables that would split, inject or
// point at what is not the run's own are refused before anything runs; `make clean` removes only
// the pipeline's files; every file of the scene is a dependency, by content; a stamp that cannot
// be written fails the run; `make -n` writes nothing; a stepped range and an odd size make a
// whole movie; the mp4 step stops its ffmpeg and leaves no temporary file on SIGTERM.
#include <sys/mount.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "formats/provenance.h"
#include "tests/cli/cli_util.h"
#include "tests/pipeline/pipeline_util.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

const std::string kScene = std::string(RAD_SOURCE_DIR) + "/pipelines/scenes/cornell-moving.gltf";

void writeFile(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// `make -f animation.mk` with the given assignments (each one shell word) and goal.
CommandResult runMake(const std::vector<std::string>& assignments, const std::string& goal = "",
                      const std::string& environment = "") {
  std::string command = environment + " make --no-print-directory -C " RAD_SOURCE_DIR
                                      " -f pipelines/animation.mk BIN=" RAD_BIN_DIR;
  for (const std::string& a : assignments) command += " " + shellQuote(a);
  return runCommand(command + " " + goal);
}

class PipelineSafety : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(missingStages().empty()) << "stage not built: " << missingStages().front();
  }
};

// Each refused: exit 2, one line saying what is wrong, and nothing run, written or deleted.
TEST_F(PipelineSafety, UnsafeVariablesAreRefusedBeforeAnythingRuns) {
  fs::path dir = freshDir("refused");
  // `OUT="DIR/renders DIR/v2"` once ran `rm -rf DIR/renders DIR/v2`.
  for (const char* name : {"renders", "v2", "home"}) {
    fs::create_directories(dir / name);
    writeFile(dir / name / "keep", "mine");
  }
  writeFile(dir / "a-file", "mine");
  const std::string d = dir.string();
  struct Case {
    std::vector<std::string> assignments;
    std::string says;
  };
  const std::vector<Case> cases = {
      {{"OUT=" + d + "/renders " + d + "/v2"}, "' ' is not allowed in a path"},
      {{"OUT=/"}, "is the root folder"},
      {{"OUT="}, "OUT is empty"},
      {{"OUT=" + d + "/home"}, "is the home folder"},
      {{"OUT=" RAD_SOURCE_DIR}, "is the repository or holds it"},
      {{"OUT=" + fs::path(RAD_SOURCE_DIR).parent_path().string()}, "is the repository or holds it"},
      {{"OUT=" + d + "/x;touch " + d + "/injected"}, "';' is not allowed"},
      {{"OUT=" + d + "/it's"}, "''' is not allowed"},
      {{"OUT=" + d + "/a-file"}, "exists and is not a folder"},
      {{"OUT=" + d + "/o", "SCENE=" + d + "/my scene.gltf"}, "SCENE='" + d + "/my scene.gltf'"},
      {{"OUT=" + d + "/o", "FRAMES=0-7;touch " + d + "/injected"}, "FRAMES=0-7;touch"},
      {{"OUT=" + d + "/o", "SIZE=88"}, "SIZE=88: give WIDTHxHEIGHT"},
      {{"OUT=" + d + "/o", "FPS=0"}, "FPS=0: give a positive number"},
      {{"OUT=" + d + "/o", "QUALITY=best"}, "QUALITY=best: give draft, default or final"},
  };
  for (const Case& c : cases) {
    for (const std::string goal : {"clean", ""}) {
      CommandResult r = runMake(c.assignments, goal, "HOME=" + shellQuote(d + "/home"));
      const std::string what = c.assignments.back() + " " + goal;
      EXPECT_EQ(r.exitCode, 2) << what << "\n" << r.err;
      EXPECT_EQ(countLines(r.err), 1) << what << "\n" << r.err;
      EXPECT_NE(r.err.find(c.says), std::string::npos) << what << "\n" << r.err;
    }
  }
  for (const char* name : {"renders", "v2", "home"})
    EXPECT_TRUE(fs::exists(dir / name / "keep")) << name << " was deleted";
  EXPECT_TRUE(fs::exists(dir / "a-file"));
  EXPECT_FALSE(fs::exists(dir / "injected")) << "a command in a variable ran";
  EXPECT_FALSE(fs::exists(dir / "o")) << "a refused run wrote into OUT";
  fs::remove_all(dir);
}

// `make clean` removes the files the pipeline wrote, by name, and keeps (and names) the folders
// that hold anything else.
TEST_F(PipelineSafety, CleanRemovesOnlyWhatThePipelineWrote) {
  fs::path dir = freshDir("clean");
  fs::path out = dir / "out";
  ASSERT_EQ(runCommand(makeCommand(out)).exitCode, 0);
  writeFile(out / "notes.txt", "mine");
  writeFile(out / "frames" / "graded.exr", "mine");
  CommandResult r = runCommand(makeCommand(out, RAD_BIN_DIR, "clean"));
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(fs::exists(out / "notes.txt"));
  EXPECT_TRUE(fs::exists(out / "frames" / "graded.exr"));
  for (const char* written : {"global.rlh", "intervals.rti", "movies", "frames/0000.exr",
                              "frames/0000.png", "frames/.done", "movie.mp4", "contact-sheet.png",
                              "compose.params", "scene.params", "global-report.json"})
    EXPECT_FALSE(fs::exists(out / written)) << written << " survived make clean";
  EXPECT_NE(r.err.find("kept " + (out / "frames").string()), std::string::npos) << r.err;
  fs::remove(out / "notes.txt");
  fs::remove(out / "frames" / "graded.exr");
  EXPECT_EQ(runCommand(makeCommand(out, RAD_BIN_DIR, "clean")).exitCode, 0);
  EXPECT_FALSE(fs::exists(out)) << "an OUT holding only the pipeline's files is removed";
  EXPECT_TRUE(fs::exists(dir));
  fs::remove_all(dir);
}

// The bundled scene with its buffer in an external .bin and an image beside it, in DIR.
void writeSceneWithExternalFiles(const fs::path& dir) {
  const std::string script =
      "import base64, json, sys\n"
      "src, dst = sys.argv[1], sys.argv[2]\n"
      "j = json.load(open(src))\n"
      "b = j['buffers'][0]\n"
      "open(dst + '/scene.bin', 'wb').write(base64.b64decode(b['uri'].split(',', 1)[1]))\n"
      "b['uri'] = 'scene.bin'\n"
      "j['images'] = [{'uri': 'wall.png'}]\n"
      "json.dump(j, open(dst + '/scene.gltf', 'w'))\n";
  writeFile(dir / "convert.py", script);
  ASSERT_EQ(
      runCommand("python3 " + (dir / "convert.py").string() + " " + kScene + " " + dir.string())
          .exitCode,
      0);
  fs::copy_file(fs::path(RAD_SOURCE_DIR) / "pipelines/scenes/cornell-moving-contact-sheet.png",
                dir / "wall.png");
}

// Flips the bits of the byte at `offset` of `path`, keeping its size.
void changeByte(const fs::path& path, size_t offset) {
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  f.seekg(std::streamoff(offset));
  char c = 0;
  f.get(c);
  f.seekp(std::streamoff(offset));
  f.put(char(~c));
}

// Every file the scene is made of is a prerequisite by its content: a changed .bin or image, and
// a scene replaced by an older file, re-run every stage; a new time on the same bytes re-runs none.
TEST_F(PipelineSafety, EveryFileOfTheSceneIsADependencyByContent) {
  fs::path dir = freshDir("inputs");
  writeSceneWithExternalFiles(dir);
  const fs::path out = dir / "out";
  const std::string make = makeCommand(out, RAD_BIN_DIR, "SCENE=" + (dir / "scene.gltf").string());
  CommandResult first = runCommand(make);
  ASSERT_EQ(first.exitCode, 0) << first.err;
  ASSERT_TRUE(stagesMakeWouldRun(make).empty());
  auto afterChange = [&](const std::string& change, auto&& apply) {
    apply();
    EXPECT_EQ(stagesMakeWouldRun(make), kStages) << change;
    CommandResult r = runCommand(make);
    EXPECT_EQ(r.exitCode, 0) << change << "\n" << r.err;
    EXPECT_TRUE(stagesMakeWouldRun(make).empty()) << "after " << change;
  };
  runCommand("touch " + (dir / "scene.gltf").string() + " " + (dir / "scene.bin").string());
  EXPECT_TRUE(stagesMakeWouldRun(make).empty()) << "a new time on the same bytes";
  afterChange("a byte of the .bin", [&] { changeByte(dir / "scene.bin", 64); });
  afterChange("an older image of other content", [&] {
    changeByte(dir / "wall.png", 100);
    runCommand("touch -d 2001-01-01 " + (dir / "wall.png").string());
  });
  afterChange("the scene replaced by an older copy of other content", [&] {
    std::string text = readWholeFile((dir / "scene.gltf").string());
    writeFile(dir / "older.gltf", text + "\n");
    runCommand("touch -d 2001-01-01 " + (dir / "older.gltf").string());
    fs::rename(dir / "older.gltf", dir / "scene.gltf");
  });
  fs::remove_all(dir);
}

// OUT as a tmpfs of its own while the test runs (root ignores permissions, so a read-only
// mount is the only way to make a folder it cannot write).
struct TmpfsMount {
  fs::path at;
  bool mounted = false;
  explicit TmpfsMount(const fs::path& p) : at(p) {
    fs::create_directories(p);
    mounted = ::mount("none", p.c_str(), "tmpfs", 0, "size=64m") == 0;
  }
  bool makeReadOnly() const {
    return ::mount("none", at.c_str(), "tmpfs", MS_REMOUNT | MS_RDONLY, nullptr) == 0;
  }
  ~TmpfsMount() {
    if (mounted) ::umount(at.c_str());
  }
};

// With OUT read-only, a changed parameter fails the run with one line instead of exit 0 with the
// old frames; an unchanged one is up to date. Root ignores permissions, so as root OUT is on a
// tmpfs remounted read-only.
TEST_F(PipelineSafety, AStampThatCannotBeWrittenFailsTheRun) {
  fs::path dir = freshDir("readonly");
  fs::path out = dir / "out";
  const bool root = ::geteuid() == 0;
  std::unique_ptr<TmpfsMount> tmpfs;
  if (root) {
    tmpfs = std::make_unique<TmpfsMount>(out);
    if (!tmpfs->mounted) GTEST_SKIP() << "root, but cannot mount a tmpfs to make read-only";
  }
  ASSERT_EQ(runCommand(makeCommand(out)).exitCode, 0);
  const auto before = fs::last_write_time(out / "frames" / "0000.exr");
  if (root)
    ASSERT_TRUE(tmpfs->makeReadOnly());
  else
    fs::permissions(out, fs::perms::owner_write, fs::perm_options::remove);
  for (const std::string change : {"COMPOSE_FLAGS=--exposure=2", "FRAMES=0-3"}) {
    CommandResult r = runCommand(makeCommand(out, RAD_BIN_DIR, change));
    EXPECT_NE(r.exitCode, 0) << change;
    EXPECT_NE(r.err.find("cannot write the stamp"), std::string::npos) << change << "\n" << r.err;
  }
  EXPECT_EQ(runCommand(makeCommand(out)).exitCode, 0) << "unchanged parameters: up to date";
  EXPECT_EQ(fs::last_write_time(out / "frames" / "0000.exr"), before);
  if (!root) fs::permissions(out, fs::perms::owner_write, fs::perm_options::add);
  tmpfs.reset();
  fs::remove_all(dir);
}

// `make -n` writes nothing: not OUT, not a stamp.
TEST_F(PipelineSafety, DryRunWritesNothing) {
  fs::path dir = freshDir("dry");
  fs::path out = dir / "out";
  CommandResult planned = runCommand(makeCommand(out, RAD_BIN_DIR, "-n"));
  EXPECT_EQ(planned.exitCode, 0) << planned.err;
  EXPECT_FALSE(fs::exists(out)) << "make -n created OUT";
  ASSERT_EQ(runCommand(makeCommand(out)).exitCode, 0);
  const std::string stamp = readWholeFile((out / "compose.params").string());
  EXPECT_EQ(stagesMakeWouldRun(makeCommand(out, RAD_BIN_DIR, "COMPOSE_FLAGS=--exposure=2")),
            std::vector<std::string>{"rad-compose"});
  EXPECT_EQ(readWholeFile((out / "compose.params").string()), stamp);
  fs::remove_all(dir);
}

// FRAMES=0-15x2 gives an mp4 of its 8 frames (ffmpeg's %04d reader had stopped at the first gap:
// one frame); an odd SIZE is padded to even sides for H.264 instead of failing at the end; the
// contact sheet is a PNG.
TEST_F(PipelineSafety, ASteppedRangeAndAnOddSizeMakeAWholeMovie) {
  fs::path dir = freshDir("stepped");
  fs::path out = dir / "out";
  CommandResult r = runMake({"OUT=" + out.string(), "FRAMES=0-15x2", "SIZE=87x59"});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  CommandResult probe = runCommand(
      "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
      "stream=nb_read_frames,width,height -of csv=p=0 " +
      (out / "movie.mp4").string());
  EXPECT_EQ(probe.out, "88,60,8\n");
  // A PNG, as its name says (ffmpeg's image2 muxer had taken the codec from a `.tmp` name: JPEG).
  EXPECT_EQ(readWholeFile((out / "contact-sheet.png").string()).substr(0, 8),
            std::string("\x89PNG\r\n\x1a\n", 8));
  fs::remove_all(dir);
}

// SIGTERM to make while the mp4 is encoded: ffmpeg is stopped and its temporary file removed.
TEST_F(PipelineSafety, TheMp4StepStopsItsFfmpegOnSigterm) {
  fs::path dir = freshDir("sigterm");
  fs::path out = dir / "out", fake = dir / "fake-bin";
  ASSERT_EQ(runCommand(makeCommand(out)).exitCode, 0);
  fs::remove(out / "movie.mp4");
  fs::create_directories(fake);
  // An ffmpeg that writes its output, says its pid and waits.
  writeFile(fake / "ffmpeg",
            "#!/bin/sh\nfor a in \"$@\"; do last=$a; done\n: > \"$last\"\necho $$ > " +
                (dir / "ffmpeg.pid").string() + "\nexec sleep 60\n");
  fs::permissions(fake / "ffmpeg", fs::perms::owner_all);
  const std::string pid = (dir / "ffmpeg.pid").string();
  CommandResult r = runCommand(
      "{ PATH=" + fake.string() + ":$PATH " + makeCommand(out) + " & m=$!; " +
      "for i in $(seq 200); do [ -s " + pid + " ] && break; sleep 0.05; done; " +
      "kill -TERM $m; wait $m; echo make=$?; p=$(cat " + pid + "); " +
      "for i in $(seq 40); do kill -0 $p 2>/dev/null || break; sleep 0.05; done; " +
      "kill -0 $p 2>/dev/null && { echo ffmpeg-alive; kill $p; }; ls -A " + out.string() + "; }");
  const size_t at = r.out.find("make=");
  ASSERT_NE(at, std::string::npos) << r.out << r.err;
  const std::string after = r.out.substr(at);  // the exit code, then what OUT holds
  EXPECT_EQ(after.find("make=0"), std::string::npos) << after;
  EXPECT_EQ(after.find("ffmpeg-alive"), std::string::npos) << after;
  EXPECT_EQ(after.find(".tmp."), std::string::npos) << "a temporary file was left:\n" << after;
  EXPECT_EQ(after.find("movie.mp4"), std::string::npos) << after;
  fs::remove_all(dir);
}

// Two runs into one OUT at once both succeed (a fixed temporary name, or one run emptying the
// folder the other was reading, had failed one of them).
TEST_F(PipelineSafety, TwoRunsIntoOneOutBothSucceed) {
  fs::path dir = freshDir("concurrent");
  fs::path out = dir / "out";
  const std::string make = makeCommand(out) + " -s";
  CommandResult r =
      runCommand("{ " + make + " & a=$!; " + make + "; b=$?; wait $a; " + "echo \"runs=$?,$b\"; }");
  EXPECT_NE(r.out.find("runs=0,0"), std::string::npos) << r.out << r.err;
  EXPECT_TRUE(stagesMakeWouldRun(makeCommand(out)).empty());
  EXPECT_TRUE(fs::exists(out / "movie.mp4"));
  fs::remove_all(dir);
}

// A path that starts with `-` is passed as a path (`./-scene.gltf`), not read as an option.
TEST_F(PipelineSafety, APathStartingWithADashIsAPath) {
  CommandResult r =
      runMake({"SCENE=-scene.gltf", "OUT=/tmp/-out", "FRAMES=0-7"}, "-s stage-commands");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("rad-global ./-scene.gltf -o /tmp/-out/global.rlh"), std::string::npos)
      << r.out;
}

// QUALITY becomes every stage's --preset (each has quality knobs: rad-intervals' and
// rad-compose's since the edge cells); without FRAMES the stages cover the scene's animation, as
// the tools do without --frames.
TEST_F(PipelineSafety, QualityAndTheScenesFramesReachTheStages) {
  CommandResult r = runMake({"OUT=/tmp/q", "QUALITY=final", "FPS=12"}, "-s stage-commands");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (const std::string line : {"global\t", "intervals\t", "movies\t", "compose\t"}) {
    const size_t at = r.out.find(line);
    ASSERT_NE(at, std::string::npos) << r.out;
    EXPECT_NE(r.out.substr(at, r.out.find('\n', at) - at).find(" --preset final"),
              std::string::npos)
        << r.out;
  }
  CommandResult none = runMake({"OUT=/tmp/q", "FPS=12"}, "-s stage-commands");
  ASSERT_EQ(none.exitCode, 0) << none.err;
  EXPECT_EQ(none.out.find("--preset"), std::string::npos) << none.out;
  CommandResult frames =
      runCommand(tool("rad-inspect") + " --default-frames " + kScene + " --fps 12");
  ASSERT_EQ(frames.exitCode, 0) << frames.err;
  EXPECT_NE(r.out.find("--frames " + frames.out.substr(0, frames.out.find('\n')) + " --fps 12"),
            std::string::npos)
      << frames.out << r.out;
}

// Run from another folder, the defaults (BIN, SCENE) are the repository's, not the folder's.
TEST_F(PipelineSafety, RunFromAnotherFolderTheDefaultsAreTheRepositorys) {
  fs::path dir = freshDir("elsewhere");
  CommandResult r =
      runCommand("cd " + dir.string() +
                 " && make -s -f " RAD_SOURCE_DIR "/pipelines/animation.mk stage-commands");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find(RAD_SOURCE_DIR "/build/bin/rad-global " RAD_SOURCE_DIR
                                      "/pipelines/scenes/cornell-moving.gltf -o out/"),
            std::string::npos)
      << r.out;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rad::test
