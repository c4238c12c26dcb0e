// rad-compose's frame loop with lazily loaded, evicted texture movies (paper §5: the movie
// files are the disk cache; only the movies of the current frame, and of each only the key
// textures around the current time, are in memory).
#include "tools/stages/frame_sequence.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <memory>

#include "formats/frame_image.h"
#include "formats/texture_movie.h"
#include "libcommon/core/error.h"

namespace rad {
namespace {

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
    // The headers readUsedMovies read, not every part's header parsed again with OpenEXR's C++
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
                                      const Provenance& provenance, UsedMovies movies,
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
                         options.everySample, options.edgeCoverage, options.edgeContrast);
  MovieCache cache(intervals, options.moviesDir, std::move(movies.headers));
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
