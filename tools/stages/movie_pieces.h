// Texture movies in pieces for a render farm (issue 58; docs/design.md §6.3, §7): a movie of
// more than K keys is cut into pieces of at most K consecutive keys, each baked by its own task
// (rad-movies --piece-keys K) into a piece file (formats/texture_movie_piece.md), and a merge
// (rad-movies --merge-pieces K) joins each movie's pieces into the movie file one task bakes,
// byte for byte: either a stage of its own after every piece (mergeMoviePieces), or inside the
// piece tasks, each joining the movies whose last piece it wrote (mergeReadyMoviePieces: one
// stage boundary less on a farm's critical path, docs/design.md §7). Both write the same keys
// (each piece plans the whole movie, so its keys are the whole bake's) with the same
// TextureMovieWriter and the provenance of the command line without --merge-pieces. A piece
// pays the movie's planning, and with it the static shadows that paper §5 renders once a
// movie, again: the planning is per texel and per link (the good layer's per-texel form factors
// and visibility), not per key, so a piece cannot shed it by planning only its own keys
// (docs/results.md, "Farm tasks finer than one movie, merged in the piece tasks").
#pragma once

#include <string>
#include <vector>

#include "formats/provenance.h"
#include "formats/texture_intervals.h"
#include "formats/texture_movie.h"
#include "libcommon/movies/texture_movie_baker.h"
#include "tools/stages/movie_cut.h"
#include "tools/stages/movie_sequence.h"

namespace rad {

// The pieces of a movie of `keys` keys at most `pieceKeys` each: ceil(keys / pieceKeys) pieces
// of as equal a size as the keys allow (piece p holds keys [keys p / P, keys (p + 1) / P)).
// pieceKeys <= 0 or keys <= pieceKeys: one piece (count 1), the whole movie.
std::vector<TextureMoviePiece> moviePieces(int keys, int pieceKeys);
// The same cut into `count` pieces (MovieCut::pieceCount; 1: the whole movie).
std::vector<TextureMoviePiece> moviePiecesByCount(int keys, int count);

// The command line of a --merge-pieces run without `--merge-pieces K`, `--shard i/n`,
// `--piece-costs FILE`, `--piece-seconds T` (or their `=` forms) and `--merge-ready`: the
// provenance the merged movies record, the whole bake's.
std::vector<std::string> argumentsWithoutMergePieces(int argc, const char* const* argv);

struct MoviePieceMergeReport {
  long moviesMerged = 0, piecesRead = 0;
  double seconds = 0.0;
};

// Joins the pieces of every movie of `intervals` of `shard` (id % n == i, so that merges run side
// by side) that `cut` (--piece-keys, --piece-costs) cut into more than one piece: reads
// MOVIES_DIR/MMMMMM.piece-PPPP.exr for every piece (each checked against the movie's key plan from
// `baker` and against `provenance`: made with the same parameters, --shard aside, and from the same
// inputs), writes MOVIES_DIR/MMMMMM.exr (provenance: `provenance`) and removes the pieces. Movies
// of one piece were written whole by their task and are left as they are. Throws
// rad::inputError(piece path, ...) for a missing, damaged or foreign piece (no movie of it is
// written) and rad::outputError when a movie cannot be written.
MoviePieceMergeReport mergeMoviePieces(const TextureMovieBaker& baker,
                                       const TextureIntervals& intervals,
                                       const std::string& moviesDir, const MovieCut& cut,
                                       const Provenance& provenance, MovieShard shard);

// The lock a merge of movie `id` holds (DIR/MMMMMM.merge-lock, tools/stages/file_lock.h).
std::string movieMergeLockPath(const std::string& dir, uint32_t id);

// The merge inside the piece tasks (--merge-pieces K --merge-ready --shard i/n, run by the task
// that baked shard i/n's pieces, after them): of the movies of which shard i/n baked a piece
// (shardWork), joins those whose pieces are all on disk, as mergeMoviePieces does, and leaves
// the others to the task that writes their last piece. A piece is on disk only once it is
// complete (an atomic rename), and each task looks after writing its own, so the task that
// writes a movie's last piece sees them all, and no movie is left unmerged once every task has
// run. Each movie is merged under its lock (movieMergeLockPath), its files checked again under
// it, so two tasks that both see every piece merge it once; a movie found merged has its pieces
// of a task that ran again removed. Throws as mergeMoviePieces for a damaged or foreign piece,
// and rad::outputError when the lock cannot be taken.
MoviePieceMergeReport mergeReadyMoviePieces(const TextureMovieBaker& baker,
                                            const TextureIntervals& intervals,
                                            const std::string& moviesDir, const MovieCut& cut,
                                            const Provenance& provenance, MovieShard shard);

}  // namespace rad
