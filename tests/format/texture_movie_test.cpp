// movies/MMMMMM.exr (formats/texture_movie.md): round trip of keys, times and attributes;
// constant movies; interpolation between keys; truncated, corrupted, non-movie and
// future-version files give one-line errors naming the file, never a crash; the streaming
// TextureMovieWriter writes writeTextureMovie's bytes, detects constant movies and leaves
// nothing behind when it fails; its files are byte for byte those OpenEXR's own writer makes of
// the same headers and pixels.
#include "formats/texture_movie.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "formats/exr_header_scan.h"
#include "formats/uncompressed_exr_part.h"
#include "libcommon/core/error.h"

namespace fs = std::filesystem;

namespace rad {
namespace {

class TextureMovieFormat : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) /
           ("rad_texture_movie_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string dir() const { return dir_.string(); }
  fs::path dir_;
};

TextureMovie sampleMovie(int keys) {
  TextureMovie m;
  m.movie = 42;
  m.patch = PatchId{7, 1}.child(2).child(1);
  m.firstFrame = 10;
  m.lastFrame = 10 + 6 * (keys - 1);
  m.width = 5;
  m.height = 3;
  for (int k = 0; k < keys; ++k) {
    m.keyFrames.push_back(10 + 6 * k);
    m.keyTimes.push_back((10 + 6 * k) / 24.0);
    std::vector<float> px(size_t(m.width) * m.height * 3);
    for (size_t i = 0; i < px.size(); ++i) px[i] = float(k * 1000 + i) * 0.5f + 1e-7f * float(i);
    m.keys.push_back(px);
  }
  m.provenanceJson = R"({"tool":"rad-movies","version":"0.1.0"})";
  return m;
}

std::string errorOf(const std::string& path) {
  try {
    readTextureMovie(path);
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kBadInput);
    return e.what();
  }
  return "";
}

TEST_F(TextureMovieFormat, RoundTripKeepsEverythingBitExact) {
  TextureMovie m = sampleMovie(4);
  std::string path = textureMoviePath(dir(), m.movie);
  EXPECT_EQ(fs::path(path).filename(), "000042.exr");
  writeTextureMovie(path, m);
  TextureMovie r = readTextureMovie(path);
  EXPECT_EQ(r.movie, m.movie);
  EXPECT_EQ(r.patch, m.patch);
  EXPECT_EQ(r.patch.level(), 2);
  EXPECT_EQ(r.firstFrame, m.firstFrame);
  EXPECT_EQ(r.lastFrame, m.lastFrame);
  EXPECT_EQ(r.width, m.width);
  EXPECT_EQ(r.height, m.height);
  EXPECT_EQ(r.keyFrames, m.keyFrames);
  EXPECT_EQ(r.keyTimes, m.keyTimes);
  EXPECT_EQ(r.keys, m.keys);
  EXPECT_EQ(r.provenanceJson, m.provenanceJson);
  EXPECT_FALSE(r.constant());
  // Parts are named and carry the attributes the spec lists.
  Imf::MultiPartInputFile in(path.c_str());
  ASSERT_EQ(in.parts(), 4);
  EXPECT_EQ(in.header(0).name(), "key0000");
  EXPECT_EQ(in.header(3).name(), "key0003");
  EXPECT_EQ(in.header(1).findTypedAttribute<Imf::StringAttribute>("rad.patch")->value(), "7/2.1");
  EXPECT_EQ(in.header(0).findTypedAttribute<Imf::StringAttribute>("rad.format")->value(),
            "texture-movie 2.1");
}

TEST_F(TextureMovieFormat, ConstantMovieAndInterpolation) {
  TextureMovie c = sampleMovie(1);
  writeTextureMovie(dir() + "/c.exr", c);
  TextureMovie r = readTextureMovie(dir() + "/c.exr");
  EXPECT_TRUE(r.constant());
  std::vector<float> out;
  r.textureAt(100.0, out);
  EXPECT_EQ(out, c.keys[0]);
  TextureMovie m = sampleMovie(3);
  std::vector<float> mid;
  m.textureAt(0.5 * (m.keyTimes[1] + m.keyTimes[2]), mid);
  for (size_t i = 0; i < mid.size(); ++i)
    EXPECT_FLOAT_EQ(mid[i], 0.5f * (m.keys[1][i] + m.keys[2][i]));
  m.textureAt(-1.0, out);
  EXPECT_EQ(out, m.keys[0]);
}

