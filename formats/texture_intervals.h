// intervals.rti: the texture-movie extents rad-intervals writes (container kind "intervals").
// Arrays and metadata: formats/texture_intervals.md. Paper §4.1, §4.3.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/container.h"
#include "libcommon/intervals/movie_extent.h"
#include "libcommon/scene/sample_grid.h"

namespace rad {

constexpr const char* kTextureIntervalsKind = "intervals";
constexpr int kTextureIntervalsMajor = 1;
constexpr int kTextureIntervalsMinor = 2;

// intervals.rti stores libcommon's movie record (libcommon/intervals/movie_extent.h: patch,
// frames, size, MovieEnd) as it is.

struct TextureIntervals {
  int firstFrame = 0, lastFrame = 0;  // the window computed
  double fps = 24.0;
  int imageWidth = 0, imageHeight = 0;
  // The samples whose coverage the item buffers decided (1.1; a 1.0 file: the pixel centres).
  PixelSampling sampling = PixelSampling::pixelCentres();
  std::vector<MovieExtent> movies;  // sorted by id (movies[i].movie == i)
  double frameTime(int frame) const { return frame / fps; }
};

void writeTextureIntervals(const std::string& path, const TextureIntervals& intervals,
                           const Provenance& provenance, const nlohmann::json& metadata);
// Validates: frames inside the window, first <= last, sizes >= 1, ids 0..n-1 in order, known
// close reasons (MovieEnd). Errors are rad::inputError(path, ...).
TextureIntervals readTextureIntervals(const ContainerReader& reader);
TextureIntervals readTextureIntervals(const std::string& path);

// rad-inspect's summary: movies, mean length, texels per frame, levels, close reasons.
nlohmann::json summarizeTextureIntervals(const ContainerReader& reader);

}  // namespace rad
