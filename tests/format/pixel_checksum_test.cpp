// rad.pixelChecksum (formats/pixel_checksum.h, texture_movie.md, frame_image.md): its value is
// the spec's (recomputed here from the file's own chunk bytes), and every reader catches every
// corrupted pixel-data byte and every truncation of a small texture movie and of small frames
// (FLOAT, HALF, ZIP; rad-compose's and rad-reference's writers), with one line naming the file.
// Damaged chunk tables and chunk headers are caught or read back bit-exact, never silently
// wrong. Issue 18: before the checksum, 223 of 261 data-region corruptions of a movie were
// accepted with wrong values.
#include "formats/pixel_checksum.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <random>
#include <set>

#include "formats/checksum.h"
#include "formats/exr_image.h"
#include "formats/frame_image.h"
#include "formats/item_buffer_exr.h"
#include "formats/texture_movie.h"
#include "libcommon/core/error.h"
#include "tests/format/exr_layout.h"

namespace fs = std::filesystem;

namespace rad {
namespace {

using test::Layout;
using test::layoutOf;

class PixelChecksum : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) /
           ("rad_pixel_checksum_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

std::vector<char> bytesOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>((std::istreambuf_iterator<char>(in)), {});
}

void writeBytes(const std::string& path, const std::vector<char>& bytes, size_t n) {
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), std::streamsize(n));
}

// What a reader gives, or the error it throws.
struct Outcome {
  bool threw = false;
  std::string error;
  std::vector<std::vector<float>> pixels;
};

Outcome outcomeOf(const std::function<std::vector<std::vector<float>>()>& read) {
  Outcome o;
  try {
    o.pixels = read();
  } catch (const Error& e) {
    o.threw = true;
    o.error = e.what();
    EXPECT_EQ(e.code(), ExitCode::kBadInput) << o.error;
  }
  return o;
}

struct Tally {
  int tried = 0, caught = 0, sameValues = 0, silent = 0;
};

using Reader = std::function<std::vector<std::vector<float>>(const std::string&)>;

// Each mutant of `good` written to a file and given to every reader: caught (one line naming
// the file), the original values, or silently different values.
void tally(const std::string& file, const std::vector<char>& mutant, size_t size,
           const std::vector<std::vector<float>>& original,
           const std::vector<std::pair<std::string, Reader>>& readers,
           std::map<std::string, Tally>& tallies, const std::string& what) {
  writeBytes(file, mutant, size);
  for (const auto& [name, read] : readers) {
    Outcome o = outcomeOf([&] { return read(file); });
    Tally& t = tallies[name];
    ++t.tried;
    if (o.threw) {
      ++t.caught;
      EXPECT_EQ(o.error.rfind(file + ": ", 0), 0u) << o.error;
      EXPECT_EQ(o.error.find('\n'), std::string::npos) << o.error;
    } else if (o.pixels == original) {
      ++t.sameValues;
    } else {
      ++t.silent;
      ADD_FAILURE() << name << ": " << what << " read back different values silently";
    }
  }
}

// Flips `count` bytes sampled (seeded) from `ranges`, one per mutant, then cuts the file at
// `cuts` sampled lengths; returns the tallies of flipped pixel bytes, cuts and flipped table
// bytes by reader.
struct Corruption {
  std::map<std::string, Tally> pixelBytes, truncations, tableBytes;
};

Corruption corrupt(const std::string& good, const std::vector<std::vector<float>>& original,
                   const std::vector<std::pair<std::string, Reader>>& readers, int flips, int cuts,
                   int tableFlips) {
  const std::vector<char> bytes = bytesOf(good);
  const Layout layout = layoutOf(good);
  std::vector<uint64_t> pixelBytes;
  for (const auto& [at, n] : layout.pixelData)
    for (uint64_t i = 0; i < n; ++i) pixelBytes.push_back(at + i);
  std::set<uint64_t> isPixel(pixelBytes.begin(), pixelBytes.end());
  std::vector<uint64_t> tableBytes;  // chunk tables and chunk headers
  for (uint64_t i = layout.tablesBegin; i < bytes.size(); ++i)
    if (!isPixel.count(i)) tableBytes.push_back(i);
  std::mt19937 rng(18);
  const std::string file = good + ".mutant.exr";
  Corruption c;
  auto flipSampled = [&](const std::vector<uint64_t>& from, int n, auto& tallies,
                         const char* what) {
    std::uniform_int_distribution<size_t> pick(0, from.size() - 1);
    std::uniform_int_distribution<int> mask(1, 255);
    for (int i = 0; i < n; ++i) {
      std::vector<char> m = bytes;
      const uint64_t at = from[pick(rng)];
      m[at] = char(m[at] ^ mask(rng));
      tally(file, m, m.size(), original, readers, tallies,
            std::string(what) + " byte " + std::to_string(at));
    }
  };
  flipSampled(pixelBytes, flips, c.pixelBytes, "pixel");
  flipSampled(tableBytes, tableFlips, c.tableBytes, "chunk table/header");
  std::uniform_int_distribution<size_t> cut(0, bytes.size() - 1);
  for (int i = 0; i < cuts; ++i) {
    const size_t n = cut(rng);
    tally(file, bytes, n, original, readers, c.truncations, "cut at " + std::to_string(n));
  }
  return c;
}