TEST_F(TextureMovieFormat, TruncatedFilesGiveOneLineErrors) {
  TextureMovie m = sampleMovie(3);
  std::string path = dir() + "/m.exr";
  writeTextureMovie(path, m);
  std::ifstream in(path, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
  ASSERT_GT(bytes.size(), 200u);
  for (size_t cut : {size_t(0), size_t(3), size_t(40), bytes.size() / 2, bytes.size() - 1}) {
    std::string t = dir() + "/cut" + std::to_string(cut) + ".exr";
    std::ofstream(t, std::ios::binary).write(bytes.data(), std::streamsize(cut));
    std::string e = errorOf(t);
    EXPECT_FALSE(e.empty()) << "cut at " << cut;
    EXPECT_EQ(e.rfind(t + ": ", 0), 0u) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  // Corrupted bytes in the pixel data: an error or a valid movie, never a crash.
  for (size_t at = bytes.size() / 3; at < bytes.size(); at += bytes.size() / 7) {
    std::vector<char> bad = bytes;
    bad[at] = char(bad[at] ^ 0x5a);
    std::string t = dir() + "/bad.exr";
    std::ofstream(t, std::ios::binary | std::ios::trunc)
        .write(bad.data(), std::streamsize(bad.size()));
    try {
      readTextureMovie(t);
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
  }
}

// rad-compose's reader: the same textures as the whole-file reader at every time, at most
// the two keys around the time in memory, and truncated or corrupted files as one-line errors.
TEST_F(TextureMovieFormat, StreamGivesTheSameTexturesHoldingTwoKeys) {
  TextureMovie m = sampleMovie(6);
  m.width = 37;  // several scanline chunks (ZIP: 16 lines each)
  m.height = 41;
  for (auto& k : m.keys) {
    k.resize(size_t(m.width) * m.height * 3);
    for (size_t i = 0; i < k.size(); ++i) k[i] = float(i % 97) * 0.25f + float(&k - &m.keys[0]);
  }
  std::string path = dir() + "/s.exr";
  writeTextureMovie(path, m);
  TextureMovie whole = readTextureMovie(path);
  TextureMovieStream stream(path);
  EXPECT_EQ(stream.movie().keyTimes, whole.keyTimes);
  EXPECT_EQ(stream.movie().patch, whole.patch);
  EXPECT_EQ(stream.keysRead(), 0);  // headers only so far
  std::vector<float> a, b;
  for (double t = m.keyTimes.front() - 0.1; t <= m.keyTimes.back() + 0.1; t += 1 / 48.0) {
    whole.textureAt(t, a);
    stream.textureAt(t, b);
    ASSERT_EQ(a, b) << t;
    size_t held = 0;
    for (const auto& k : stream.movie().keys) held += k.empty() ? 0 : 1;
    EXPECT_LE(held, 2u) << t;
  }
  EXPECT_EQ(stream.keysRead(), 6);  // each key read once while playing forwards
  EXPECT_EQ(stream.key(0), m.keys[0]);

  // Truncated: the header check or the first key read fails with one line naming the file.
  std::ifstream in(path, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
  for (size_t cut : {size_t(40), bytes.size() / 2, bytes.size() - 1}) {
    std::string t = dir() + "/cut" + std::to_string(cut) + ".exr";
    std::ofstream(t, std::ios::binary).write(bytes.data(), std::streamsize(cut));
    try {
      TextureMovieStream s(t);
      std::vector<float> out;
      for (size_t k = 0; k < s.movie().keyTimes.size(); ++k)
        s.textureAt(s.movie().keyTimes[k], out);
      ADD_FAILURE() << "no error for a file cut at " << cut;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ExitCode::kBadInput);
      EXPECT_EQ(std::string(e.what()).rfind(t + ": ", 0), 0u) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
  // Corrupted pixel data: an error or textures, never a crash.
  for (size_t at = bytes.size() / 3; at < bytes.size(); at += bytes.size() / 7) {
    std::vector<char> bad = bytes;
    bad[at] = char(bad[at] ^ 0x5a);
    std::string t = dir() + "/bad.exr";
    std::ofstream(t, std::ios::binary | std::ios::trunc)
        .write(bad.data(), std::streamsize(bad.size()));
    try {
      TextureMovieStream s(t);
      std::vector<float> out;
      for (double time : s.movie().keyTimes) s.textureAt(time, out);
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
  }
}

// The stream reads through a 64 KiB window (one pread per window instead of one per scanline).
// Keys larger than the window, read out of order, must still come back bit for bit.
TEST_F(TextureMovieFormat, StreamReadsKeysLargerThanItsReadWindowInAnyOrder) {
  TextureMovie m = sampleMovie(4);
  m.width = 160;  // 160 x 120 x 3 floats: 230 KB per key, 3.5 windows
  m.height = 120;
  for (auto& k : m.keys) {
    k.resize(size_t(m.width) * m.height * 3);
    for (size_t i = 0; i < k.size(); ++i)
      k[i] = float(i % 1009) * 0.125f + 1000.0f * float(&k - &m.keys[0]);
  }
  std::string path = dir() + "/big.exr";
  writeTextureMovie(path, m);
  TextureMovieStream stream(path);
  for (size_t k : {size_t(3), size_t(0), size_t(2), size_t(1)})
    ASSERT_EQ(stream.key(k), m.keys[k]) << "key " << k;
  EXPECT_EQ(stream.keysRead(), 4);
}

// rad-compose blends the two keys per sampled texel (keysAt) instead of copying textureAt's
// blend: the same float arithmetic must give textureAt's texels bit for bit, at every time
// (before, between, on and after the keys), with only the two keys around t held.
TEST_F(TextureMovieFormat, StreamKeysAtBlendIsTextureAtBitForBit) {
  TextureMovie m = sampleMovie(5);
  for (auto& k : m.keys)
    for (size_t i = 0; i < k.size(); ++i)
      k[i] = std::sin(float(i) * 0.37f + float(&k - &m.keys[0])) * 3.1f + 3.3f;
  std::string path = dir() + "/k.exr";
  writeTextureMovie(path, m);
  TextureMovie whole = readTextureMovie(path);
  TextureMovieStream stream(path);
  std::vector<float> expected, blended;
  int between = 0, alone = 0;
  for (double t = m.keyTimes.front() - 0.1; t <= m.keyTimes.back() + 0.1; t += 1 / 96.0) {
    whole.textureAt(t, expected);
    const float* from = nullptr;
    const float* to = nullptr;
    float w = -1.0f;
    stream.keysAt(t, from, to, w);
    ASSERT_NE(from, nullptr);
    blended.assign(expected.size(), 0.0f);
    for (size_t i = 0; i < blended.size(); ++i)
      blended[i] = to ? (1.0f - w) * from[i] + w * to[i] : from[i];
    ASSERT_EQ(0, std::memcmp(blended.data(), expected.data(), blended.size() * sizeof(float))) << t;
    (to ? between : alone)++;
    if (to) {
      EXPECT_GE(w, 0.0f);
      EXPECT_LT(w, 1.0f);
    }
    size_t held = 0;
    for (const auto& k : stream.movie().keys) held += k.empty() ? 0 : 1;
    EXPECT_LE(held, 2u) << t;
  }
  EXPECT_GT(between, 10);  // both branches were exercised
  EXPECT_GT(alone, 2);
  EXPECT_EQ(stream.keysRead(), 5);
}

TEST_F(TextureMovieFormat, NotAMovieAndFutureVersionsAreRefusedByName) {
  std::string missing = dir() + "/missing.exr";
  EXPECT_EQ(errorOf(missing).rfind(missing + ": ", 0), 0u);
  std::string text = dir() + "/text.exr";
  std::ofstream(text) << "hello";
  EXPECT_EQ(errorOf(text).rfind(text + ": ", 0), 0u);
  TextureMovie m = sampleMovie(2);
  std::string path = dir() + "/m.exr";
  writeTextureMovie(path, m);
  // Rewrite the version string in place ("texture-movie 2.1" -> "texture-movie 9.0").
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  size_t pos = 0;
  int replaced = 0;
  while ((pos = bytes.find("texture-movie 2.", pos)) != std::string::npos) {
    bytes[pos + 14] = '9';
    bytes[pos + 16] = '0';
    ++replaced;
  }
  ASSERT_EQ(replaced, 2);
  std::string future = dir() + "/future.exr";
  std::ofstream(future, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
  std::string e = errorOf(future);
  EXPECT_NE(e.find("texture-movie version 9.0, expected 2.x"), std::string::npos) << e;
  // The previous version (no pixel checksums) is refused with the stage to re-run.
  for (size_t at = 0; (at = bytes.find("texture-movie 9.", at)) != std::string::npos;)
    bytes[at + 14] = '1';
  std::string old = dir() + "/old.exr";
  std::ofstream(old, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
  EXPECT_EQ(errorOf(old), old +
                              ": texture-movie version 1.0 is no longer read (its pixels "
                              "carry no checksum): re-run rad-movies");
}

TEST_F(TextureMovieFormat, WriterRefusesInconsistentMovies) {
  TextureMovie m = sampleMovie(2);
  m.keyTimes.pop_back();
  EXPECT_THROW(writeTextureMovie(dir() + "/x.exr", m), Error);
  EXPECT_FALSE(fs::exists(dir() + "/x.exr"));
  m = sampleMovie(2);
  m.keys[1].pop_back();
  EXPECT_THROW(writeTextureMovie(dir() + "/y.exr", m), Error);
  EXPECT_FALSE(fs::exists(dir() + "/y.exr"));
}

std::string bytesOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Every file in the directory (hidden temporaries included).
std::vector<std::string> filesIn(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

size_t streamMovie(const std::string& path, const TextureMovie& m, bool collapse) {
  TextureMovie meta = m;
  meta.keys.clear();  // the writer only needs the metadata and key frames/times
  TextureMovieWriter writer(path, meta, collapse);
  for (size_t k = 0; k < m.keys.size(); ++k) writer.writeKey(k, m.keys[k]);
  return writer.commit();
}

TEST_F(TextureMovieFormat, StreamingWriterWritesWriteTextureMoviesBytes) {
  TextureMovie m = sampleMovie(5);
  writeTextureMovie(dir() + "/whole.exr", m);
  EXPECT_EQ(streamMovie(dir() + "/streamed.exr", m, false), 5u);
  EXPECT_EQ(streamMovie(dir() + "/collapsing.exr", m, true), 5u) << "keys differ: all stored";
  const std::string whole = bytesOf(dir() + "/whole.exr");
  EXPECT_GT(whole.size(), 1000u);
  EXPECT_EQ(bytesOf(dir() + "/streamed.exr"), whole);
  EXPECT_EQ(bytesOf(dir() + "/collapsing.exr"), whole);
  TextureMovie r = readTextureMovie(dir() + "/streamed.exr");
  EXPECT_EQ(r.keys, m.keys);
  EXPECT_EQ(r.keyFrames, m.keyFrames);
  EXPECT_EQ(filesIn(dir()),
            (std::vector<std::string>{"collapsing.exr", "streamed.exr", "whole.exr"}));
}

TEST_F(TextureMovieFormat, StreamingWriterStoresAConstantMovieWithOneKey) {
  TextureMovie m = sampleMovie(4);
  for (auto& key : m.keys) key = m.keys[0];
  TextureMovie one = m;
  one.keys.resize(1);
  one.keyFrames.resize(1);
  one.keyTimes.resize(1);
  writeTextureMovie(dir() + "/one.exr", one);
  writeTextureMovie(dir() + "/all.exr", m);
  EXPECT_EQ(streamMovie(dir() + "/constant.exr", m, true), 1u);
  EXPECT_EQ(bytesOf(dir() + "/constant.exr"), bytesOf(dir() + "/one.exr"));
  TextureMovie r = readTextureMovie(dir() + "/constant.exr");
  EXPECT_TRUE(r.constant());
  EXPECT_EQ(r.keyFrames, std::vector<int>{m.firstFrame});
  EXPECT_EQ(r.lastFrame, m.lastFrame);
  // Without collapsing every key is stored.
  EXPECT_EQ(streamMovie(dir() + "/kept.exr", m, false), 4u);
  EXPECT_EQ(bytesOf(dir() + "/kept.exr"), bytesOf(dir() + "/all.exr"));

  // Equal keys first, then one that differs by one bit: keys 0..2 are written as copies of
  // key 0 when key 3 arrives; the file is the full movie's.
  TextureMovie late = m;
  uint32_t bits;
  std::memcpy(&bits, &late.keys[3][7], 4);
  bits ^= 1u;
  std::memcpy(&late.keys[3][7], &bits, 4);
  writeTextureMovie(dir() + "/late.exr", late);
  {
    TextureMovie meta = late;
    meta.keys.clear();
    TextureMovieWriter writer(dir() + "/late-streamed.exr", meta, true);
    for (size_t k = 0; k < 3; ++k) {
      writer.writeKey(k, late.keys[k]);
      EXPECT_TRUE(writer.constantSoFar()) << k;
    }
    writer.writeKey(3, late.keys[3]);
    EXPECT_FALSE(writer.constantSoFar());
    EXPECT_EQ(writer.commit(), 4u);
  }
  EXPECT_EQ(bytesOf(dir() + "/late-streamed.exr"), bytesOf(dir() + "/late.exr"));
}

TEST_F(TextureMovieFormat, StreamingWriterLeavesNothingBehindOnFailure) {
  TextureMovie m = sampleMovie(4);
  TextureMovie meta = m;
  meta.keys.clear();
  const std::string path = dir() + "/000042.exr";
  for (bool collapse : {false, true}) {
    {  // abandoned after two keys (an exception in the baker)
      TextureMovieWriter writer(path, meta, collapse);
      writer.writeKey(0, m.keys[0]);
      writer.writeKey(1, m.keys[1]);
    }
    EXPECT_TRUE(filesIn(dir()).empty()) << "collapse " << collapse;
    {  // committed too early, then a key out of order and one of the wrong size
      TextureMovieWriter writer(path, meta, collapse);
      writer.writeKey(0, m.keys[0]);
      EXPECT_THROW(writer.commit(), Error);
      EXPECT_THROW(writer.writeKey(2, m.keys[2]), Error);
      std::vector<float> small(m.keys[1].begin(), m.keys[1].end() - 1);
      EXPECT_THROW(writer.writeKey(1, small), Error);
    }
    EXPECT_TRUE(filesIn(dir()).empty()) << "collapse " << collapse;
  }
  // A previous version of the movie survives an abandoned rewrite untouched.
  writeTextureMovie(path, sampleMovie(2));
  const std::string before = bytesOf(path);
  {
    TextureMovieWriter writer(path, meta, false);
    writer.writeKey(0, m.keys[0]);
  }
  EXPECT_EQ(bytesOf(path), before);
  EXPECT_EQ(filesIn(dir()), std::vector<std::string>{"000042.exr"});
  // An unwritable place is an output error naming the movie, and nothing is created.
  try {
    TextureMovieWriter writer(dir() + "/no/such/dir/000001.exr", meta, false);
    for (size_t k = 0; k < m.keys.size(); ++k) writer.writeKey(k, m.keys[k]);
    writer.commit();
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kOutput) << e.what();
    EXPECT_NE(std::string(e.what()).find("000001.exr"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir() + "/no"));
}

}  // namespace
}  // namespace rad

namespace rad {
namespace {

// A piece of a movie (texture_movie_piece.md): its own format name, its place in the movie
// round-trips, a piece reader takes it, and a whole-movie reader (rad-compose's, rad-inspect's)
// refuses it by name, as the piece reader refuses a whole movie.
TEST_F(TextureMovieFormat, PieceRoundTripsAndIsNeverReadAsAWholeMovie) {
  TextureMovie whole = sampleMovie(5);
  TextureMovie piece = whole;
  piece.piece = TextureMoviePiece{1, 2, 2, 3, 5};  // keys 2, 3, 4 of 5
  piece.keyFrames.erase(piece.keyFrames.begin(), piece.keyFrames.begin() + 2);
  piece.keyTimes.erase(piece.keyTimes.begin(), piece.keyTimes.begin() + 2);
  piece.keys.erase(piece.keys.begin(), piece.keys.begin() + 2);
  const std::string path = textureMoviePiecePath(dir(), piece.movie, 1);
  EXPECT_EQ(fs::path(path).filename(), "000042.piece-0001.exr");
  writeTextureMovie(path, piece);

  TextureMovieStream stream(path, MovieFileKind::kPiece);
  const TextureMovie& r = stream.movie();
  EXPECT_EQ(r.piece.index, 1);
  EXPECT_EQ(r.piece.count, 2);
  EXPECT_EQ(r.piece.firstKey, 2);
  EXPECT_EQ(r.piece.keys, 3);
  EXPECT_EQ(r.piece.movieKeys, 5);
  EXPECT_EQ(r.keyFrames, piece.keyFrames);
  EXPECT_EQ(stream.key(2), piece.keys[2]);
  Imf::MultiPartInputFile in(path.c_str());
  EXPECT_EQ(in.header(0).findTypedAttribute<Imf::StringAttribute>("rad.format")->value(),
            "texture-movie-piece 1.0");

  const std::string e = errorOf(path);
  EXPECT_EQ(e, path +
                   ": a piece of texture movie 42 (texture-movie-piece 1.0), not a whole movie: "
                   "rad-movies --merge-pieces joins the pieces into the movie");
  EXPECT_THROW(readTextureMovieHeaders(path), Error);
  const std::string wholePath = textureMoviePath(dir(), whole.movie);
  writeTextureMovie(wholePath, whole);
  try {
    TextureMovieStream wrong(wholePath, MovieFileKind::kPiece);
    ADD_FAILURE() << "a whole movie read as a piece";
  } catch (const Error& err) {
    EXPECT_NE(std::string(err.what()).find("not a piece"), std::string::npos) << err.what();
  }
}

// A constant piece (all its keys equal) is stored with one part, and its attributes still say
// how many keys it covers.
TEST_F(TextureMovieFormat, ConstantPieceKeepsOneKeyAndItsKeyCount) {
  TextureMovie piece = sampleMovie(4);
  piece.piece = TextureMoviePiece{0, 3, 0, 4, 10};
  const std::string path = textureMoviePiecePath(dir(), piece.movie, 0);
  TextureMovieWriter writer(path, piece, true);
  for (size_t k = 0; k < 4; ++k) writer.writeKey(k, piece.keys[0]);
  EXPECT_EQ(writer.commit(), 1u);
  TextureMovie r = readTextureMovieHeaders(path, MovieFileKind::kPiece);
  EXPECT_EQ(r.keyFrames.size(), 1u);
  EXPECT_EQ(r.piece.keys, 4);
  EXPECT_EQ(r.piece.movieKeys, 10);
}

// The file OpenEXR's MultiPartOutputFile writes from `path`'s headers (with `compression`) and
// pixels, as bytes.
std::string rewrittenByOpenExr(const std::string& path, const std::string& out,
                               Imf::Compression compression = Imf::NO_COMPRESSION) {
  Imf::MultiPartInputFile in(path.c_str());
  std::vector<Imf::Header> headers;
  for (int p = 0; p < in.parts(); ++p) {
    headers.push_back(in.header(p));
    headers.back().compression() = compression;
  }
  const Imath::Box2i dw = headers[0].dataWindow();
  const int w = dw.max.x + 1, h = dw.max.y + 1;
  std::vector<std::vector<float>> pixels(headers.size(), std::vector<float>(size_t(w) * h * 3));
  const auto frameBuffer = [&](std::vector<float>& px) {
    Imf::FrameBuffer fb;
    char* base = reinterpret_cast<char*>(px.data());
    const size_t xs = 3 * sizeof(float), ys = size_t(w) * xs;
    fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
    fb.insert("G", Imf::Slice(Imf::FLOAT, base + 4, xs, ys));
    fb.insert("B", Imf::Slice(Imf::FLOAT, base + 8, xs, ys));
    return fb;
  };
  for (int p = 0; p < in.parts(); ++p) {
    Imf::InputPart part(in, p);
    part.setFrameBuffer(frameBuffer(pixels[size_t(p)]));
    part.readPixels(0, h - 1);
  }
  {
    Imf::MultiPartOutputFile file(out.c_str(), headers.data(), int(headers.size()));
    for (int p = 0; p < int(headers.size()); ++p) {
      Imf::OutputPart part(file, p);
      part.setFrameBuffer(frameBuffer(pixels[size_t(p)]));
      part.writePixels(h);
    }
  }
  return bytesOf(out);
}

TEST_F(TextureMovieFormat, WriterWritesTheBytesOfOpenExrsOwnWriter) {
  TextureMovie m = sampleMovie(4);
  writeTextureMovie(dir() + "/multi.exr", m);
  const std::string ours = bytesOf(dir() + "/multi.exr");
  EXPECT_GT(ours.size(), 1000u);
  EXPECT_EQ(rewrittenByOpenExr(dir() + "/multi.exr", dir() + "/imf-multi.exr"), ours);
  // One key: a single-part file (no part numbers, no chunkCount).
  writeTextureMovie(dir() + "/single.exr", sampleMovie(1));
  EXPECT_EQ(rewrittenByOpenExr(dir() + "/single.exr", dir() + "/imf-single.exr"),
            bytesOf(dir() + "/single.exr"));
  // A piece (more attributes) of a wider movie.
  TextureMovie piece = sampleMovie(3);
  piece.width = 17;
  for (std::vector<float>& key : piece.keys) key.resize(size_t(17) * 3 * 3, 2.5f);
  piece.piece = TextureMoviePiece{1, 3, 3, 3, 9};
  writeTextureMovie(dir() + "/piece.exr", piece);
  EXPECT_EQ(rewrittenByOpenExr(dir() + "/piece.exr", dir() + "/imf-piece.exr"),
            bytesOf(dir() + "/piece.exr"));
}

TEST_F(TextureMovieFormat, UncompressedPartsAreReadWithoutOpenExrAndOtherLayoutsWithIt) {
  const TextureMovie m = sampleMovie(3);
  const std::string path = dir() + "/m.exr";
  writeTextureMovie(path, m);
  const ExrHeaderScan scan = scanExrFile(path);
  const int fd = ::open(path.c_str(), O_RDONLY);
  ASSERT_GE(fd, 0);
  std::vector<float> px;
  for (int k = 0; k < 3; ++k) {
    EXPECT_TRUE(readUncompressedRgbPart(fd, uncompressedPartTableAt(scan.headerBytes, k, m.height),
                                        true, k, m.width, m.height, px));
    EXPECT_EQ(px, m.keys[size_t(k)]) << "key " << k;
  }
  // The wrong part's table, or a single-part leader, is refused (the leaders disagree).
  EXPECT_FALSE(readUncompressedRgbPart(fd, uncompressedPartTableAt(scan.headerBytes, 1, m.height),
                                       true, 0, m.width, m.height, px));
  EXPECT_FALSE(readUncompressedRgbPart(fd, uncompressedPartTableAt(scan.headerBytes, 0, m.height),
                                       false, 0, m.width, m.height, px));
  ::close(fd);
  EXPECT_GT(readTextureMovieHeaders(path).uncompressedTablesAt, 0u);
  // ZIP (any writer's choice): read through OpenEXR, the same keys.
  const std::string zip = dir() + "/zip.exr";
  rewrittenByOpenExr(path, zip, Imf::ZIP_COMPRESSION);
  const TextureMovie headers = readTextureMovieHeaders(zip);
  EXPECT_EQ(headers.uncompressedTablesAt, 0u);
  TextureMovieStream stream(zip, headers);
  for (size_t k = 0; k < 3; ++k) EXPECT_EQ(stream.key(k), m.keys[k]) << "key " << k;
  EXPECT_EQ(readTextureMovie(zip).keys, m.keys);
}

}  // namespace
}  // namespace rad
