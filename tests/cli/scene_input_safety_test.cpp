// Issue 54 at the command line: every stage prints a scene's warnings, refuses a scene that is
// not a regular file in milliseconds, reports out of memory as exit 4; rad-inspect --inputs
// lists a scene's files with content hashes for make.
#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <sstream>

#include <gtest/gtest.h>

#include "tests/cli/cli_util.h"
#include "tests/format/gltf_test_files.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

class SceneInputSafety : public TexturedTriangleFolder {
 protected:
  SceneInputSafety() : TexturedTriangleFolder("rad_scene_safety_") {}
  // Runs and checks it ends within `seconds` (a FIFO read must not wait for a writer).
  CommandResult runFast(const std::string& command, double seconds = 20.0) {
    const auto start = std::chrono::steady_clock::now();
    CommandResult r = runCommand("timeout 60 " + command);
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
              seconds)
        << command;
    return r;
  }
};

int countOf(const std::string& text, const std::string& part) {
  int n = 0;
  for (size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}

// Each stage loads the scene before its other inputs: the warning comes first, once.
TEST_F(SceneInputSafety, EveryStagePrintsTheScenesWarningsOnce) {
  const std::string scene = at("scene.gltf");
  writeFile(scene, texturedTriangleGltf("missing.png"));
  const std::string out = " -o " + at("out");
  const std::vector<std::pair<std::string, std::string>> stages = {
      {"rad-global", out},
      {"rad-intervals", out},
      {"rad-movies", " g.rlh i.rti" + out},
      {"rad-compose", " g.rlh i.rti movies" + out},
      {"rad-reference", " --spp 1 --size 8x6 --frames 0" + out}};
  for (const auto& [t, rest] : stages) {
    CommandResult r = runFast(tool(t) + " " + scene + rest, 120.0);
    const std::string line =
        t + ": " + scene + ": warning: texture 0: image 0 'missing.png': no such file";
    EXPECT_EQ(countOf(r.err, line), 1) << t << ": " << r.err;
    EXPECT_EQ(r.err.rfind(line, 0), 0u) << t << ": " << r.err;
  }
}

TEST_F(SceneInputSafety, NonRegularSceneIsRefusedAtOnce) {
  ASSERT_EQ(::mkfifo(at("pipe.gltf").c_str(), 0600), 0);
  fs::create_directories(at("dir.gltf"));
  const std::vector<std::pair<std::string, std::string>> cases = {
      {at("pipe.gltf"), "not a regular file (a FIFO)"},
      {at("dir.gltf"), "not a regular file (a directory)"},
      {"/dev/zero", "not a regular file (a character device)"}};
  for (const char* t : {"rad-global", "rad-inspect"}) {
    for (const auto& [path, why] : cases) {
      if (t == std::string("rad-inspect") && path == at("dir.gltf")) continue;  // a movie folder
      CommandResult r = runFast(tool(t) + " " + path + (t[4] == 'g' ? " -o " + at("o") : ""));
      EXPECT_EQ(r.exitCode, 1) << t << " " << path << ": " << r.err;
      EXPECT_EQ(r.err, std::string(t) + ": " + path + ": " + why + "\n");
    }
  }
}

TEST_F(SceneInputSafety, FifoBufferAndTextureDoNotHang) {
  ASSERT_EQ(::mkfifo(at("pipe.bin").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo(at("pipe.png").c_str(), 0600), 0);
  writeFile(at("buffer.gltf"), texturedTriangleGltf("", 0.8, "pipe.bin"));
  CommandResult r = runFast(tool("rad-global") + " " + at("buffer.gltf") + " -o " + at("o"));
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(r.err, "rad-global: " + at("buffer.gltf") +
                       ": buffer 0 'pipe.bin': not a regular file (a FIFO)\n");
  writeFile(at("texture.gltf"), texturedTriangleGltf("pipe.png"));
  r = runFast(tool("rad-inspect") + " --check " + at("texture.gltf"));
  EXPECT_EQ(r.exitCode, 0) << r.err;
}

// 8000^2 grey pixels are within the default limit; their float copy does not fit in 300 MB.
TEST_F(SceneInputSafety, OutOfMemoryWhileReadingIsExit4) {
  writeFile(at("big.png"), zeroPng(8000, 8000));
  writeFile(at("scene.gltf"), texturedTriangleGltf("big.png"));
  CommandResult r = runFast(
      "sh -c 'ulimit -v 400000; exec " + tool("rad-inspect") + " " + at("scene.gltf") + "'", 60.0);
  EXPECT_EQ(r.exitCode, 4) << r.err;
  EXPECT_EQ(r.err,
            "rad-inspect: " + at("scene.gltf") + ": out of memory while reading the scene\n");
}

TEST_F(SceneInputSafety, TextureAboveThePixelLimitIsAWarningAndTheOptionMovesIt) {
  writeFile(at("tex.png"), encodedImage(4, 4, false));
  writeFile(at("scene.gltf"), texturedTriangleGltf("tex.png"));
  CommandResult r = runFast(tool("rad-global") + " --max-texture-pixels 15 --print-defaults");
  EXPECT_NE(r.out.find("\"max-texture-pixels\": 67108864"), std::string::npos) << r.out;
  r = runFast(tool("rad-inspect") + " --max-texture-pixels 15 --json " + at("scene.gltf"));
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("4x4 pixels"), std::string::npos) << r.out;
  r = runFast(tool("rad-inspect") + " --max-texture-pixels 0 " + at("scene.gltf"));
  EXPECT_EQ(r.exitCode, 2) << r.err;
}

TEST_F(SceneInputSafety, InspectInputsListsHashesAndFollowsChanges) {
  writeFile(at("tex.png"), encodedImage(4, 4, false));
  writeFile(at("scene.gltf"), texturedTriangleGltf("tex.png"));
  const std::string command = tool("rad-inspect") + " --inputs " + at("scene.gltf");
  CommandResult r = runFast(command);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  std::istringstream lines(r.out);
  std::vector<std::string> got;
  for (std::string line; std::getline(lines, line);) got.push_back(line);
  ASSERT_EQ(got.size(), 3u) << r.out;
  const std::vector<std::string> paths = {at("scene.gltf"), at("tri.bin"), at("tex.png")};
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(got[i].size(), 8 + 16 + 1 + paths[i].size()) << got[i];
    EXPECT_EQ(got[i].rfind("fnv1a64:", 0), 0u) << got[i];
    EXPECT_EQ(got[i].substr(25), paths[i]) << got[i];
    EXPECT_EQ(got[i][24], '\t') << got[i];
  }
  // One changed byte of the buffer changes its line only.
  std::string bin = texturedTriangleBin();
  bin[60] ^= 1;
  writeFile(at("tri.bin"), bin);
  CommandResult changed = runFast(command);
  EXPECT_EQ(changed.out.substr(0, got[0].size()), got[0]);
  EXPECT_EQ(changed.out.find(got[1]), std::string::npos) << changed.out;
  EXPECT_NE(changed.out.find(got[2]), std::string::npos) << changed.out;
  fs::remove(at("tex.png"));
  CommandResult missing = runFast(command);
  EXPECT_EQ(missing.exitCode, 0) << missing.err;
  EXPECT_NE(missing.out.find("missing\t" + at("tex.png") + "\n"), std::string::npos) << missing.out;
  // Relative scene paths stay relative.
  CommandResult relative =
      runFast("sh -c 'cd " + dir.string() + " && " + tool("rad-inspect") + " --inputs scene.gltf'");
  EXPECT_NE(relative.out.find("\ttri.bin\n"), std::string::npos) << relative.out;
  // A missing buffer, a scene that is not JSON, --inputs with a FILE: one line each.
  fs::remove(at("tri.bin"));
  r = runFast(command);
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_EQ(r.err, "rad-inspect: " + at("scene.gltf") + ": buffer 0 '" + at("tri.bin") +
                       "': no such file\n");
  writeFile(at("bad.gltf"), "{ nope");
  r = runFast(tool("rad-inspect") + " --inputs " + at("bad.gltf"));
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_EQ(countLines(r.err), 1) << r.err;
  r = runFast(tool("rad-inspect") + " --inputs " + at("scene.gltf") + " " + at("scene.gltf"));
  EXPECT_EQ(r.exitCode, 2) << r.err;
  r = runFast(tool("rad-inspect") + " --help");
  EXPECT_NE(r.out.find("--inputs"), std::string::npos);
}

}  // namespace
}  // namespace rad::test
