// rad-movies end to end on the Cornell box (tests/data/external/cornell_box): a global solution
// and intervals written here (constant key times over the window, every surface a bad receiver
// of the light), the tool run as a user runs it; movies read back; shards, the baseline,
// determinism, report, errors, the frame-window check and the key-step flags checked.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include "formats/gltf_scene.h"
#include "formats/link_hierarchy.h"
#include "formats/provenance.h"
#include "formats/texture_intervals.h"
#include "formats/texture_movie.h"
#include "libcommon/scene/frame_range.h"
#include "tests/cli/cli_util.h"

namespace fs = std::filesystem;

namespace rad::test {
namespace {

const std::string kScene = std::string(RAD_TEST_DATA) + "/external/cornell_box/cornell_box.gltf";

class RadMoviesCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::path(::testing::TempDir()) /
                        ("rad_movies_cli_" + std::to_string(::getpid())));
    fs::remove_all(*dir_);
    fs::create_directories(*dir_);
    Scene scene = readGltfScene(kScene);
    GlobalSolution g;
    // A key time at every frame of the intervals' window 0-11 (as rad-global --frames 0-11
    // --key-step 1 writes them), all with the same values: the window is covered and every
    // movie key is at a global key time.
    const int K = 12;
    for (int f = 0; f < K; ++f) g.keyTimes.push_back(f / 24.0);
    g.hierarchy = PatchHierarchy(scene.inputPolygons());
    const int n = g.hierarchy.topCount();
    std::vector<int> emitters, receivers;
    for (int i = 0; i < n; ++i) {
      int mat = g.hierarchy.top(i).material;
      bool emits = mat >= 0 && scene.materials[size_t(mat)].isEmitter();
      (emits ? emitters : receivers).push_back(i);
      for (int k = 0; k < K; ++k)
        g.nodeRadiosity.push_back(emits ? glm::vec3(scene.materials[size_t(mat)].emission * 3.14159)
                                        : glm::vec3(0.2f));
      g.leafRow.push_back(i);
      for (int c = 0; c < 4 * K; ++c) g.leafVertexGoodIrradiance.push_back(glm::vec3(0.3f));
    }
    ASSERT_FALSE(emitters.empty());
    for (int r : receivers)
      for (int e : emitters) g.badPairs.push_back({uint32_t(r), uint32_t(e)});
    std::sort(g.badPairs.begin(), g.badPairs.end());
    Provenance p = makeProvenance("test", 0, nullptr, nlohmann::json::object());
    writeLinkHierarchy(path("global.rlh"), g, p, nlohmann::json::object());

    TextureIntervals iv;
    iv.firstFrame = 0;
    iv.lastFrame = 11;
    iv.fps = 24.0;
    iv.imageWidth = iv.imageHeight = 64;
    for (int r : receivers) {
      MovieExtent t;
      t.movie = uint32_t(iv.movies.size());
      t.patch = PatchId{uint32_t(r), 1u};
      t.firstFrame = 0;
      t.lastFrame = 11;
      t.width = 8;
      t.height = 6;
      iv.movies.push_back(t);
    }
    MovieExtent child = iv.movies.front();
    child.movie = uint32_t(iv.movies.size());
    child.patch = child.patch.child(2);
    child.firstFrame = 3;
    iv.movies.push_back(child);
    movieCount_ = int(iv.movies.size());
    writeTextureIntervals(path("intervals.rti"), iv, p, nlohmann::json::object());
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  static std::string path(const std::string& name) { return (*dir_ / name).string(); }
  static std::string command(const std::string& out, const std::string& flags = "") {
    return tool("rad-movies") + " " + kScene + " " + path("global.rlh") + " " +
           path("intervals.rti") + " -o " + path(out) + " " + flags;
  }
  static fs::path* dir_;
  static int movieCount_;
};
fs::path* RadMoviesCli::dir_ = nullptr;
int RadMoviesCli::movieCount_ = 0;

