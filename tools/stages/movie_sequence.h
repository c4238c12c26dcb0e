// rad-movies' movie loop (docs/design.md §6.3 "rad-movies"; paper §3.1, §5), next to rad-compose's
// (frame_sequence.h): the movies of one shard of intervals.rti are baked by one worker per
// thread, each taking the next movie and baking it whole with its own baker
// (libcommon/movies/texture_movie_baker.h), and each is streamed key by key into
// MOVIES_DIR/MMMMMM.exr (formats/texture_movie.h TextureMovieWriter), committed atomically
// when the movie is done and synced once for all movies at the end. Peak memory is one movie's
// working buffers per worker whatever the animation's length.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "formats/provenance.h"
#include "formats/texture_intervals.h"
#include "libcommon/movies/texture_movie_baker.h"

namespace rad {

// Movies with id % count == index: --shard i/n.
struct MovieShard {
  int index = 0, count = 1;
  // Parses "i/n" with 0 <= i < n; throws a usage Error naming --shard.
  static MovieShard parse(const std::string& spec);
  bool contains(uint32_t movie) const { return int(movie % uint32_t(count)) == index; }
};

struct MovieSequenceOptions {
  std::string intervalsPath;  // named in the error of a bad movie
  std::string moviesDir;      // created if missing
  MovieShard shard;
};

struct MovieSequenceReport {
  long moviesBaked = 0;
  double secondsWrite = 0.0;  // movie files: open, write, commit, and the final sync
  // Per movie baked, in id order: (movie id, seconds to bake and write it). The farm model
  // (pipelines/farm_model.py) re-splits a run's movies into any number of shards from these.
  std::vector<std::pair<uint32_t, double>> movieSeconds;
  std::string rendererName;  // the first worker's that rendered a mask ("" when none did)
};

// The movies of `shard`, in id order.
std::vector<const MovieExtent*> shardMovies(const TextureIntervals& intervals, MovieShard shard);

// Bakes and writes every movie of the shard with as many workers as TBB's allowed parallelism
// (the tools' --threads): `baker` and baker.sibling()s, whose stats are added to `baker`'s at
// the end. `progress` is called after each movie, from one worker at a time. A movie
// whose keys are all equal is stored with one key when the baker's coherence is on. Throws
// rad::inputError(intervalsPath, ...) for a movie the baker refuses as bad input,
// rad::outputError when MOVIES_DIR or a movie cannot be written, and passes the baker's other
// errors on (kEnvironment for the memory budget); a movie that fails leaves no file, the
// workers stop after their current movie, and of the movies that failed, the lowest id's
// error is thrown.
MovieSequenceReport bakeMovieSequence(TextureMovieBaker& baker, const TextureIntervals& intervals,
                                      const MovieSequenceOptions& options,
                                      const Provenance& provenance,
                                      const std::function<void()>& progress = {});

}  // namespace rad