void report(const std::string& what, const Corruption& c) {
  for (const auto& [kind, tallies] : {std::pair{"pixel bytes flipped", &c.pixelBytes},
                                      {"truncations", &c.truncations},
                                      {"table/chunk-header bytes flipped", &c.tableBytes}})
    for (const auto& [reader, t] : *tallies)
      std::cout << what << ", " << kind << ", " << reader << ": " << t.caught << " of " << t.tried
                << " caught, " << t.sameValues << " read back exactly, " << t.silent
                << " silently different\n";
}

TextureMovie smallMovie() {
  TextureMovie m;
  m.movie = 7;
  m.patch = PatchId{3, 1}.child(1);
  m.firstFrame = 0;
  m.lastFrame = 12;
  m.width = 16;
  m.height = 8;
  m.keyFrames = {0, 6, 12};
  m.keyTimes = {0.0, 0.25, 0.5};
  for (int k = 0; k < 3; ++k) {
    std::vector<float> px(size_t(m.width) * m.height * 3);
    for (size_t i = 0; i < px.size(); ++i) px[i] = 0.25f * float(k + 1) + 1e-3f * float(i);
    m.keys.push_back(px);
  }
  m.provenanceJson = R"({"tool":"rad-movies","version":"0.1.0"})";
  return m;
}

ComposedFrame smallFrame() {
  ComposedFrame f;
  f.size = {12, 9};
  f.time = 0.5;
  f.rgb.resize(size_t(12) * 9 * 3);
  for (size_t i = 0; i < f.rgb.size(); ++i) f.rgb[i] = 0.01f * float(i) + 0.5f;
  f.coveredPixels = 108;
  return f;
}

const std::vector<std::pair<std::string, Reader>> kMovieReaders = {
    {"readTextureMovie", [](const std::string& p) { return readTextureMovie(p).keys; }},
    {"TextureMovieStream", [](const std::string& p) {
       TextureMovieStream s(p);
       std::vector<std::vector<float>> keys;
       for (size_t k = 0; k < s.movie().keyTimes.size(); ++k) keys.push_back(s.key(k));
       return keys;
     }}};

const std::vector<std::pair<std::string, Reader>> kFrameReaders = {
    {"readFrameExr",
     [](const std::string& p) { return std::vector<std::vector<float>>{readFrameExr(p).rgb}; }},
    {"verifyExrPixels", [](const std::string& p) {
       verifyExrPixels(p);
       return std::vector<std::vector<float>>{readExrImage(p).pixels};
     }}};

// The stored value is the spec's: FNV-1a 64 of the chunks' pixel bytes of an uncompressed
// FLOAT part, in file order (scan line by scan line, channels B, G, R within a line).
TEST_F(PixelChecksum, MovieChecksumIsFnv1aOfTheChunksPixelBytes) {
  const TextureMovie m = smallMovie();
  const std::string file = path("m.exr");
  writeTextureMovie(file, m);
  const std::vector<char> bytes = bytesOf(file);
  const Layout layout = layoutOf(file);
  ASSERT_EQ(layout.pixelData.size(), 3u * 8u);  // 3 parts of 8 one-line chunks
  Imf::MultiPartInputFile in(file.c_str());
  for (int k = 0; k < 3; ++k) {
    uint64_t h = kFnv1a64Offset;
    for (int y = 0; y < 8; ++y) {
      const auto [at, n] = layout.pixelData[size_t(k) * 8 + size_t(y)];
      h = fnv1a64(bytes.data() + at, n, h);
    }
    const auto* stored =
        in.header(k).findTypedAttribute<Imf::StringAttribute>(kPixelChecksumAttribute);
    ASSERT_NE(stored, nullptr) << "part " << k;
    EXPECT_EQ(stored->value(), formatFnv1a64(h)) << "part " << k;
    EXPECT_EQ(stored->value(), formatFnv1a64(rgbPixelChecksum(m.keys[size_t(k)].data(), 16, 8)));
  }
  // No placeholder left behind, whichever way the writer wrote the movie.
  EXPECT_EQ(std::string(bytes.begin(), bytes.end()).find(kPixelChecksumPlaceholder),
            std::string::npos);
}