TEST_F(RadMoviesCli, BakesEveryMovieWithProvenanceAndAReport) {
  // The hand-made solution carries its good layer as Gouraud vertex values.
  CommandResult r =
      runCommand(command("movies", "--good-layer gouraud --report " + path("report.json")));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  int lit = 0;
  for (int id = 0; id < movieCount_; ++id) {
    TextureMovie m = readTextureMovie(textureMoviePath(path("movies"), uint32_t(id)));
    EXPECT_EQ(m.movie, uint32_t(id));
    EXPECT_EQ(m.keys.size(), 1u) << "static scene: constant movie";
    EXPECT_NE(m.provenanceJson.find("rad-movies"), std::string::npos);
    for (float v : m.keys[0]) {
      ASSERT_TRUE(std::isfinite(v));
      ASSERT_GE(v, 0.3f - 1e-6f) << "at least the good layer";
      lit += v > 0.31f;
    }
  }
  EXPECT_GT(lit, 100);
  nlohmann::json report = nlohmann::json::parse(readWholeFile(path("report.json")));
  EXPECT_EQ(report["movies"], movieCount_);
  EXPECT_EQ(report["constant_movies"], movieCount_);
  EXPECT_GT(report["render_passes"].get<long>(), 0);
  EXPECT_GT(report["blockers_static"].get<long>(), 0);
  EXPECT_EQ(report["blockers_dynamic"], 0);
  EXPECT_TRUE(report["seconds"].contains("transmittance"));
}

TEST_F(RadMoviesCli, SecondRunIsBitIdentical) {
  ASSERT_EQ(runCommand(command("again")).exitCode, 0);
  std::string first = readWholeFile(textureMoviePath(path("again"), 3));
  ASSERT_EQ(runCommand(command("again")).exitCode, 0);
  EXPECT_EQ(readWholeFile(textureMoviePath(path("again"), 3)), first);
  EXPECT_FALSE(first.empty());
}

TEST_F(RadMoviesCli, ShardsPartitionTheMoviesAndBaselineAgrees) {
  ASSERT_EQ(runCommand(command("full")).exitCode, 0);
  ASSERT_EQ(runCommand(command("shards", "--shard 0/3")).exitCode, 0);
  ASSERT_EQ(runCommand(command("shards", "--shard 1/3")).exitCode, 0);
  ASSERT_EQ(runCommand(command("shards", "--shard 2/3")).exitCode, 0);
  ASSERT_EQ(runCommand(command("baseline", "--no-coherence")).exitCode, 0);
  for (int id = 0; id < movieCount_; ++id) {
    TextureMovie a = readTextureMovie(textureMoviePath(path("full"), uint32_t(id)));
    TextureMovie b = readTextureMovie(textureMoviePath(path("shards"), uint32_t(id)));
    TextureMovie c = readTextureMovie(textureMoviePath(path("baseline"), uint32_t(id)));
    EXPECT_EQ(a.keys, b.keys) << id;
    EXPECT_GT(c.keys.size(), 1u) << "the baseline stores every key";
    for (const auto& key : c.keys) EXPECT_EQ(key, a.keys[0]) << id;
  }
  int files = 0;
  for (const auto& e : fs::directory_iterator(path("shards")))
    files += e.path().extension() == ".exr";
  EXPECT_EQ(files, movieCount_);
}

// rad-movies bakes whole movies on one worker per thread (tools/stages/movie_sequence.h): the
// movies must not depend on how many there are, and the report adds the workers' counts up.
TEST_F(RadMoviesCli, WorkersPerThreadChangeNoMovieAndTheReportAddsUp) {
  ASSERT_EQ(runCommand(command("one", "--threads 1 --report " + path("one.json"))).exitCode, 0);
  ASSERT_EQ(runCommand(command("three", "--threads 3 --report " + path("three.json"))).exitCode, 0);
  for (int id = 0; id < movieCount_; ++id) {
    TextureMovie a = readTextureMovie(textureMoviePath(path("one"), uint32_t(id)));
    TextureMovie b = readTextureMovie(textureMoviePath(path("three"), uint32_t(id)));
    EXPECT_EQ(a.keys, b.keys) << id;
  }
  nlohmann::json one = nlohmann::json::parse(readWholeFile(path("one.json")));
  nlohmann::json three = nlohmann::json::parse(readWholeFile(path("three.json")));
  for (const char* count : {"movies", "keys", "texels", "bad_pairs", "samples", "render_passes",
                            "sample_passes", "blockers_static", "good_layer_gather"})
    EXPECT_EQ(one[count], three[count]) << count;
  EXPECT_EQ(three["movie_seconds"].size(), size_t(movieCount_));
  EXPECT_EQ(one["renderer"], three["renderer"]);
}

