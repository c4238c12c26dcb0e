// movies/MMMMMM.exr: one texture movie (paper §3.1, §4.3): the irradiance over one patch node
// at the movie's key times, as a multi-part OpenEXR file, one part per key time (FLOAT R, G, B;
// W/m^2). Readable with exrheader and oiiotool --info -v. Spec: formats/texture_movie.md.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/atomic_file.h"
#include "formats/provenance.h"
#include "libcommon/intervals/movie_extent.h"
#include "libcommon/scene/patch_hierarchy.h"

namespace rad {

constexpr int kTextureMovieMajor = 2;
constexpr int kTextureMovieMinor = 1;
// A piece of a movie (formats/texture_movie_piece.md) has a format of its own, so that no reader
// of whole movies takes one for a whole movie.
constexpr int kTextureMoviePieceMajor = 1;
constexpr int kTextureMoviePieceMinor = 0;

// Which keys of its movie a file holds. A render farm task may bake a long movie's keys as
// pieces of consecutive keys (rad-movies --piece-keys), each its own file, and one merge joins
// them into the whole movie, byte for byte the movie one task bakes (--merge-pieces;
// docs/design.md §6.3). count == 0: the whole movie.
struct TextureMoviePiece {
  int index = 0, count = 0;  // piece `index` of `count`
  int firstKey = 0;          // the movie's index of the piece's first key
  int keys = 0;              // keys the piece covers (its parts: these, or 1 when all are equal)
  int movieKeys = 0;         // keys of the whole movie
  bool isPiece() const { return count > 0; }
};

struct TextureMovie {
  uint32_t movie = 0;  // id in intervals.rti
  PatchId patch;
  int firstFrame = 0, lastFrame = 0;
  int width = 1, height = 1;     // texel (i, j) centre at node (u,v) = ((i+.5)/w, (j+.5)/h);
                                 // row j = 0 is v = 0 (stored as the EXR's first scanline)
  std::vector<int> keyFrames;    // frames of the key textures, increasing, within the movie
  std::vector<double> keyTimes;  // their times, seconds
  // keys[k]: width * height * 3 floats (RGB irradiance), row-major from j = 0. A movie whose
  // texture does not change over its interval has exactly one key ("constant").
  std::vector<std::vector<float>> keys;
  std::string provenanceJson;  // Provenance::toJson().dump() of the tool that baked it
  // Read from the file: each part's rad.pixelChecksum (formats/pixel_checksum.h), which the
  // readers verify against the pixels they decode. Writers compute their own.
  std::vector<uint64_t> keyChecksums;
  // Set by readTextureMovieHeaders (else 0): ExrHeaderScan::headerHash of the file, every part's
  // header, so with keyChecksums its whole content, without reading the pixels.
  uint64_t headerHash = 0;
  // Set by the readers from their header scan: where the chunk tables start (the headers' end)
  // when every part is an uncompressed scan-line image of one chunk a line, the layout
  // rad-movies writes, so that TextureMovieStream reads a key without OpenEXR's decoder
  // (uncompressed_exr_part.h); else 0.
  uint64_t uncompressedTablesAt = 0;
  // A piece's place in its movie (keyFrames, keyTimes and keys are then the piece's); a whole
  // movie's count is 0.
  TextureMoviePiece piece;

  bool constant() const { return keys.size() == 1; }
  // Irradiance texture at time t: linear between the two key textures around t (held before
  // the first and after the last). out gets width * height * 3 floats.
  void textureAt(double t, std::vector<float>& out) const;
  // The keys textureAt(t) reads: k0 == k1 when t is at or outside the ends (or one key).
  void keysAround(double t, size_t& k0, size_t& k1) const;
  // textureAt's weight of key k1 at t (k0 < k1 from keysAround): texel = (1 - w) k0 + w k1.
  float keyWeight(double t, size_t k0, size_t k1) const {
    return float((t - keyTimes[k0]) / (keyTimes[k1] - keyTimes[k0]));
  }
};

// The metadata of the movie baked for one intervals.rti record: its id, patch, frames and size,
// and the baking tool's provenance (keyFrames, keyTimes and keys empty).
TextureMovie textureMovieOf(const MovieExtent& extent, std::string provenanceJson);

// Path of movie `id` in `dir`: dir/000042.exr.
std::string textureMoviePath(const std::string& dir, uint32_t id);
// Path of piece `index` of movie `id` in `dir`: dir/000042.piece-0003.exr.
std::string textureMoviePiecePath(const std::string& dir, uint32_t id, int index);

// Atomic write (temporary + rename). Throws rad::outputError(path, ...). The movie is written
// as given (no constant detection); a thin wrapper over TextureMovieWriter.
void writeTextureMovie(const std::string& path, const TextureMovie& movie);

// Writes a movie key by key as its keys are computed, so that only O(1) keys are in memory
// (rad-movies: peak memory independent of the movie's length). The file is the one
// writeTextureMovie writes, byte for byte. Atomic: the movie appears at `path` on commit()
// only; a writer destroyed without commit() (exception, early return) leaves nothing behind.
//
// storeConstantAsOneKey: while every key written so far is bit-equal to key 0, only key 0 is
// held (nothing is written); the first key that differs writes keys 0..k-1 (copies of key 0)
// and then streams. If all K keys were equal, commit() writes the movie with one key
// (keyFrames[0], keyTimes[0]): a constant movie (texture_movie.md).
class TextureMovieWriter {
 public:
  // `movie`: metadata plus the keyFrames and keyTimes of all K keys (its keys are ignored).
  // Throws rad::Error(kInternal) for inconsistent metadata. `durability`: see AtomicFile
  // (kDeferred: the caller syncs the output's file system once when all movies are written).
  TextureMovieWriter(std::string path, const TextureMovie& movie, bool storeConstantAsOneKey,
                     AtomicFile::Durability durability = AtomicFile::Durability::kEachFile);
  ~TextureMovieWriter();
  TextureMovieWriter(const TextureMovieWriter&) = delete;
  TextureMovieWriter& operator=(const TextureMovieWriter&) = delete;

