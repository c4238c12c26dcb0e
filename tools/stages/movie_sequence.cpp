// rad-movies' shard loop and movie-file sink. Sources in movie_sequence.h.
#include "tools/stages/movie_sequence.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <mutex>
#include <thread>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "formats/atomic_file.h"
#include "formats/texture_movie.h"
#include "libcommon/core/error.h"
#include "libcommon/core/stopwatch.h"
#include "tools/stages/movie_pieces.h"

namespace rad {
namespace {

// Streams each baked key into the movie's file (constant movies collapse to one key when
// coherence is on, as the baker's in-memory bake does).
class MovieFileSink : public BakedKeySink {
 public:
  MovieFileSink(bool collapse, double& secondsWrite)
      : collapse_(collapse), secondsWrite_(secondsWrite) {}

  // The movie the next bake() streams: its metadata (keys come from the baker) and file in `dir`;
  // for a piece, its place in the movie (meta.piece), whose keys alone the file holds.
  void start(const MovieWork& work, const std::string& provenanceJson, const std::string& dir) {
    const MovieExtent& m = *work.movie;
    meta_ = textureMovieOf(m, provenanceJson);
    meta_.piece = work.piece;
    path_ = work.piece.isPiece() ? textureMoviePiecePath(dir, m.movie, work.piece.index)
                                 : textureMoviePath(dir, m.movie);
  }
  // Drops a half-written movie (nothing is left at its path).
  void discard() { writer_.reset(); }

  void begin(const BakedMovie& plan) override {
    auto t = SteadyClock::now();
    first_ = meta_.piece.isPiece() ? size_t(meta_.piece.firstKey) : 0;
    const size_t keys = meta_.piece.isPiece() ? size_t(meta_.piece.keys) : plan.keyFrames.size();
    meta_.keyFrames.assign(plan.keyFrames.begin() + long(first_),
                           plan.keyFrames.begin() + long(first_ + keys));
    meta_.keyTimes.assign(plan.keyTimes.begin() + long(first_),
                          plan.keyTimes.begin() + long(first_ + keys));
    writer_ = std::make_unique<TextureMovieWriter>(path_, meta_, collapse_,
                                                   AtomicFile::Durability::kDeferred);
    secondsWrite_ += secondsSince(t);
  }
  void key(size_t k, const std::vector<float>& texture) override {
    auto t = SteadyClock::now();
    writer_->writeKey(k - first_, texture);
    secondsWrite_ += secondsSince(t);
  }
  size_t finish() override {
    auto t = SteadyClock::now();
    size_t stored = writer_->commit();
    writer_.reset();
    secondsWrite_ += secondsSince(t);
    return stored;
  }

 private:
  bool collapse_;
  double& secondsWrite_;
  TextureMovie meta_;
  size_t first_ = 0;  // the movie's index of the file's first key
  std::string path_;
  std::unique_ptr<TextureMovieWriter> writer_;
};

// What a unit of work cost, for the report.
MovieWorkSeconds workSeconds(const MovieWork& work, const BakedMovie& baked, double seconds) {
  const TextureMoviePiece& piece = work.piece;
  const int movieKeys = int(baked.keyFrames.size());
  return {work.movie->movie,
          piece.isPiece() ? piece.index : -1,
          piece.isPiece() ? piece.keys : movieKeys,
          movieKeys,
          long(work.movie->width) * long(work.movie->height),
          seconds,
          baked.secondsPlan};
}

}  // namespace

MovieShard MovieShard::parse(const std::string& s) {
  int i = -1, n = -1;
  char slash = 0, extra = 0;
  if (std::sscanf(s.c_str(), "%d%c%d%c", &i, &slash, &n, &extra) != 3 || slash != '/' || n < 1 ||
      i < 0 || i >= n)
    throw Error(ExitCode::kUsage, "--shard", "'" + s + "'; expected i/n with 0 <= i < n, e.g. 0/4");
  return {i, n};
}

std::vector<MovieWork> shardWork(const TextureIntervals& intervals, MovieShard shard,
                                 const MovieCut& cut, const TextureMovieBaker& baker) {
  std::vector<MovieWork> all;  // every movie's units, in id and piece order
  std::vector<double> estimates;
  for (const MovieExtent& m : intervals.movies) {
    if (!cut.cuts()) {
      if (shard.contains(m.movie)) all.push_back({&m, TextureMoviePiece{}});
      continue;
    }
    const int keys = int(baker.keyPlan(m).keyFrames.size());
    const std::vector<TextureMoviePiece> pieces =
        moviePiecesByCount(keys, cut.pieceCount(m.movie, keys));
    for (const TextureMoviePiece& p : pieces) {
      all.push_back({&m, pieces.size() > 1 ? p : TextureMoviePiece{}});
      estimates.push_back(cut.estimate(m.movie, keys, p.index, p.count));
    }
  }
  if (!cut.cuts()) return all;
  const std::vector<int> shardOf =
      cut.byCost() ? dealByCost(estimates, shard.count) : std::vector<int>();
  std::vector<MovieWork> mine;
  for (size_t u = 0; u < all.size(); ++u)
    if (cut.byCost() ? shardOf[u] == shard.index : shard.contains(uint32_t(u)))
      mine.push_back(all[u]);
  return mine;
}

MovieSequenceReport bakeMovieSequence(TextureMovieBaker& baker,
                                      const std::vector<MovieWork>& movies,
                                      const MovieSequenceOptions& options,
                                      const Provenance& provenance,
                                      const std::function<void()>& progress) {
  std::error_code ec;
  std::filesystem::create_directories(options.moviesDir, ec);
  if (ec || !std::filesystem::is_directory(options.moviesDir))
    throw outputError(options.moviesDir, "cannot create the movie directory" +
                                             (ec ? ": " + ec.message() : std::string()));
  const std::string provenanceJson = provenance.toJson().dump();
  // One worker per allowed thread (--threads), each baking whole movies with its own baker: a big
  // scene's movies are mostly a few texels, too small for the per-texel loops inside a movie to
  // keep two cores busy. `baker` is worker 0 on this thread; the others are its siblings, made,
  // used and destroyed on their own threads (each holds a GL context). A movie is made whole by one
  // baker, so the files do not depend on the number of workers.
  const size_t workers = std::clamp<size_t>(
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism), 1,
      std::max<size_t>(movies.size(), 1));
  struct Worker {
    double secondsWrite = 0.0;
    TextureMovieBakerStats stats;  // a sibling's, handed over when its thread ends
    std::string rendererName;
  };
  std::vector<Worker> done(workers);
  std::vector<MovieWorkSeconds> movieSeconds(movies.size());
  std::atomic<size_t> next{0};
  std::atomic<bool> stop{false};
  std::mutex mutex;  // progress and the first failure
  size_t failedAt = movies.size();
  std::exception_ptr failure;