TEST_F(PixelChecksum, FrameChecksumIsOfTheDecodedValuesWhateverTheStorage) {
  const ComposedFrame f = smallFrame();
  FrameImageInfo info;
  writeFrameExr(path("float.exr"), f, info, false);
  writeFrameExr(path("zip.exr"), f, info, false, frameCompressionOf("zip"));
  writeFrameExr(path("half.exr"), f, info, true);
  auto stored = [](const std::string& p) {
    Imf::MultiPartInputFile in(p.c_str());
    return in.header(0).findTypedAttribute<Imf::StringAttribute>(kPixelChecksumAttribute)->value();
  };
  EXPECT_EQ(stored(path("float.exr")), stored(path("zip.exr")));
  EXPECT_EQ(stored(path("float.exr")), formatFnv1a64(rgbPixelChecksum(f.rgb.data(), 12, 9)));
  const FrameExr half = readFrameExr(path("half.exr"));
  EXPECT_NE(half.rgb, f.rgb);  // rounded to half
  EXPECT_EQ(stored(path("half.exr")), formatFnv1a64(rgbPixelChecksum(half.rgb.data(), 12, 9)));
  EXPECT_EQ(half.attributes.at("rad.format"), "frame 2.2");
}

TEST_F(PixelChecksum, EveryCorruptedPixelByteAndTruncationOfAMovieIsCaught) {
  const TextureMovie m = smallMovie();
  const std::string file = path("m.exr");
  writeTextureMovie(file, m);
  const Corruption c = corrupt(file, m.keys, kMovieReaders, 600, 150, 200);
  report("movie 16x8x3 keys", c);
  for (const auto& [reader, t] : c.pixelBytes) EXPECT_EQ(t.caught, t.tried) << reader;
  for (const auto& [reader, t] : c.truncations) EXPECT_EQ(t.caught, t.tried) << reader;
  for (const auto& [reader, t] : c.tableBytes) EXPECT_EQ(t.silent, 0) << reader;
}

TEST_F(PixelChecksum, EveryCorruptedPixelByteAndTruncationOfAFrameIsCaught) {
  const ComposedFrame f = smallFrame();
  FrameImageInfo info;
  info.provenanceJson = R"({"tool":"rad-compose","version":"0.1.0"})";
  struct Variant {
    const char* name;
    bool half;
    const char* compression;
  };
  for (const Variant v : {Variant{"float", false, "none"}, Variant{"half", true, "none"},
                          Variant{"zip", false, "zip"}}) {
    const std::string file = path(std::string(v.name) + ".exr");
    writeFrameExr(file, f, info, v.half, frameCompressionOf(v.compression));
    const std::vector<std::vector<float>> original = {readFrameExr(file).rgb};
    const Corruption c = corrupt(file, original, kFrameReaders, 600, 150, 200);
    report(std::string("frame 12x9 ") + v.name, c);
    // A flipped bit of a ZIP stream may not change what it inflates to (1 of 600 here): the
    // values read are then the written ones, which is no corruption of the frame.
    for (const auto& [reader, t] : c.pixelBytes)
      EXPECT_EQ(t.caught + (v.compression == std::string("zip") ? t.sameValues : 0), t.tried)
          << v.name << reader;
    for (const auto& [reader, t] : c.truncations) EXPECT_EQ(t.caught, t.tried) << v.name << reader;
    for (const auto& [reader, t] : c.tableBytes) EXPECT_EQ(t.silent, 0) << v.name << reader;
  }
}

// rad-reference's frames (writeExrImage: ZIP, no rad.format) carry the same checksum.
TEST_F(PixelChecksum, EveryCorruptedPixelByteOfAReferenceFrameIsCaught) {
  FloatImage im(10, 7, {"R", "G", "B"});
  for (size_t i = 0; i < im.pixels.size(); ++i) im.pixels[i] = 0.125f * float(i % 97);
  const std::string file = path("0003.exr");
  writeExrImage(file, im, {{"rad.frame", "3"}});
  const Corruption c = corrupt(file, {im.pixels},
                               {{"readExrImage",
                                 [](const std::string& p) {
                                   return std::vector<std::vector<float>>{readExrImage(p).pixels};
                                 }}},
                               300, 100, 100);
  report("reference frame 10x7 zip", c);
  for (const auto& [reader, t] : c.pixelBytes) EXPECT_EQ(t.caught, t.tried) << reader;
  for (const auto& [reader, t] : c.truncations) EXPECT_EQ(t.caught, t.tried) << reader;
  for (const auto& [reader, t] : c.tableBytes) EXPECT_EQ(t.silent, 0) << reader;
}

