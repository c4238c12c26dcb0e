// rad-movies' render-farm pieces (issue 58; tools/stages/movie_pieces.h) on the bundled scene
// through the real tools: movies cut into pieces of keys by --piece-keys tasks and joined by
// --merge-pieces (two merges, each of half the movies) are the one-task bake's files byte for
// byte; a piece is never read as a movie
// (rad-compose refuses it by name); the merge refuses a piece of another run and a missing piece;
// merged inside the piece tasks (--merge-ready), by the task that writes a movie's last piece,
// once even when two tasks find every piece at once.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "formats/texture_movie.h"
#include "tests/cli/cli_util.h"

namespace fs = std::filesystem;

namespace rad::test {
namespace {

const std::string kScene = RAD_SOURCE_DIR "/pipelines/scenes/cornell-moving.gltf";
// Frames 0-11 with a key every 2 frames (every frame where shadows move): movies of 7 or 12
// keys, cut into pieces of at most 3.
const std::string kFrames = "--frames 0-11";
const std::string kMovieFlags = "--movie-key-step 2 --moving-shadow-key-step 1 --threads 2";

class MoviePiecesCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::path(::testing::TempDir()) /
                        ("rad_movie_pieces_" + std::to_string(::getpid())));
    fs::remove_all(*dir_);
    fs::create_directories(*dir_);
    const std::string d = dir_->string();
    CommandResult g = runCommand(tool("rad-global") + " " + kScene + " -o " + d +
                                 "/global.rlh --preset draft " + kFrames);
    ASSERT_EQ(g.exitCode, 0) << g.err;
    CommandResult i = runCommand(tool("rad-intervals") + " " + kScene + " -o " + d +
                                 "/intervals.rti --size 88x60 " + kFrames);
    ASSERT_EQ(i.exitCode, 0) << i.err;
    // The one-task bake, moved aside: the pieces are baked into the same -o (the provenance
    // records it).
    CommandResult m = runCommand(movies(""));
    ASSERT_EQ(m.exitCode, 0) << m.err;
    fs::rename(d + "/movies", d + "/whole");
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  static std::string movies(const std::string& extra, const std::string& out = "movies") {
    const std::string d = dir_->string();
    return tool("rad-movies") + " " + kScene + " " + d + "/global.rlh " + d + "/intervals.rti -o " +
           d + "/" + out + " " + kMovieFlags + " " + extra;
  }
  static std::string path(const std::string& name) { return (*dir_ / name).string(); }
  // The files of a folder by name: their bytes.
  static std::map<std::string, std::string> files(const std::string& folder) {
    std::map<std::string, std::string> out;
    for (const auto& e : fs::directory_iterator(folder))
      out[e.path().filename().string()] = readWholeFile(e.path().string());
    return out;
  }
  static fs::path* dir_;
};
fs::path* MoviePiecesCli::dir_ = nullptr;

const std::regex kPieceName("([0-9]{6})\\.piece-[0-9]{4}\\.exr");

