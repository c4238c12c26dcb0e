// rad-movies' shard loop and movie-file sink. Sources in movie_sequence.h.
#include "formats/movie_sequence.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>

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
  MovieSequenceReport report;
  MovieFileSink sink(baker.options().coherence, report.secondsWrite);
  for (const MovieExtent* m : shardMovies(intervals, options.shard)) {
    const auto movieStart = SteadyClock::now();
    sink.start(textureMovieOf(*m, provenanceJson), textureMoviePath(options.moviesDir, m->movie));
    try {
      baker.bake(*m, sink);
    } catch (const Error& e) {
      sink.discard();
      // Name the file the bad movie came from.
      if (e.code() == ExitCode::kBadInput) throw inputError(options.intervalsPath, e.what());
      throw;
    }
    ++report.moviesBaked;
    report.movieSeconds.emplace_back(m->movie, secondsSince(movieStart));
    if (progress) progress();
  }
  // One sync for all movies (AtomicFile::Durability::kDeferred) before the tool reports
  // success: Make's movies/.done stamp follows our exit status.
  auto t = SteadyClock::now();
  syncFileSystemOf(options.moviesDir);
  report.secondsWrite += secondsSince(t);
  return report;
}

}  // namespace rad