  // Key k (k = 0, 1, ... in order): width * height * 3 floats. Throws rad::outputError(path,
  // ...) on a write failure and rad::Error(kInternal) for a key out of order or of the wrong size.
  void writeKey(size_t k, const std::vector<float>& rgb);
  // After all K keys: closes, renames onto path. Returns the number of keys stored (1 for a
  // constant movie). Throws rad::outputError(path, ...).
  size_t commit();
  // True while every key written so far equals key 0 (only with storeConstantAsOneKey).
  bool constantSoFar() const { return collapse_ && !diverged_; }

 private:
  void open(size_t parts);
  void writePart(size_t k, const std::vector<float>& rgb);
  void fillInChecksums();
  std::string path_;
  AtomicFile::Durability durability_;
  TextureMovie meta_;  // keys empty
  bool collapse_ = false, diverged_ = false, committed_ = false;
  size_t next_ = 0, texelFloats_ = 0;
  std::vector<uint64_t> checksums_;  // of the parts written, by part
  std::vector<float> key0_;          // held while the movie may be constant
  struct File;                       // AtomicFile + the EXR writer (scanline_exr_writer.h)
  std::unique_ptr<File> file_;
};
// What a reader expects a file to be: a whole movie, or a piece of one. Each refuses the other
// by name (a piece is never read as a whole movie).
enum class MovieFileKind { kWhole, kPiece };

// Reads and validates (part count, sizes, attributes, pixel checksums, finite values). Throws
// rad::inputError(path, ...), never crashes on a truncated or corrupted file.
TextureMovie readTextureMovie(const std::string& path);
// The metadata alone (keys empty), every part's header checked as readTextureMovie checks it.
TextureMovie readTextureMovieHeaders(const std::string& path,
                                     MovieFileKind kind = MovieFileKind::kWhole);

// A movie read as it plays: every part's header is read and checked at construction, the
// pixels of a key only when textureAt needs them, and at most the two keys around the current
// time are held. rad-compose's memory is then the same whatever the movie's length (a static
// patch's movie spans the whole animation). textureAt gives exactly TextureMovie::textureAt.
class TextureMovieStream {
 public:
  // Checks every part's header (a checksum present in each) and opens the file for reading (it
  // stays open until destruction); throws rad::inputError(path, ...).
  explicit TextureMovieStream(std::string path, MovieFileKind kind = MovieFileKind::kWhole);
  // The same with the headers already read and checked (readTextureMovieHeaders of `path`):
  // the file is opened, and OpenEXR's reader started (the part count checked against it) only
  // if a key is not in the uncompressed layout.
  TextureMovieStream(std::string path, TextureMovie headers);
  ~TextureMovieStream();
  TextureMovieStream(const TextureMovieStream&) = delete;
  TextureMovieStream& operator=(const TextureMovieStream&) = delete;
  // The movie's metadata; keys[k] is empty unless key k is loaded.
  const TextureMovie& movie() const { return movie_; }
  void textureAt(double t, std::vector<float>& out);
  // What textureAt(t) blends, without blending it into a copy (rad-compose blends the texels it
  // samples): `from` = key k0, `to` = key k1 or null when textureAt copies k0 alone, `weight`
  // = keyWeight(t, k0, k1). Keys other than k0, k1 are dropped; the pointers stay valid until
  // the next textureAt/keysAt/key call.
  void keysAt(double t, const float*& from, const float*& to, float& weight);
  // Key k's texture, loaded if it is not (for a constant movie: its only texture). Every key
  // loaded is verified against its part's checksum (rad::inputError naming the part if not).
  const std::vector<float>& key(size_t k);
  long long keysRead() const { return keysRead_; }

 private:
  void load(size_t k);
  void open();
  void startExr();  // OpenEXR's core context over the open file, once
  void decodeWithOpenExr(size_t k, std::vector<float>& px);
  void loadAround(double t, size_t& k0, size_t& k1);
  std::string path_;
  struct Reader;  // OpenEXR core context, open for the stream's lifetime
  std::unique_ptr<Reader> reader_;
  TextureMovie movie_;
  long long keysRead_ = 0;
};

// rad-inspect's summary of a movies folder: every NNNNNN.exr read and validated; counts of
// movies, keys and constant movies, texels, frame range, levels, bytes on disk, irradiance
// range. Throws the first movie's error (a corrupt movie is never summarised as fine).
nlohmann::json summarizeTextureMovieDirectory(const std::string& dir);

}  // namespace rad