TEST_F(MoviePiecesCli, PiecesMergedAreTheOneTaskBakeByteForByte) {
  for (int s = 0; s < 3; ++s) {
    CommandResult r = runCommand(movies("--piece-keys 3 --shard " + std::to_string(s) + "/3"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
  }
  // The movies cut into pieces (their pieces only, no movie file yet).
  std::set<std::string> split;
  for (const auto& [name, bytes] : files(path("movies"))) {
    std::smatch match;
    if (std::regex_match(name, match, kPieceName)) split.insert(match[1].str() + ".exr");
  }
  ASSERT_GE(split.size(), 2u) << "the scene's movies are longer than 3 keys";
  for (const std::string& name : split) EXPECT_FALSE(fs::exists(path("movies/" + name))) << name;

  // Two merges side by side, each of its share of the movies (slurm.mk's array): their movies
  // record the one-task command line, without --merge-pieces and --shard.
  for (int s = 0; s < 2; ++s) {
    CommandResult merge =
        runCommand(movies("--merge-pieces 3 --shard " + std::to_string(s) + "/2"));
    ASSERT_EQ(merge.exitCode, 0) << merge.err;
  }
  const std::map<std::string, std::string> whole = files(path("whole")),
                                           merged = files(path("movies"));
  ASSERT_EQ(merged.size(), whole.size()) << "no piece left, every movie there";
  for (const auto& [name, bytes] : whole) {
    ASSERT_TRUE(merged.count(name)) << name;
    if (split.count(name)) {
      EXPECT_TRUE(merged.at(name) == bytes)
          << name << ": merged pieces differ from the one-task bake";
    } else {  // a movie of one piece, baked whole by its shard (whose --shard it records)
      EXPECT_EQ(readTextureMovie(path("movies/" + name)).keys,
                readTextureMovie(path("whole/" + std::string(name))).keys)
          << name;
    }
  }
}

// The merge inside the piece tasks (slurm.mk): each task runs --merge-ready after its pieces
// and joins the movies whose pieces are then all written. The tasks run one after the other,
// so the first finds movies still waiting for another task's pieces, and the last joins them.
TEST_F(MoviePiecesCli, TheTaskThatWritesAMoviesLastPieceMergesIt) {
  // Into the one-task bake's -o, which the movies' provenance records.
  const std::string out = "movies";
  fs::remove_all(path(out));
  long waitingAfterTheFirst = -1;  // pieces left by the first task for later ones
  for (int s = 0; s < 3; ++s) {
    const std::string shard = " --shard " + std::to_string(s) + "/3";
    CommandResult r = runCommand(movies("--piece-keys 3" + shard, out));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    CommandResult m = runCommand(movies("--merge-pieces 3 --merge-ready" + shard, out));
    ASSERT_EQ(m.exitCode, 0) << m.err;
    if (s == 0) {
      waitingAfterTheFirst = 0;
      for (const auto& [name, bytes] : files(path(out)))
        waitingAfterTheFirst += std::regex_match(name, kPieceName) ? 1 : 0;
    }
  }
  EXPECT_GT(waitingAfterTheFirst, 0) << "the first task merged movies it had not every piece of";
  const std::map<std::string, std::string> whole = files(path("whole")), merged = files(path(out));
  ASSERT_EQ(merged.size(), whole.size()) << "no piece and no lock left, every movie there";
  int split = 0;
  for (const auto& [name, bytes] : whole) {
    ASSERT_TRUE(merged.count(name)) << name;
    if (readTextureMovie(path("whole/" + name)).keyFrames.size() <= 3) continue;  // one piece
    ++split;
    EXPECT_TRUE(merged.at(name) == bytes) << name << ": merged in the tasks, not the one-task bake";
  }
  EXPECT_GE(split, 2);
}

// Two tasks that both find every piece of the same movies written (they ran at once) merge
// each movie once, under its lock: both succeed, the movies are the one-task bake's.
TEST_F(MoviePiecesCli, TwoTasksMergingAtOnceMergeEachMovieOnce) {
  // Into the one-task bake's -o, which the movies' provenance records.
  const std::string out = "movies";
  fs::remove_all(path(out));
  for (int s = 0; s < 2; ++s) {
    CommandResult r = runCommand(movies("--piece-keys 3 --shard " + std::to_string(s) + "/2", out));
    ASSERT_EQ(r.exitCode, 0) << r.err;
  }
  const std::string a = movies("--merge-pieces 3 --merge-ready --shard 0/2", out),
                    b = movies("--merge-pieces 3 --merge-ready --shard 1/2", out);
  // Each task's messages to its own file: written at once to one pipe they interleave.
  const std::string errA = path("merge-a.err"), errB = path("merge-b.err");
  CommandResult both = runCommand("( " + a + " 2>'" + errA + "' & pid=$!; " + b + " 2>'" + errB +
                                  "'; rb=$?; wait $pid && exit $rb )");
  std::string said;
  for (const std::string& f : {errA, errB}) {
    std::ifstream in(f);
    said += std::string(std::istreambuf_iterator<char>(in), {}) + "\n";
  }
  ASSERT_EQ(both.exitCode, 0) << said;
  long mergedSum = 0;
  const std::regex mergedLine("rad-movies: merged ([0-9]+) movies");
  for (auto it = std::sregex_iterator(said.begin(), said.end(), mergedLine);
       it != std::sregex_iterator(); ++it)
    mergedSum += std::stol((*it)[1].str());
  long split = 0;
  const std::map<std::string, std::string> whole = files(path("whole")), merged = files(path(out));
  ASSERT_EQ(merged.size(), whole.size()) << "no piece and no lock left, every movie there";
  for (const auto& [name, bytes] : whole) {
    if (readTextureMovie(path("whole/" + name)).keyFrames.size() <= 3) continue;
    ++split;
    EXPECT_TRUE(merged.at(name) == bytes) << name;
  }
  EXPECT_EQ(mergedSum, split) << said;
}

// The cut by known cost (--piece-costs, movie_cut.h): an earlier run's report cuts only the
// movies that took longer than --piece-seconds, deals every unit by its estimated cost, and the
// pieces merged inside the tasks are the one-task bake's bytes.
TEST_F(MoviePiecesCli, TheCutByKnownCostMergesToTheOneTaskBake) {
  const std::string report = path("cost-run.json");
  CommandResult r = runCommand(movies("--report " + report, "cost-run"));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json work = nlohmann::json::parse(readWholeFile(report))["work_seconds"];
  std::vector<double> seconds;
  for (const nlohmann::json& w : work) seconds.push_back(w["seconds"].get<double>());
  ASSERT_GE(seconds.size(), 3u);
  std::sort(seconds.begin(), seconds.end());
  // Between the two costliest movies' halves: the costliest are cut, the cheap ones whole.
  const double target = 0.5 * seconds[seconds.size() - 2];
  std::ostringstream flags;
  flags << " --piece-costs " << report << " --piece-seconds " << target;
  const std::string out = "movies";
  fs::remove_all(path(out));
  for (int s = 0; s < 3; ++s) {
    const std::string shard = " --shard " + std::to_string(s) + "/3";
    CommandResult b = runCommand(movies(flags.str() + shard, out));
    ASSERT_EQ(b.exitCode, 0) << b.err;
    CommandResult m =
        runCommand(movies("--merge-pieces 1 --merge-ready" + flags.str() + shard, out));
    ASSERT_EQ(m.exitCode, 0) << m.err;
  }
  const std::map<std::string, std::string> whole = files(path("whole")), merged = files(path(out));
  ASSERT_EQ(merged.size(), whole.size()) << "no piece and no lock left, every movie there";
  int cut = 0, kept = 0;
  for (const nlohmann::json& w : work) {
    char name[16];
    std::snprintf(name, sizeof name, "%06u.exr", w["movie"].get<unsigned>());
    ASSERT_TRUE(merged.count(name)) << name;
    const bool costly = w["seconds"].get<double>() > target && w["movie_keys"].get<int>() > 1;
    (costly ? cut : kept) += 1;
    if (costly)  // merged from its pieces: the one-task bake's bytes, provenance included
      EXPECT_TRUE(merged.at(name) == whole.at(name)) << name << ": not the one-task bake";
    else  // baked whole by its shard (whose --shard it records): the same keys
      EXPECT_EQ(readTextureMovie(path(out + "/" + name)).keys,
                readTextureMovie(path("whole/" + std::string(name))).keys)
          << name;
  }
  EXPECT_GE(cut, 1) << "no movie costly enough to cut";
  EXPECT_GE(kept, 1) << "every movie cut: the cut is not by cost";
}

TEST_F(MoviePiecesCli, APieceIsNeverTakenForAMovie) {
  CommandResult r = runCommand(movies("--piece-keys 3", "unmerged"));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  // A piece put where a movie is expected: rad-compose refuses it by name, on one line.
  std::string piece;
  for (const auto& e : fs::directory_iterator(path("unmerged")))
    if (std::regex_match(e.path().filename().string(), kPieceName)) piece = e.path().string();
  ASSERT_FALSE(piece.empty());
  const std::string id = fs::path(piece).filename().string().substr(0, 6);
  fs::create_directories(path("forged"));
  for (const auto& e : fs::directory_iterator(path("whole")))
    fs::copy_file(e.path(), path("forged") / e.path().filename());
  fs::copy_file(piece, path("forged/" + id + ".exr"), fs::copy_options::overwrite_existing);
  const std::string d = dir_->string();
  CommandResult c = runCommand(tool("rad-compose") + " " + kScene + " " + d + "/global.rlh " + d +
                               "/intervals.rti " + d + "/forged -o " + d + "/frames --frames 0-1");
  EXPECT_EQ(c.exitCode, 1) << c.err;
  EXPECT_NE(c.err.find("a piece of texture movie"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("--merge-pieces"), std::string::npos) << c.err;
}

TEST_F(MoviePiecesCli, MergeRefusesForeignAndMissingPieces) {
  // Pieces baked with another parameter: the merge names it and writes nothing.
  CommandResult r = runCommand(movies("--piece-keys 3 --min-samples 8", "foreign"));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  CommandResult m = runCommand(movies("--merge-pieces 3", "foreign"));
  EXPECT_EQ(m.exitCode, 1) << m.err;
  EXPECT_EQ(countLines(m.err), 1) << m.err;
  EXPECT_NE(m.err.find("--min-samples 8"), std::string::npos) << m.err;
  // A missing piece: named, and its movie not written.
  r = runCommand(movies("--piece-keys 3", "missing"));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::string piece;
  for (const auto& e : fs::directory_iterator(path("missing")))
    if (std::regex_match(e.path().filename().string(), kPieceName)) piece = e.path().string();
  ASSERT_FALSE(piece.empty());
  fs::remove(piece);
  m = runCommand(movies("--merge-pieces 3", "missing"));
  EXPECT_EQ(m.exitCode, 1) << m.err;
  EXPECT_NE(m.err.find(fs::path(piece).filename().string()), std::string::npos) << m.err;
  const std::string id = fs::path(piece).filename().string().substr(0, 6);
  EXPECT_FALSE(fs::exists(path("missing/" + id + ".exr"))) << "a movie made without its piece";
}

}  // namespace
}  // namespace rad::test
