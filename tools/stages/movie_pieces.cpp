// Texture movies in pieces: the cut and the merge. Contracts in movie_pieces.h.
#include "tools/stages/movie_pieces.h"

#include <cstdio>
#include <filesystem>
#include <memory>

#include "formats/atomic_file.h"
#include "libcommon/core/error.h"
#include "libcommon/core/stopwatch.h"
#include "tools/stages/file_lock.h"

namespace rad {

std::vector<TextureMoviePiece> moviePieces(int keys, int pieceKeys) {
  return moviePiecesByCount(keys, MovieCut(pieceKeys).pieceCount(0, keys));
}

std::vector<TextureMoviePiece> moviePiecesByCount(int keys, int count) {
  std::vector<TextureMoviePiece> pieces;
  for (int p = 0; p < count; ++p) {
    TextureMoviePiece piece;
    piece.index = p;
    piece.count = count;
    piece.firstKey = int(int64_t(keys) * p / count);
    piece.keys = int(int64_t(keys) * (p + 1) / count) - piece.firstKey;
    piece.movieKeys = keys;
    pieces.push_back(piece);
  }
  return pieces;
}

std::vector<std::string> argumentsWithoutMergePieces(int argc, const char* const* argv) {
  std::vector<std::string> words;
  for (int i = 0; i < argc; ++i) {
    const std::string w = argv[i];
    if (w == "--merge-pieces" || w == "--shard" || w == "--piece-costs" || w == "--piece-seconds") {
      ++i;  // and its value
      continue;
    }
    if (w == "--merge-ready") continue;
    if (w.rfind("--merge-pieces=", 0) == 0 || w.rfind("--shard=", 0) == 0 ||
        w.rfind("--piece-costs=", 0) == 0 || w.rfind("--piece-seconds=", 0) == 0)
      continue;
    words.push_back(w);
  }
  return words;
}

namespace {

// A piece must come from this run's command line (--shard aside) and inputs: a piece of another
// run would make a movie no single bake makes.
void requireSameRun(const std::string& path, const std::string& pieceProvenance,
                    const Provenance& run) {
  const Provenance built = Provenance::fromJson(parseProvenanceJson(pieceProvenance, path), path);
  std::vector<std::string> keys;
  for (const auto& [name, value] : run.parameters.items())
    if (name != "shard") keys.push_back(name);
  const std::vector<std::string> differ = parameterMismatch(built.parameters, run.parameters, keys);
  if (!differ.empty()) throw inputError(path, "a piece of another run: " + differ.front());
  bool same = built.inputs.size() == run.inputs.size();
  for (size_t i = 0; same && i < run.inputs.size(); ++i)
    same = built.inputs[i].hash == run.inputs[i].hash;
  if (!same) throw inputError(path, "a piece baked from other inputs than this run's");
}

// The piece file's place and keys, against the movie's plan.
void requirePieceOf(const std::string& path, const TextureMovie& piece, const MovieExtent& m,
                    const TextureMoviePiece& want, const BakedMovie& plan) {
  const TextureMoviePiece& got = piece.piece;
  if (piece.movie != m.movie || piece.patch.packed() != m.patch.packed() ||
      piece.firstFrame != m.firstFrame || piece.lastFrame != m.lastFrame ||
      piece.width != m.width || piece.height != m.height)
    throw inputError(path,
                     "not a piece of movie " + std::to_string(m.movie) + " of this intervals file");
  if (got.index != want.index || got.count != want.count || got.firstKey != want.firstKey ||
      got.keys != want.keys || got.movieKeys != want.movieKeys)
    throw inputError(path, "piece " + std::to_string(got.index) + " of " +
                               std::to_string(got.count) + " (keys " +
                               std::to_string(got.firstKey) + "+" + std::to_string(got.keys) +
                               "); this run cuts the movie's " + std::to_string(want.movieKeys) +
                               " keys into " + std::to_string(want.count) + " pieces");
  for (size_t j = 0; j < piece.keyFrames.size(); ++j)
    if (piece.keyFrames[j] != plan.keyFrames[size_t(want.firstKey) + j])
      throw inputError(path, "key " + std::to_string(j) + " at frame " +
                                 std::to_string(piece.keyFrames[j]) + "; the movie's is at " +
                                 std::to_string(plan.keyFrames[size_t(want.firstKey) + j]));
}

// Joins the pieces of movie `m` (every one on disk) into its movie file, each piece checked
// before the movie is written, then removes them.
void mergeMovie(const TextureMovieBaker& baker, const MovieExtent& m, const BakedMovie& plan,
                const std::vector<TextureMoviePiece>& pieces, const std::string& moviesDir,
                const Provenance& provenance, const std::string& provenanceJson) {
  std::vector<std::unique_ptr<TextureMovieStream>> streams;
  for (const TextureMoviePiece& want : pieces) {
    const std::string path = textureMoviePiecePath(moviesDir, m.movie, want.index);
    streams.push_back(std::make_unique<TextureMovieStream>(path, MovieFileKind::kPiece));
    requirePieceOf(path, streams.back()->movie(), m, want, plan);
    requireSameRun(path, streams.back()->movie().provenanceJson, provenance);
  }
  TextureMovie meta = textureMovieOf(m, provenanceJson);
  meta.keyFrames = plan.keyFrames;
  meta.keyTimes = plan.keyTimes;
  TextureMovieWriter writer(textureMoviePath(moviesDir, m.movie), meta, baker.options().coherence,
                            AtomicFile::Durability::kDeferred);
  for (size_t p = 0; p < pieces.size(); ++p) {
    TextureMovieStream& piece = *streams[p];
    const bool constant = piece.movie().keyFrames.size() == 1;  // all its keys equal
    for (int j = 0; j < pieces[p].keys; ++j) {
      const std::vector<float>& key = piece.key(constant ? 0 : size_t(j));
      writer.writeKey(size_t(pieces[p].firstKey + j), key);
    }
    streams[p].reset();  // a piece's keys are held until the piece is written
  }
  writer.commit();
  for (const TextureMoviePiece& piece : pieces)
    std::filesystem::remove(textureMoviePiecePath(moviesDir, m.movie, piece.index));
}

}  // namespace

MoviePieceMergeReport mergeMoviePieces(const TextureMovieBaker& baker,
                                       const TextureIntervals& intervals,
                                       const std::string& moviesDir, const MovieCut& cut,
                                       const Provenance& provenance, MovieShard shard) {
  const auto start = SteadyClock::now();
  const std::string provenanceJson = provenance.toJson().dump();
  MoviePieceMergeReport report;
  // The movies cut into pieces, and whether each is still to merge: a merge that stopped half way
  // (killed, or a piece missing) has removed the pieces of the movies it wrote, and its re-run
  // takes those movies as written.
  struct Split {
    const MovieExtent* movie;
    BakedMovie plan;
    std::vector<TextureMoviePiece> pieces;
  };
  std::vector<Split> todo;
  for (const MovieExtent& m : intervals.movies) {
    if (!shard.contains(m.movie)) continue;
    BakedMovie plan = baker.keyPlan(m);
    const int keys = int(plan.keyFrames.size());
    std::vector<TextureMoviePiece> pieces = moviePiecesByCount(keys, cut.pieceCount(m.movie, keys));
    if (pieces.size() < 2) continue;
    bool anyPiece = false;
    std::string missing;
    for (const TextureMoviePiece& piece : pieces) {
      const std::string path = textureMoviePiecePath(moviesDir, m.movie, piece.index);
      if (std::filesystem::exists(path))
        anyPiece = true;
      else if (missing.empty())
        missing = path;
    }
    if (!anyPiece && std::filesystem::exists(textureMoviePath(moviesDir, m.movie))) continue;
    if (!missing.empty())
      throw inputError(missing, "missing: a piece of movie " + std::to_string(m.movie) +
                                    " was not baked (rad-movies --piece-keys or --piece-costs"
                                    " with --shard ...)");
    todo.push_back({&m, std::move(plan), std::move(pieces)});
  }
  for (const Split& split : todo) {
    mergeMovie(baker, *split.movie, split.plan, split.pieces, moviesDir, provenance,
               provenanceJson);
    ++report.moviesMerged;
    report.piecesRead += long(split.pieces.size());
  }
  syncFileSystemOf(moviesDir);
  report.seconds = secondsSince(start);
  return report;
}

std::string movieMergeLockPath(const std::string& dir, uint32_t id) {
  char name[32];
  std::snprintf(name, sizeof name, "%06u.merge-lock", id);
  return (std::filesystem::path(dir) / name).string();
}

MoviePieceMergeReport mergeReadyMoviePieces(const TextureMovieBaker& baker,
                                            const TextureIntervals& intervals,
                                            const std::string& moviesDir, const MovieCut& cut,
                                            const Provenance& provenance, MovieShard shard) {
  const auto start = SteadyClock::now();
  const std::string provenanceJson = provenance.toJson().dump();
  MoviePieceMergeReport report;
  const MovieExtent* previous = nullptr;
  for (const MovieWork& work : shardWork(intervals, shard, cut, baker)) {
    if (!work.piece.isPiece() || work.movie == previous) continue;
    previous = work.movie;
    const MovieExtent& m = *work.movie;
    const std::vector<TextureMoviePiece> pieces =
        moviePiecesByCount(work.piece.movieKeys, work.piece.count);
    const std::string moviePath = textureMoviePath(moviesDir, m.movie);
    auto piecesOnDisk = [&] {
      size_t n = 0;
      for (const TextureMoviePiece& p : pieces)
        n += std::filesystem::exists(textureMoviePiecePath(moviesDir, m.movie, p.index)) ? 1 : 0;
      return n;
    };
    // Not ready (a piece still to come: the task that writes it merges), or nothing to do.
    size_t have = piecesOnDisk();
    if (have == 0 || (have < pieces.size() && !std::filesystem::exists(moviePath))) continue;
    // Checked again under the lock: another task may have merged it meanwhile.
    FileLock lock(movieMergeLockPath(moviesDir, m.movie));
    have = piecesOnDisk();
    if (std::filesystem::exists(moviePath)) {  // merged; pieces of a task that ran again
      for (const TextureMoviePiece& p : pieces)
        std::filesystem::remove(textureMoviePiecePath(moviesDir, m.movie, p.index));
      continue;
    }
    if (have < pieces.size()) continue;
    mergeMovie(baker, m, baker.keyPlan(m), pieces, moviesDir, provenance, provenanceJson);
    ++report.moviesMerged;
    report.piecesRead += long(pieces.size());
  }
  if (report.moviesMerged > 0) syncFileSystemOf(moviesDir);
  report.seconds = secondsSince(start);
  return report;
}

}  // namespace rad
