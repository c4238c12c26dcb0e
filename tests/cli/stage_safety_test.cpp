// Issue 54 (pipeline safety), the tools' part: --threads is bounded; GL stages under an
// address-space limit end with exit 4 and one line, never a signal; SIGINT and SIGTERM leave no
// temporary file; intermediates from a scene with other materials or another camera are
// refused naming the part.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/inotify.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "tests/cli/cli_util.h"

namespace fs = std::filesystem;
using rad::test::runCommand;
using rad::test::tool;

namespace {

const std::string kScene = RAD_SOURCE_DIR "/pipelines/scenes/cornell-moving.gltf";
const std::string kSmall = " --frames 0-1";
const std::string kSize = " --size 88x60";

// The bundled scene with `edit` applied, written to `path`.
void writeEditedScene(const std::string& path, const std::function<void(nlohmann::json&)>& edit) {
  nlohmann::json g = nlohmann::json::parse(rad::test::readWholeFile(kScene));
  edit(g);
  std::ofstream(path) << g.dump();
}

class StageSafety : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("rad_stage_safety_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const std::string d = dir_.string();
    writeEditedScene(d + "/materials.gltf", [](nlohmann::json& g) {
      g["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"][0] = 0.3;
    });
    writeEditedScene(d + "/camera.gltf", [](nlohmann::json& g) {
      for (auto& n : g["nodes"])
        if (n.contains("camera")) n["translation"][0] = n["translation"][0].get<double>() + 0.1;
    });
    for (const std::string& cmd :
         {tool("rad-global") + " " + kScene + " -o " + d + "/global.rlh" + kSmall,
          tool("rad-intervals") + " " + kScene + " -o " + d + "/intervals.rti" + kSmall + kSize,
          tool("rad-movies") + " " + kScene + " " + d + "/global.rlh " + d + "/intervals.rti -o " +
              d + "/movies"}) {
      const auto r = runCommand(cmd);
      ASSERT_EQ(r.exitCode, 0) << cmd << "\n" << r.err;
    }
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static std::string path(const std::string& name) { return (dir_ / name).string(); }

  static fs::path dir_;
};
fs::path StageSafety::dir_;

TEST_F(StageSafety, ThreadsAboveTheLimitAreAUsageError) {
  for (const char* t : {"rad-global", "rad-intervals", "rad-movies", "rad-compose"}) {
    const auto r = runCommand(tool(t) + " --threads 100000000 a b c d -o out");
    EXPECT_EQ(r.exitCode, 2) << t << ": " << r.err;
    EXPECT_EQ(rad::test::countLines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("--threads"), std::string::npos) << r.err;
  }
  EXPECT_EQ(runCommand(tool("rad-global") + " --threads 1024 --print-defaults").exitCode, 0);
}

// rad-intervals and rad-compose under `ulimit -v`: Mesa crashed (SIGSEGV in the shader compile,
// LLVM's abort) at 300-600 MB; now exit 0, or 4 with one line.
TEST_F(StageSafety, GlStagesUnderAnAddressSpaceLimitEndWithExit4NotASignal) {
  const std::string d = dir_.string();
  for (int mb : {300, 450, 600}) {
    const std::string limit = "ulimit -v " + std::to_string(mb * 1024) + "; exec ";
    for (const std::string& cmd :
         {tool("rad-intervals") + " " + kScene + " -o " + d + "/limited.rti" + kSmall + kSize,
          tool("rad-compose") + " " + kScene + " " + d + "/global.rlh " + d + "/intervals.rti " +
              d + "/movies -o " + d + "/limited-frames"}) {
      const auto r = runCommand("bash -c '" + limit + cmd + "'");
      EXPECT_TRUE(r.exitCode == 0 || r.exitCode == 4)
          << mb << " MB: " << cmd << ": " << r.exitCode << "\n"
          << r.err;
      if (r.exitCode == 4) {
        EXPECT_EQ(rad::test::countLines(r.err), 1) << mb << " MB: " << r.err;
      }
    }
  }
}

TEST_F(StageSafety, OtherMaterialsAreRefusedNamingThePart) {
  const std::string d = dir_.string();
  const auto r = runCommand(tool("rad-movies") + " " + d + "/materials.gltf " + d + "/global.rlh " +
                            d + "/intervals.rti -o " + d + "/movies-materials");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(rad::test::countLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("global.rlh: made from a scene whose materials differ"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("re-run rad-global"), std::string::npos) << r.err;
  const auto c =
      runCommand(tool("rad-compose") + " " + d + "/materials.gltf " + d + "/global.rlh " + d +
                 "/intervals.rti " + d + "/movies -o " + d + "/frames-materials");
  EXPECT_EQ(c.exitCode, 1) << c.err;
  EXPECT_NE(c.err.find("materials differ"), std::string::npos) << c.err;
}

// rad-global does not depend on the camera; the intervals do.
TEST_F(StageSafety, AnotherCameraRefusesTheIntervalsOnly) {
  const std::string d = dir_.string();
  const auto r = runCommand(tool("rad-movies") + " " + d + "/camera.gltf " + d + "/global.rlh " +
                            d + "/intervals.rti -o " + d + "/movies-camera");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(rad::test::countLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("intervals.rti: made from a scene whose camera differs"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("re-run rad-intervals"), std::string::npos) << r.err;
}

// Movies baked from the old materials, with a global solution and intervals of the new scene.
TEST_F(StageSafety, ComposeRefusesMoviesOfOtherMaterials) {
  const std::string d = dir_.string();
  const std::string scene = d + "/materials.gltf";
  for (const std::string& cmd :
       {tool("rad-global") + " " + scene + " -o " + d + "/global-m.rlh" + kSmall,
        tool("rad-intervals") + " " + scene + " -o " + d + "/intervals-m.rti" + kSmall + kSize}) {
    const auto r = runCommand(cmd);
    ASSERT_EQ(r.exitCode, 0) << cmd << "\n" << r.err;
  }
  const auto r = runCommand(tool("rad-compose") + " " + scene + " " + d + "/global-m.rlh " + d +
                            "/intervals-m.rti " + d + "/movies -o " + d + "/frames-m");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find("movies: made from a scene whose materials differ"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("re-run rad-movies"), std::string::npos) << r.err;
}

// Starts `argv` with stdout and stderr to /dev/null; returns its pid.
pid_t spawnQuiet(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t quiet;
  posix_spawn_file_actions_init(&quiet);
  posix_spawn_file_actions_addopen(&quiet, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&quiet, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = -1;
  posix_spawn(&pid, argv[0], &quiet, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&quiet);
  return pid;
}

std::vector<std::string> temporariesIn(const fs::path& dir) {
  std::vector<std::string> found;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp") != std::string::npos)
      found.push_back(e.path().filename().string());
  return found;
}

// Stops rad-global the moment its temporary global.rlh appears (inotify, then SIGSTOP), sends
// `sig` and lets it go on: it must remove the temporary and die of `sig`. Returns false when the
// write finished before the stop landed (the caller tries again).
bool interruptMidWrite(const fs::path& out, int sig) {
  fs::remove_all(out);
  fs::create_directories(out);
  const int watch = inotify_init1(IN_CLOEXEC | IN_NONBLOCK);
  inotify_add_watch(watch, out.c_str(), IN_CREATE);
  const pid_t pid = spawnQuiet(
      {tool("rad-global"), kScene, "-o", (out / "global.rlh").string(), "--frames", "0-1"});
  bool stopped = false;
  for (int waited = 0; !stopped && waited < 120000; waited += 10) {
    pollfd p{watch, POLLIN, 0};
    if (::poll(&p, 1, 10) <= 0) continue;
    char buf[4096];
    for (ssize_t n; (n = ::read(watch, buf, sizeof buf)) > 0;)
      for (ssize_t i = 0; i < n;) {
        const auto* e = reinterpret_cast<const inotify_event*>(buf + i);
        if (e->len && std::string(e->name).rfind(".global.tmp.", 0) == 0 && !stopped) {
          ::kill(pid, SIGSTOP);
          stopped = true;
        }
        i += ssize_t(sizeof(inotify_event) + e->len);
      }
  }
  ::close(watch);
  const bool midWrite = stopped && !temporariesIn(out).empty();
  ::kill(pid, midWrite ? sig : SIGCONT);
  ::kill(pid, SIGCONT);
  int status = 0;
  ::waitpid(pid, &status, 0);
  if (!midWrite) return false;
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << "status " << status;
  const std::vector<std::string> left = temporariesIn(out);
  EXPECT_TRUE(left.empty()) << left.front();
  EXPECT_FALSE(fs::exists(out / "global.rlh"));
  return true;
}

TEST_F(StageSafety, SigtermAndSigintMidWriteLeaveNoTemporary) {
  for (int sig : {SIGTERM, SIGINT}) {
    bool done = false;
    for (int attempt = 0; attempt < 5 && !done; ++attempt)
      done = interruptMidWrite(dir_ / ("interrupted-" + std::to_string(sig)), sig);
    EXPECT_TRUE(done) << "the write never outlasted a SIGSTOP (signal " << sig << ")";
  }
}

}  // namespace