TEST_F(RadMoviesCli, UsageAndInputErrorsAreOneLine) {
  CommandResult r = runCommand(command("x", "--shard 3/2"));
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_EQ(countLines(r.err), 1) << r.err;
  r = runCommand(command("x", "--merge average"));
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_NE(r.err.find("--merge"), std::string::npos) << r.err;
  // The intervals file given as the global solution: refused by name.
  r = runCommand(tool("rad-movies") + " " + kScene + " " + path("intervals.rti") + " " +
                 path("intervals.rti") + " -o " + path("x"));
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(countLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("intervals.rti"), std::string::npos) << r.err;
}

TEST_F(RadMoviesCli, MovieBeyondTheMemoryBudgetIsRefusedAndLeavesNoFile) {
  // 8x6 texels need far more than 1e-4 MiB of working buffers, whatever the number of keys.
  CommandResult r = runCommand(command("tiny", "--max-texture-memory 0.0001"));
  EXPECT_EQ(r.exitCode, 4) << r.err;
  EXPECT_EQ(countLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("--max-texture-memory"), std::string::npos) << r.err;
  int files = 0;
  for (const auto& e : fs::directory_iterator(path("tiny"))) files += !e.path().empty();
  EXPECT_EQ(files, 0) << "no movie and no temporary left behind";
}

// A global solution whose key times stop before the intervals' last frame would be read outside
// the times it was solved for: refused before any movie is baked, naming both files and ranges.
TEST_F(RadMoviesCli, GlobalSolutionNotCoveringTheIntervalsIsRefused) {
  CommandResult g = runCommand(tool("rad-global") + " " + kScene + " -o " + path("global00.rlh") +
                               " --frames 0-0 --threads 1");
  ASSERT_EQ(g.exitCode, 0) << g.err;
  TextureIntervals iv = readTextureIntervals(path("intervals.rti"));
  iv.lastFrame = 23;
  for (MovieExtent& m : iv.movies) m.lastFrame = 23;
  Provenance p = makeProvenance("test", 0, nullptr, nlohmann::json::object());
  writeTextureIntervals(path("intervals23.rti"), iv, p, nlohmann::json::object());
  CommandResult r = runCommand(tool("rad-movies") + " " + kScene + " " + path("global00.rlh") +
                               " " + path("intervals23.rti") + " -o " + path("window"));
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(countLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("global00.rlh"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("intervals23.rti"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("0-23"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("0-0"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(textureMoviePath(path("window"), 0))) << "no movie baked";
}

// --movie-key-step sets the frames between key textures; --key-step, its old name, still does
// and warns once.
TEST_F(RadMoviesCli, KeyStepIsADeprecatedNameOfMovieKeyStep) {
  CommandResult a = runCommand(command("step-new", "--movie-key-step 3 --no-coherence"));
  ASSERT_EQ(a.exitCode, 0) << a.err;
  EXPECT_TRUE(a.err.empty()) << a.err;
  CommandResult b = runCommand(command("step-old", "--key-step 3 --no-coherence"));
  ASSERT_EQ(b.exitCode, 0) << b.err;
  EXPECT_EQ(b.err, "rad-movies: warning: --key-step is deprecated; use --movie-key-step\n");
  for (int id = 0; id < movieCount_; ++id) {
    TextureMovie x = readTextureMovie(textureMoviePath(path("step-new"), uint32_t(id)));
    TextureMovie y = readTextureMovie(textureMoviePath(path("step-old"), uint32_t(id)));
    EXPECT_EQ(x.keyFrames, keyFrames(x.firstFrame, x.lastFrame, 3)) << id;
    EXPECT_EQ(y.keyFrames, x.keyFrames) << id;
    EXPECT_EQ(y.keys, x.keys) << id;
  }
  TextureMovie first = readTextureMovie(textureMoviePath(path("step-new"), 0));
  EXPECT_EQ(first.keyFrames, (std::vector<int>{0, 3, 6, 9, 11}));
  CommandResult both = runCommand(command("step-both", "--key-step 3 --movie-key-step 3"));
  EXPECT_EQ(both.exitCode, 2) << both.err;
}

}  // namespace
}  // namespace rad::test
