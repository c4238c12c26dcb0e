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
#include "formats/texture_movie.h"
#include "libcommon/movies/texture_movie_baker.h"
#include "tools/stages/movie_cut.h"

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
};

// One unit of a shard's work: a whole movie, or one piece of one (piece.count == 0: whole).
struct MovieWork {
  const MovieExtent* movie = nullptr;
  TextureMoviePiece piece;
  // The keys to bake: the piece's, or all.
  MovieKeyRange keys() const {
    return piece.isPiece() ? MovieKeyRange{piece.firstKey, piece.keys} : MovieKeyRange{};
  }
};

// What one unit cost: the farm model (pipelines/farm_model.py) re-splits a run's movies into any
// number of shards and pieces from these.
struct MovieWorkSeconds {
  uint32_t movie = 0;
  int piece = -1;            // -1: the whole movie
  int keys = 0;              // keys baked
  int movieKeys = 0;         // keys of the whole movie
  long texels = 0;           // of the movie's texture
  double seconds = 0.0;      // to plan, bake and write it
  double secondsPlan = 0.0;  // of which planning (BakedMovie::secondsPlan)
};

struct MovieSequenceReport {
  long moviesBaked = 0, piecesBaked = 0;
  double secondsWrite = 0.0;  // movie files: open, write, commit, and the final sync
  std::vector<MovieWorkSeconds> workSeconds;  // per unit baked, in work order
  std::string rendererName;  // the first worker's that rendered a mask ("" when none did)
};

// The work of `shard`, in id order (and piece order within a movie). `cut` (render farm,
// docs/design.md §6.3, movie_cut.h): a movie it cuts is baked as pieces of consecutive keys
// (movie_pieces.h), each written as a piece file for --merge-pieces to join. Without a cut, the
// movies with id % n == i. By keys (--piece-keys), every movie's pieces (a movie of one piece is
// its whole movie) are dealt to the shards in id and piece order: the u-th is shard u % n's, so
// a long movie's pieces go to consecutive shards (a piece's cost is not known before it is
// baked: the texels' cost varies by far more than their count). By known cost (--piece-costs:
// an earlier run's reports), only the costly movies are cut and the units are dealt by their
// estimated seconds, longest first (dealByCost). Every task computes the same list from the
// inputs alone (`baker` gives each movie's key count, keyPlan).
std::vector<MovieWork> shardWork(const TextureIntervals& intervals, MovieShard shard,
                                 const MovieCut& cut, const TextureMovieBaker& baker);

// Bakes and writes every movie and piece of `work` (shardWork) with as many workers as TBB's
// allowed parallelism (the tools' --threads): `baker` and baker.sibling()s, whose stats are added
// to `baker`'s at the end. `progress` is called after each movie, from one worker at a time. A
// movie whose keys are all equal is stored with one key when the baker's coherence is on. Throws
// rad::inputError(intervalsPath, ...) for a movie the baker refuses as bad input,
// rad::outputError when MOVIES_DIR or a movie cannot be written, and passes the baker's other
// errors on (kEnvironment for the memory budget); a movie that fails leaves no file, the
// workers stop after their current movie, and of the movies that failed, the lowest id's
// error is thrown.
MovieSequenceReport bakeMovieSequence(TextureMovieBaker& baker, const std::vector<MovieWork>& work,
                                      const MovieSequenceOptions& options,
                                      const Provenance& provenance,
                                      const std::function<void()>& progress = {});

}  // namespace rad
