// rad-compose's peak memory (maximum resident set of the child process, wait4) holds neither
// the global solution's links nor copies of the movie textures, and stays flat in the number of
// frames composed. The real stages (rad-global, rad-intervals, rad-movies) run on the bundled
// moving Cornell box, frames 0-47 at 352x240. Then:
//  - global.rlh padded with 4 M unused link samples (+48 MB on disk) must raise rad-compose's
//    peak by less than 32 MiB: it reads only the radiosity and releases the file's bytes once
//    read (they are in memory only while the file is validated, before the GL context, Embree
//    and the movies). Before, the whole file and a copy of its link arrays were held for the
//    whole sequence: +96 MiB here (93 -> 189 MiB; now 90 -> 103), +94 MB on the 32-cube
//    benchmark (peak 240 MiB, now 108);
//  - composing 48 frames must peak within 10 % of composing one (the texture copies per active
//    movie used to keep the capacity of the largest texture each slot ever held).
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "formats/container.h"
#include "formats/gltf_scene.h"
#include "formats/link_hierarchy.h"
#include "tests/cli/cli_util.h"

namespace fs = std::filesystem;

namespace rad::test {
namespace {

const std::string kScene = std::string(RAD_SOURCE_DIR) + "/pipelines/scenes/cornell-moving.gltf";

// Runs `args` (no shell, output discarded) and returns its peak resident set in MiB, or -1 if
// it did not exit with 0.
double peakRssMiB(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = ::fork();
  if (pid == 0) {
    std::freopen("/dev/null", "w", stdout);
    std::freopen("/dev/null", "w", stderr);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  int status = 0;
  struct rusage usage {};
  if (pid < 0 || ::wait4(pid, &status, 0, &usage) != pid) return -1;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return -1;
  return double(usage.ru_maxrss) / 1024.0;  // KiB on Linux
}

TEST(RadComposeMemory, HoldsNeitherTheLinksNorTextureCopiesAndIsFlatInLength) {
  const fs::path dir =
      fs::path(::testing::TempDir()) / ("rad_compose_memory_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string g = (dir / "global.rlh").string(), i = (dir / "intervals.rti").string(),
                    movies = (dir / "movies").string(), padded = (dir / "padded.rlh").string();
  CommandResult r =
      runCommand(tool("rad-global") + " " + kScene + " -o " + g + " --frames 0-47 --threads 1");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  r = runCommand(tool("rad-intervals") + " " + kScene + " -o " + i +
                 " --frames 0-47 --size 352x240 --threads 1");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  r = runCommand(tool("rad-movies") + " " + kScene + " " + g + " " + i + " -o " + movies +
                 " --threads 1");
  ASSERT_EQ(r.exitCode, 0) << r.err;

  // The same solution with 6 M more (unreferenced, valid) link samples.
  {
    Scene scene = readGltfScene(kScene);
    ContainerReader reader = ContainerReader::open(g);
    GlobalSolution s = readLinkHierarchy(reader, scene);
    const size_t extra = 4u << 20;  // keys, F·V and V: 48 MB
    s.linkSampleKeys.resize(s.linkSampleKeys.size() + extra, 0u);
    s.linkSampleValues.resize(s.linkSampleValues.size() + extra, 0.5f);
    s.linkSampleVisibility.resize(s.linkSampleValues.size(), 1.0f);
    writeLinkHierarchy(padded, s, reader.provenance(), reader.metadata());
  }
  ASSERT_GT(fs::file_size(padded), fs::file_size(g) + (45u << 20));

  auto compose = [&](const std::string& global, const std::string& frames) {
    return peakRssMiB({tool("rad-compose"), kScene, global, i, movies, "-o",
                       (dir / ("frames_" + frames)).string(), "--frames", frames, "--no-png",
                       "--threads", "1"});
  };
  const double one = compose(g, "0-0"), all = compose(g, "0-47"),
               withPadding = compose(padded, "0-47");
  std::printf(
      "rad-compose peak memory: 1 frame %.1f MiB, 48 frames %.1f MiB, 48 frames with "
      "48 MB more links %.1f MiB\n",
      one, all, withPadding);
  ASSERT_GT(one, 0.0);
  ASSERT_GT(all, 0.0);
  ASSERT_GT(withPadding, 0.0);
  EXPECT_LE(withPadding, all + 32.0);
  EXPECT_LE(all, 1.10 * one);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rad::test
