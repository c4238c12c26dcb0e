// Texture movies in pieces for a render farm (issue 58; docs/design.md §6.3, §7): a movie of
// more than K keys is cut into pieces of at most K consecutive keys, each baked by its own task
// (rad-movies --piece-keys K) into a piece file (formats/texture_movie_piece.md), and one merge
// (rad-movies --merge-pieces K) joins each movie's pieces into the movie file one task bakes,
// byte for byte: the same keys (each piece plans the whole movie, so its keys are the whole
// bake's), written by the same TextureMovieWriter with the provenance of the command line
// without --merge-pieces. A piece pays the movie's planning, and with it the static shadows that
// paper §5 renders once a movie, again.
#pragma once

#include <string>
#include <vector>

#include "formats/provenance.h"
#include "formats/texture_intervals.h"
#include "formats/texture_movie.h"
#include "libcommon/movies/texture_movie_baker.h"
#include "tools/stages/movie_sequence.h"

namespace rad {

// The pieces of a movie of `keys` keys at most `pieceKeys` each: ceil(keys / pieceKeys) pieces
// of as equal a size as the keys allow (piece p holds keys [keys p / P, keys (p + 1) / P)).
// pieceKeys <= 0 or keys <= pieceKeys: one piece (count 1), the whole movie.
std::vector<TextureMoviePiece> moviePieces(int keys, int pieceKeys);

// The command line of a --merge-pieces run without `--merge-pieces K` and `--shard i/n` (or
// their `=` forms): the provenance the merged movies record, the whole bake's.
std::vector<std::string> argumentsWithoutMergePieces(int argc, const char* const* argv);

struct MoviePieceMergeReport {
  long moviesMerged = 0, piecesRead = 0;
  double seconds = 0.0;
};

// Joins the pieces of every movie of `intervals` of `shard` (id % n == i, so that merges run side
// by side) that --piece-keys `pieceKeys` cut into more than one piece: reads
// MOVIES_DIR/MMMMMM.piece-PPPP.exr for every piece (each checked against the movie's key plan from
// `baker` and against `provenance`: made with the same parameters, --shard aside, and from the same
// inputs), writes MOVIES_DIR/MMMMMM.exr (provenance: `provenance`) and removes the pieces. Movies
// of one piece were written whole by their task and are left as they are. Throws
// rad::inputError(piece path, ...) for a missing, damaged or foreign piece (no movie of it is
// written) and rad::outputError when a movie cannot be written.
MoviePieceMergeReport mergeMoviePieces(const TextureMovieBaker& baker,
                                       const TextureIntervals& intervals,
                                       const std::string& moviesDir, int pieceKeys,
                                       const Provenance& provenance, MovieShard shard);

}  // namespace rad
