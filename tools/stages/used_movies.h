// The texture movies a rad-compose run's frames use (paper §5: the movie files are the disk cache
// of the frames): their headers read and checked once before the first frame, and the frames'
// provenance input for MOVIES_DIR taken from those headers (formats/frame_image.md "Inputs in the
// provenance"), so that a compose task reads no movie's pixels beyond the keys its frames show.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/provenance.h"
#include "formats/texture_intervals.h"
#include "formats/texture_movie.h"

namespace rad {

struct UsedMovies {
  // By interval index: every part's header (keys empty, provenanceJson dropped), headerHash set.
  std::map<size_t, TextureMovie> headers;
  // The provenance of the first of them (rad-movies'), parsed; null if it has none or none is used.
  nlohmann::json firstProvenance;
};

// Throws rad::inputError(path, ...) unless the movie is the one the intervals describe (patch,
// frames, texture size).
void requireMovieMatches(const TextureMovie& movie, const MovieExtent& iv, const std::string& path);

// Every movie in `dir` whose interval holds one of `frames` (sorted): its headers read and checked
// (rad.format, parts, checksums present, patch, frames, size), so that a bad or missing movie stops
// the run before its first frame is written. The files are read in parallel; of several bad ones
// the first in interval order is reported, whatever the threads.
UsedMovies readUsedMovies(const TextureIntervals& intervals, const std::string& dir,
                          const std::vector<int>& frames);

// Records MOVIES_DIR as one provenance input: its hash is FNV-1a 64 over the header hashes
// ("fnv1a64:<16 hex>" of each movie's ExrHeaderScan::headerHash, in interval order) of the used
// movies (the offset basis when none is used); its history the first one's provenance. Each header
// holds its parts' rad.pixelChecksum, which the stream verifies for every key it loads, so the hash
// names the movies' content without reading their pixels (formats/frame_image.md, since frame 2.2).
void addMoviesInput(Provenance& provenance, const std::string& moviesDir, const UsedMovies& used);

}  // namespace rad