// A frame of the previous version (no checksum) is refused with the stage to re-run; an EXR
// without rad.format and without a checksum (another program's, an older reference) is read.
TEST_F(PixelChecksum, OlderFramesAreRefusedForeignFilesRead) {
  const ComposedFrame f = smallFrame();
  const std::string file = path("0001.exr");
  writeFrameExr(file, f, FrameImageInfo{}, false);
  std::vector<char> bytes = bytesOf(file);
  std::string text(bytes.begin(), bytes.end());
  const size_t at = text.find("frame 2.2");
  ASSERT_NE(at, std::string::npos);
  bytes[at + 6] = '1';
  bytes[at + 8] = '0';
  const std::string old = path("old.exr");
  writeBytes(old, bytes, bytes.size());
  try {
    readFrameExr(old);
    ADD_FAILURE() << "a frame 1.0 was read";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              old +
                  ": frame 1.0 is no longer read (its pixels carry no checksum): re-run "
                  "rad-compose");
  }
}

// Item buffers (rad-intervals --item-buffers, read by rad-diff --surfaces) carry the checksum
// since item-buffer 2.0: over Z then id, an id hashed as its uint32's bytes. readItemBufferExr,
// rad-inspect's verifyExrPixels and readExrImage (ids converted to float) all verify it.
TEST_F(PixelChecksum, ItemBuffersCarryAndVerifyIt) {
  ItemBuffer b;
  b.width = 5;
  b.height = 3;
  for (int p = 0; p < 15; ++p) {
    b.id.push_back(p % 4 == 0 ? kNoItem : uint32_t(p * 1000003));
    b.depth.push_back(p % 4 == 0 ? INFINITY : 0.5f + float(p));
  }
  const std::string file = path("0003.exr");
  writeItemBufferExr(file, b, 3, 0.125, "{}");
  const ItemBuffer r = readItemBufferExr(file);
  EXPECT_EQ(r.id, b.id);
  EXPECT_EQ(verifyExrPixels(file)["checksummed_parts"], 1);
  const FloatImage image = readExrImage(file, {"id"});
  EXPECT_EQ(image.pixels[1], float(1000003));
  // The spec's definition, recomputed here: FNV-1a over Z's then id's 4 bytes, line by line.
  uint64_t h = kFnv1a64Offset;
  auto hash = [&](const void* word) {
    for (int i = 0; i < 4; ++i) h = (h ^ static_cast<const uint8_t*>(word)[i]) * kFnv1a64Prime;
  };
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 5; ++x) hash(&b.depth[size_t(y * 5 + x)]);
    for (int x = 0; x < 5; ++x) hash(&b.id[size_t(y * 5 + x)]);
  }
  EXPECT_EQ(itemBufferChecksum(b), h);

  // A stored checksum that does not match the pixels (one hex digit changed).
  std::vector<char> bytes = bytesOf(file);
  std::string text(bytes.begin(), bytes.end());
  const size_t at = text.find("fnv1a64:");
  ASSERT_NE(at, std::string::npos);
  bytes[at + 8] = bytes[at + 8] == '0' ? '1' : '0';
  const std::string wrong = path("wrong.exr");
  writeBytes(wrong, bytes, bytes.size());
  for (const auto& read : std::vector<std::function<void()>>{[&] { readItemBufferExr(wrong); },
                                                             [&] { verifyExrPixels(wrong); },
                                                             [&] { readExrImage(wrong, {"Z"}); }}) {
    try {
      read();
      ADD_FAILURE() << "a wrong checksum was accepted";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind(wrong + ": part 0: pixel checksum mismatch", 0), 0u)
          << e.what();
    }
  }
  // An item-buffer 1.0 (no checksum) is refused with the stage to re-run.
  bytes = bytesOf(file);
  text.assign(bytes.begin(), bytes.end());
  const size_t version = text.find("item-buffer 2.0");
  ASSERT_NE(version, std::string::npos);
  bytes[version + 12] = '1';
  const std::string old = path("old.exr");
  writeBytes(old, bytes, bytes.size());
  try {
    readItemBufferExr(old);
    ADD_FAILURE() << "an item-buffer 1.0 was read";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              old +
                  ": item-buffer 1.0 is no longer read (its pixels carry no checksum): re-run "
                  "rad-intervals");
  }
}

TEST(PixelChecksumAttribute, ParsesOnlyWellFormedValues) {
  EXPECT_EQ(parseFnv1a64(formatFnv1a64(0x0123456789abcdefull)), 0x0123456789abcdefull);
  EXPECT_FALSE(parseFnv1a64(kPixelChecksumPlaceholder));
  EXPECT_FALSE(parseFnv1a64("fnv1a64:0123456789ABCDEF"));
  EXPECT_FALSE(parseFnv1a64("fnv1a64:0123456789abcde"));
  EXPECT_FALSE(parseFnv1a64("crc32:0123456789abcdef"));
}

}  // namespace
}  // namespace rad
