// rad-compose's frame loop with lazily loaded, evicted texture movies (paper §5: the movie
// files are the disk cache; only the movies of the current frame, and of each only the key
// textures around the current time, are in memory).
#include "tools/stages/frame_sequence.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <filesystem>
#include <map>
#include <memory>

#include <tbb/parallel_for.h>

#include "formats/checksum.h"
#include "formats/exr_info.h"
#include "formats/frame_image.h"
#include "formats/texture_movie.h"
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

// Throws rad::inputError(path, ...) unless the movie is the one the intervals describe.
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

// True if one of the sorted `frames` lies in the movie's interval.
bool usedByFrames(const MovieExtent& iv, const std::vector<int>& frames) {
  const auto f = std::lower_bound(frames.begin(), frames.end(), iv.firstFrame);
  return f != frames.end() && *f <= iv.lastFrame;
}

// Every movie the frames use: its headers read and checked (rad.format, parts, checksums
// present, patch, frames, size) before the first frame is written, so that a bad or missing
// movie leaves no frame behind. The pixels are verified as each key is loaded. Returns the
// headers by interval index, for the streams to open with (MovieCache::get).
// The files are read in parallel (a run has thousands of them); of several bad movies the first in
// interval order is reported.
std::map<size_t, TextureMovie> checkMovieHeaders(const TextureIntervals& intervals,
                                                 const std::string& dir,
                                                 const std::vector<int>& frames) {
  std::vector<size_t> used;
  for (size_t i = 0; i < intervals.movies.size(); ++i)
    if (usedByFrames(intervals.movies[i], frames)) used.push_back(i);
  std::vector<TextureMovie> read(used.size());
  forEachInParallel(used.size(), [&](size_t u) {
    const MovieExtent& iv = intervals.movies[used[u]];
    const std::string path = textureMoviePath(dir, iv.movie);
    read[u] = readTextureMovieHeaders(path);
    requireMovieMatches(read[u], iv, path);
    // Kept until the movie is opened: without the baking tool's provenance, which the frames do not
    // use (a from-scratch run has tens of thousands of one-frame movies).
    std::string().swap(read[u].provenanceJson);
  });
  std::map<size_t, TextureMovie> headers;
  for (size_t u = 0; u < used.size(); ++u) headers.emplace(used[u], std::move(read[u]));
  return headers;
}

// The movies in memory: read on first use, dropped once the frames have passed their last.
class MovieCache {
 public:
  MovieCache(const TextureIntervals& intervals, std::string dir,
             std::map<size_t, TextureMovie> headers)
      : intervals_(intervals), dir_(std::move(dir)), headers_(std::move(headers)) {}

  // Opens (once) and returns the movie of interval `index`.
  TextureMovieStream& get(size_t index) {
    auto it = loaded_.find(index);
    if (it != loaded_.end()) return *it->second;
    const MovieExtent& iv = intervals_.movies[index];
    std::string path = textureMoviePath(dir_, iv.movie);
    // The headers checkMovieHeaders read, not every part's header parsed again with OpenEXR's C++
    // reader. A file changed since is still caught: the stream checks its part count, each chunk's
    // size and each key's checksum.
    auto known = headers_.find(index);
    std::unique_ptr<TextureMovieStream> stream;
    if (known != headers_.end()) {
      stream = std::make_unique<TextureMovieStream>(path, std::move(known->second));
      headers_.erase(known);
    } else {
      stream = std::make_unique<TextureMovieStream>(path);
    }
    requireMovieMatches(stream->movie(), iv, path);
    ++read_;
    TextureMovieStream& ref = *stream;
    loaded_.emplace(index, std::move(stream));
    peak_ = std::max(peak_, int(loaded_.size()));
    return ref;
  }

  // Drops every movie whose last frame is before `frame`.
  void evictBefore(int frame) {
    for (auto it = loaded_.begin(); it != loaded_.end();) {
      if (intervals_.movies[it->first].lastFrame < frame)
        it = loaded_.erase(it);
      else
        ++it;
    }
  }

  long long read() const { return read_; }
  int peak() const { return peak_; }

 private:
  const TextureIntervals& intervals_;
  std::string dir_;
  std::map<size_t, TextureMovie> headers_;  // checked, not opened yet
  std::map<size_t, std::unique_ptr<TextureMovieStream>> loaded_;
  long long read_ = 0;
  int peak_ = 0;
};

}  // namespace

nlohmann::json ComposeSequenceReport::toJson() const {
  nlohmann::json fs = nlohmann::json::array();
  long long fallback = 0;
  for (const ComposeFrameStats& f : frames) {
    fs.push_back({{"frame", f.frame},
                  {"time", f.time},
                  {"seconds", f.seconds},
                  {"movies", f.movies},
                  {"covered_pixels", f.coveredPixels},
                  {"movie_pixels", f.moviePixels},
                  {"fallback_pixels", f.fallbackPixels}});
    fallback += f.fallbackPixels;
  }
  return {{"exposure_ev", exposureEV},
          {"seconds", seconds},
          {"seconds_per_frame", frames.empty() ? 0.0 : seconds / double(frames.size())},
          {"movies_read", moviesRead},
          {"peak_loaded_movies", peakLoadedMovies},
          {"fallback_pixels", fallback},
          {"frames", fs}};
}

