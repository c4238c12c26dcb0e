// rad-compose's frame loop (docs/design.md §6.4 "rad-compose"): for each frame, the texture movies
// active at it are read lazily from MOVIES_DIR (movies/MMMMMM.exr) and dropped after their last
// frame, so memory stays flat in the animation's length; each frame is composed
// (libcommon/compose/frame_composer.h) and written as FRAMES_DIR/NNNN.exr (+ .png), atomically.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/provenance.h"
#include "formats/texture_intervals.h"
#include "libcommon/compose/frame_composer.h"
#include "libcommon/radiosity/global_solution.h"
#include "libcommon/scene/scene.h"
#include "tools/stages/used_movies.h"

namespace rad {

struct ComposeSequenceOptions {
  std::string moviesDir;
  std::string framesDir;    // created if missing
  std::vector<int> frames;  // composed in increasing order (sorted, duplicates dropped)
  double fps = 24.0;        // frame f is at time f / fps
  ImageSize size{352, 240};
  int cameraNode = -1;        // Scene::cameraNode()
  bool autoExposure = false;  // one EV for the whole sequence (autoExposureEV)
  double exposureEV = 0.0;    // used when !autoExposure
  bool half = false;          // HALF EXR channels
  int compression = 0;        // frameCompressionOf(); 0: none
  bool png = true;            // also write NNNN.png
  // The pixel filter and sample grid (libcommon/compose/footprint_filter.h); everySample: no
  // shortcut on uniform footprints; edgeCoverage: the cells an edge crosses weighed by the area
  // each side covers (edge_cells.h).
  PixelSampling sampling = PixelSampling::pixelCentres();
  bool everySample = false;
  bool edgeCoverage = true;
  double edgeContrast = 0.0;  // EdgeCellInputs::minContrast
};

struct ComposeFrameStats {
  int frame = 0;
  double time = 0.0;
  double seconds = 0.0;  // wall time to compose and write this frame
  int movies = 0;        // movies active at the frame
  long long coveredPixels = 0, moviePixels = 0, fallbackPixels = 0;
};

struct ComposeSequenceReport {
  double exposureEV = 0.0;
  double seconds = 0.0;
  long long moviesRead = 0;  // movie files read (each at most once)
  int peakLoadedMovies = 0;  // most movies held in memory at once
  std::vector<ComposeFrameStats> frames;
  nlohmann::json toJson() const;
};

// Composes and writes every frame; `movies` are readUsedMovies(intervals, options.moviesDir,
// options.frames), whose headers the streams open with. `warn` gets one message per frame with
// fallback pixels
// ("frame 12: 37 pixels fell back to the global solution"); `progress` is called after each
// frame. Throws rad::inputError for a missing or inconsistent movie file (patch, frames or
// size differing from `intervals`), rad::outputError when FRAMES_DIR or a frame cannot be
// written, rad::Error(kUsage) for frames outside the intervals' window.
ComposeSequenceReport composeSequence(const Scene& scene, const GlobalSolution& solution,
                                      const TextureIntervals& intervals,
                                      const ComposeSequenceOptions& options,
                                      const Provenance& provenance, UsedMovies movies,
                                      const std::function<void(const std::string&)>& warn,
                                      const std::function<void()>& progress = {});

}  // namespace rad
