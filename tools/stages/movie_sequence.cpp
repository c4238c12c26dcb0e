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

namespace rad {
namespace {

// Streams each baked key into the movie's file (constant movies collapse to one key when
// coherence is on, as the baker's in-memory bake does).
class MovieFileSink : public BakedKeySink {
 public:
  MovieFileSink(bool collapse, double& secondsWrite)
      : collapse_(collapse), secondsWrite_(secondsWrite) {}

  // The movie the next bake() streams: its metadata (keys come from the baker) and file.
  void start(TextureMovie meta, std::string path) {
    meta_ = std::move(meta);
    path_ = std::move(path);
  }
  // Drops a half-written movie (nothing is left at its path).
  void discard() { writer_.reset(); }

  void begin(const BakedMovie& plan) override {
    auto t = SteadyClock::now();
    meta_.keyFrames = plan.keyFrames;
    meta_.keyTimes = plan.keyTimes;
    writer_ = std::make_unique<TextureMovieWriter>(path_, meta_, collapse_,
                                                   AtomicFile::Durability::kDeferred);
    secondsWrite_ += secondsSince(t);
  }
  void key(size_t k, const std::vector<float>& texture) override {
    auto t = SteadyClock::now();
    writer_->writeKey(k, texture);
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
  std::string path_;
  std::unique_ptr<TextureMovieWriter> writer_;
};

}  // namespace

MovieShard MovieShard::parse(const std::string& s) {
  int i = -1, n = -1;
  char slash = 0, extra = 0;
  if (std::sscanf(s.c_str(), "%d%c%d%c", &i, &slash, &n, &extra) != 3 || slash != '/' || n < 1 ||
      i < 0 || i >= n)
    throw Error(ExitCode::kUsage, "--shard", "'" + s + "'; expected i/n with 0 <= i < n, e.g. 0/4");
  return {i, n};
}

std::vector<const MovieExtent*> shardMovies(const TextureIntervals& intervals, MovieShard shard) {
  std::vector<const MovieExtent*> mine;
  for (const MovieExtent& m : intervals.movies)
    if (shard.contains(m.movie)) mine.push_back(&m);
  return mine;
}

MovieSequenceReport bakeMovieSequence(TextureMovieBaker& baker, const TextureIntervals& intervals,
                                      const MovieSequenceOptions& options,
                                      const Provenance& provenance,
                                      const std::function<void()>& progress) {
  std::error_code ec;
  std::filesystem::create_directories(options.moviesDir, ec);
  if (ec || !std::filesystem::is_directory(options.moviesDir))
    throw outputError(options.moviesDir, "cannot create the movie directory" +
                                             (ec ? ": " + ec.message() : std::string()));
  const std::string provenanceJson = provenance.toJson().dump();
  const std::vector<const MovieExtent*> movies = shardMovies(intervals, options.shard);

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
  std::vector<double> movieSeconds(movies.size(), -1.0);
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
      const MovieExtent& m = *movies[i];
      const auto movieStart = SteadyClock::now();
      try {
        sink.start(textureMovieOf(m, provenanceJson), textureMoviePath(options.moviesDir, m.movie));
        if (workers > 1 && i + workers < movies.size())
          alone.execute([&] { mine.bake(m, sink); });
        else
          mine.bake(m, sink);
      } catch (...) {
        sink.discard();
        std::lock_guard<std::mutex> lock(mutex);
        if (i < failedAt) failedAt = i, failure = std::current_exception();  // the lowest id's
        stop = true;
        return;
      }
      movieSeconds[i] = secondsSince(movieStart);
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
    ++report.moviesBaked;
    report.movieSeconds.emplace_back(movies[i]->movie, movieSeconds[i]);
  }
  // One sync for all movies (AtomicFile::Durability::kDeferred) before the tool reports
  // success: Make's movies/.done stamp follows our exit status.
  auto t = SteadyClock::now();
  syncFileSystemOf(options.moviesDir);
  report.secondsWrite += secondsSince(t);
  return report;
}

}  // namespace rad