ComposeSequenceReport composeSequence(const Scene& scene, const GlobalSolution& solution,
                                      const TextureIntervals& intervals,
                                      const ComposeSequenceOptions& options,
                                      const Provenance& provenance,
                                      const std::function<void(const std::string&)>& warn,
                                      const std::function<void()>& progress) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  std::vector<int> frames = options.frames;
  std::sort(frames.begin(), frames.end());
  frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
  for (int f : frames)
    if (f < intervals.firstFrame || f > intervals.lastFrame)
      throw Error(ExitCode::kUsage, "--frames",
                  "frame " + std::to_string(f) + " is outside the intervals' window " +
                      std::to_string(intervals.firstFrame) + "-" +
                      std::to_string(intervals.lastFrame));
  if (!(options.fps > 0.0)) throw Error(ExitCode::kUsage, "--fps", "must be positive");

  std::map<size_t, TextureMovie> headers = checkMovieHeaders(intervals, options.moviesDir, frames);
  std::error_code ec;
  std::filesystem::create_directories(options.framesDir, ec);
  if (ec || !std::filesystem::is_directory(options.framesDir))
    throw outputError(options.framesDir,
                      "cannot create output directory" + (ec ? ": " + ec.message() : ""));

  ComposeSequenceReport report;
  report.exposureEV = options.autoExposure ? autoExposureEV(scene, solution) : options.exposureEV;
  FrameImageInfo info;
  info.exposureEV = report.exposureEV;
  info.provenanceJson = provenance.toJson().dump();
  // One sync for all frames before returning (Make's frames/.done stamp follows the exit status,
  // and animation.mk removes frames/ before a re-run).
  info.durability = AtomicFile::Durability::kDeferred;

  FrameComposer composer(scene, solution, options.size, options.cameraNode, options.sampling,
                         options.everySample);
  MovieCache cache(intervals, options.moviesDir, std::move(headers));
  ComposedFrame frame;
  std::vector<MovieTexture> active;
  try {
    for (int f : frames) {
      const auto frameStart = Clock::now();
      cache.evictBefore(f);
      const double t = f / options.fps;
      active.clear();
      for (size_t i = 0; i < intervals.movies.size(); ++i) {
        const MovieExtent& iv = intervals.movies[i];
        if (iv.firstFrame > f || iv.lastFrame < f) continue;
        TextureMovieStream& stream = cache.get(i);
        const TextureMovie& movie = stream.movie();
        MovieTexture mt;
        mt.patch = movie.patch;
        mt.width = movie.width;
        mt.height = movie.height;
        // The two key textures around t, blended per sampled texel by the composer (no copy of the
        // texture, which would be one per active movie).
        if (movie.constant())
          mt.irradiance = stream.key(0).data();
        else
          stream.keysAt(t, mt.irradiance, mt.nextIrradiance, mt.weight);
        active.push_back(mt);
      }
      composer.compose(t, active, frame);
      info.frame = f;
      writeFrameExr(framePath(options.framesDir, f, ".exr"), frame, info, options.half,
                    options.compression);
      if (options.png) writeFramePng(framePath(options.framesDir, f, ".png"), frame, info);
      if (frame.fallbackPixels > 0 && warn)
        warn("frame " + std::to_string(f) + ": " + std::to_string(frame.fallbackPixels) +
             " pixels fell back to the global solution");

      ComposeFrameStats s;
      s.frame = f;
      s.time = t;
      s.movies = int(active.size());
      s.coveredPixels = frame.coveredPixels;
      s.moviePixels = frame.moviePixels;
      s.fallbackPixels = frame.fallbackPixels;
      s.seconds = std::chrono::duration<double>(Clock::now() - frameStart).count();
      report.frames.push_back(s);
      if (progress) progress();
    }
  } catch (const Error& e) {
    // A key whose pixels fail their checksum is found only when it is loaded: say which frames
    // this run had written (Make takes none as done: frames/.done follows the exit status).
    if (report.frames.empty()) throw;
    throw Error(e.code(), "",
                std::string(e.what()) + " (after writing " + std::to_string(report.frames.size()) +
                    " of " + std::to_string(frames.size()) + " frames, " +
                    std::to_string(report.frames.front().frame) + "-" +
                    std::to_string(report.frames.back().frame) + ": the sequence is incomplete)");
  }
  syncFileSystemOf(options.framesDir);
  report.moviesRead = cache.read();
  report.peakLoadedMovies = cache.peak();
  report.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return report;
}

}  // namespace rad

namespace rad {

void addMoviesInput(Provenance& provenance, const TextureIntervals& intervals,
                    const std::string& moviesDir, const std::vector<int>& frames) {
  if (frames.empty()) return;
  const auto [lo, hi] = std::minmax_element(frames.begin(), frames.end());
  uint64_t h = kFnv1a64Offset;
  InputRecord record;
  record.path = moviesDir;
  std::vector<std::string> paths;
  for (const MovieExtent& iv : intervals.movies)
    if (!(iv.lastFrame < *lo || iv.firstFrame > *hi))
      paths.push_back(textureMoviePath(moviesDir, iv.movie));
  // Each file hashed in parallel, the hashes folded in interval order (the same hash).
  std::vector<std::string> fileHash(paths.size());
  forEachInParallel(paths.size(), [&](size_t i) { fileHash[i] = hashFile(paths[i]); });
  for (size_t i = 0; i < paths.size(); ++i) {
    const std::string& path = paths[i];
    h = fnv1a64(fileHash[i].data(), fileHash[i].size(), h);
    if (record.history.is_null()) {
      nlohmann::json info = readExrInfo(path);
      const nlohmann::json& attrs = info["parts"][0]["attributes"];
      if (attrs.contains("rad.provenance") && attrs["rad.provenance"].is_string())
        record.history =
            nlohmann::json::parse(attrs["rad.provenance"].get<std::string>(), nullptr, false);
      if (record.history.is_discarded()) record.history = nullptr;
    }
  }
  record.hash = formatFnv1a64(h);
  provenance.inputs.push_back(std::move(record));
}

}  // namespace rad
