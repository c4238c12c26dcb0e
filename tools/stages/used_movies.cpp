// The texture movies a rad-compose run's frames use, read once for their headers.
#include "tools/stages/used_movies.h"

#include <algorithm>
#include <exception>

#include <tbb/parallel_for.h>

#include "formats/checksum.h"
#include "libcommon/core/error.h"

namespace rad {
namespace {

// f(i) for every i < n in parallel (the movie files, one each); when calls throw, the lowest
// i's exception is rethrown once all have run: the same error whatever the threads.
template <class F>
void forEachInParallel(size_t n, F f) {
  std::vector<std::exception_ptr> failed(n);
  tbb::parallel_for(size_t(0), n, [&](size_t i) {
    try {
      f(i);
    } catch (...) {
      failed[i] = std::current_exception();
    }
  });
  for (const std::exception_ptr& e : failed)
    if (e) std::rethrow_exception(e);
}

// True if one of the sorted `frames` lies in the movie's interval.
bool usedByFrames(const MovieExtent& iv, const std::vector<int>& frames) {
  const auto f = std::lower_bound(frames.begin(), frames.end(), iv.firstFrame);
  return f != frames.end() && *f <= iv.lastFrame;
}

}  // namespace

void requireMovieMatches(const TextureMovie& movie, const MovieExtent& iv,
                         const std::string& path) {
  auto differs = [&](const std::string& what, const std::string& got, const std::string& expected) {
    throw inputError(path, what + " " + got + " differs from the intervals' " + expected +
                               " (movie " + std::to_string(iv.movie) + ")");
  };
  if (movie.patch != iv.patch) differs("patch", movie.patch.toString(), iv.patch.toString());
  if (movie.firstFrame != iv.firstFrame || movie.lastFrame != iv.lastFrame)
    differs("frames", std::to_string(movie.firstFrame) + "-" + std::to_string(movie.lastFrame),
            std::to_string(iv.firstFrame) + "-" + std::to_string(iv.lastFrame));
  if (movie.width != iv.width || movie.height != iv.height)
    differs("texture size", std::to_string(movie.width) + "x" + std::to_string(movie.height),
            std::to_string(iv.width) + "x" + std::to_string(iv.height));
}

UsedMovies readUsedMovies(const TextureIntervals& intervals, const std::string& dir,
                          const std::vector<int>& frames) {
  std::vector<int> sorted = frames;
  std::sort(sorted.begin(), sorted.end());
  std::vector<size_t> used;
  for (size_t i = 0; i < intervals.movies.size(); ++i)
    if (usedByFrames(intervals.movies[i], sorted)) used.push_back(i);
  std::vector<TextureMovie> read(used.size());
  std::string firstProvenance;
  forEachInParallel(used.size(), [&](size_t u) {
    const MovieExtent& iv = intervals.movies[used[u]];
    const std::string path = textureMoviePath(dir, iv.movie);
    read[u] = readTextureMovieHeaders(path);
    requireMovieMatches(read[u], iv, path);
    // The baking tool's provenance is dropped (a from-scratch run has tens of thousands of
    // one-frame movies), the first movie's kept for the frames' history.
    if (u == 0) firstProvenance.swap(read[u].provenanceJson);
    std::string().swap(read[u].provenanceJson);
  });
  UsedMovies out;
  for (size_t u = 0; u < used.size(); ++u) out.headers.emplace(used[u], std::move(read[u]));
  if (!firstProvenance.empty()) {
    out.firstProvenance = nlohmann::json::parse(firstProvenance, nullptr, false);
    if (out.firstProvenance.is_discarded()) out.firstProvenance = nullptr;
  }
  return out;
}

void addMoviesInput(Provenance& provenance, const std::string& moviesDir, const UsedMovies& used) {
  uint64_t h = kFnv1a64Offset;
  for (const auto& [index, movie] : used.headers) {
    const std::string movieHash = formatFnv1a64(movie.headerHash);
    h = fnv1a64(movieHash.data(), movieHash.size(), h);
  }
  InputRecord record;
  record.path = moviesDir;
  record.hash = formatFnv1a64(h);
  record.history = used.firstProvenance;
  provenance.inputs.push_back(std::move(record));
}

}  // namespace rad