  auto work = [&](TextureMovieBaker& mine, Worker& w) {
    MovieFileSink sink(mine.options().coherence, w.secondsWrite);
    // While every worker has a movie of its own, a movie's per-texel loops run on its worker alone
    // (an arena of one thread): in the shared arena every loop of a few texels would go through
    // TBB's partitioning and stealing. The last movies, fewer than the workers, take every thread
    // again.
    tbb::task_arena alone(1);
    for (size_t i; !stop && (i = next++) < movies.size();) {
      const MovieExtent& m = *movies[i].movie;
      const auto movieStart = SteadyClock::now();
      BakedMovie baked;
      try {
        sink.start(movies[i], provenanceJson, options.moviesDir);
        if (workers > 1 && i + workers < movies.size())
          alone.execute([&] { baked = mine.bake(m, sink, movies[i].keys()); });
        else
          baked = mine.bake(m, sink, movies[i].keys());
      } catch (...) {
        sink.discard();
        std::lock_guard<std::mutex> lock(mutex);
        if (i < failedAt) failedAt = i, failure = std::current_exception();  // the lowest id's
        stop = true;
        return;
      }
      movieSeconds[i] = workSeconds(movies[i], baked, secondsSince(movieStart));
      if (progress) {
        std::lock_guard<std::mutex> lock(mutex);
        progress();
      }
    }
  };
  std::vector<std::thread> threads;
  for (size_t k = 1; k < workers && !stop; ++k) try {
      threads.emplace_back([&, k] {
        Worker& w = done[k];
        try {
          std::unique_ptr<TextureMovieBaker> sibling = baker.sibling();
          work(*sibling, w);
          w.stats = sibling->stats();
          w.rendererName = sibling->rendererName();
        } catch (...) {  // the sibling's construction or teardown, or a failed progress report
          std::lock_guard<std::mutex> lock(mutex);
          if (!failure) failure = std::current_exception();
          stop = true;
        }
      });
    } catch (...) {
      // A thread that did not start (std::system_error): the started ones stop and are joined
      // below (a joinable std::thread destroyed unjoined aborts), and the error is reported.
      std::lock_guard<std::mutex> lock(mutex);
      if (!failure) failure = std::current_exception();
      stop = true;
    }
  try {
    work(baker, done[0]);
  } catch (...) {  // a failed progress report: the other workers still have to be joined
    std::lock_guard<std::mutex> lock(mutex);
    if (!failure) failure = std::current_exception();
    stop = true;
  }
  for (std::thread& t : threads) t.join();
  done[0].rendererName = baker.rendererName();
  for (size_t k = 1; k < workers; ++k) baker.addStats(done[k].stats);

  MovieSequenceReport report;
  for (const Worker& w : done)
    if (report.rendererName.empty()) report.rendererName = w.rendererName;
  for (const Worker& w : done) report.secondsWrite += w.secondsWrite;
  if (failure) {
    try {
      std::rethrow_exception(failure);
    } catch (const Error& e) {
      // Name the file the bad movie came from.
      if (e.code() == ExitCode::kBadInput) throw inputError(options.intervalsPath, e.what());
      throw;
    }
  }
  for (size_t i = 0; i < movies.size(); ++i) {
    ++(movies[i].piece.isPiece() ? report.piecesBaked : report.moviesBaked);
    report.workSeconds.push_back(movieSeconds[i]);
  }
  // One sync for all movies (AtomicFile::Durability::kDeferred) before the tool reports
  // success: Make's movies/.done stamp follows our exit status.
  auto t = SteadyClock::now();
  syncFileSystemOf(options.moviesDir);
  report.secondsWrite += secondsSince(t);
  return report;
}

}  // namespace rad
