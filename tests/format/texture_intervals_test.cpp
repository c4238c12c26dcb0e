// intervals.rti format tests (formats/texture_intervals.md): round trip; truncated, wrong-kind,
// future-version and inconsistent files give the documented error.
#include "formats/texture_intervals.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "formats/provenance.h"
#include "libcommon/core/error.h"

namespace rad {
namespace {

TextureIntervals sample() {
  TextureIntervals iv;
  iv.firstFrame = 10;
  iv.lastFrame = 40;
  iv.fps = 30.0;
  iv.imageWidth = 352;
  iv.imageHeight = 240;
  PatchId a{3, 1}, b = PatchId{7, 1}.child(2).child(1);
  iv.movies = {{0, a, 10, 20, 64, 64, MovieEnd::kResize},
               {1, b, 10, 40, 4, 8, MovieEnd::kWindow},
               {2, a, 21, 25, 128, 128, MovieEnd::kHidden},
               {3, PatchId{0, 1}.child(3), 30, 30, 1, 1, MovieEnd::kMaxLength}};
  return iv;
}

Provenance provenance() {
  const char* argv[] = {"rad-intervals", "scene.gltf", "-o", "i.rti"};
  return makeProvenance("rad-intervals", 4, argv, {{"max-level", 2}});
}

std::string tempPath(const std::string& name) {
  return testing::TempDir() + "/" + name;
}

template <class F>
void expectInputError(F&& f, const std::string& part) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one containing: " << part;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kBadInput) << e.what();
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(TextureIntervalsFormat, RoundTrip) {
  TextureIntervals iv = sample();
  std::string path = tempPath("rad_fmt_iv.rti");
  writeTextureIntervals(path, iv, provenance(), {{"top_patches", 8}});
  TextureIntervals r = readTextureIntervals(path);
  EXPECT_EQ(r.firstFrame, 10);
  EXPECT_EQ(r.lastFrame, 40);
  EXPECT_EQ(r.fps, 30.0);
  EXPECT_EQ(r.imageWidth, 352);
  EXPECT_EQ(r.imageHeight, 240);
  ASSERT_EQ(r.movies.size(), iv.movies.size());
  for (size_t i = 0; i < iv.movies.size(); ++i) {
    const MovieExtent &a = iv.movies[i], &b = r.movies[i];
    EXPECT_EQ(b.movie, i);
    EXPECT_EQ(b.patch, a.patch);
    EXPECT_EQ(b.firstFrame, a.firstFrame);
    EXPECT_EQ(b.lastFrame, a.lastFrame);
    EXPECT_EQ(b.width, a.width);
    EXPECT_EQ(b.height, a.height);
    EXPECT_EQ(b.end, a.end);
  }
  EXPECT_EQ(r.movies[1].level(), 2);
  ContainerReader reader = ContainerReader::open(path);
  EXPECT_EQ(reader.kind(), "intervals");
  EXPECT_EQ(reader.metadata().at("top_patches"), 8);
  EXPECT_EQ(reader.provenance().tool, "rad-intervals");
  nlohmann::json s = summarizeTextureIntervals(reader);
  EXPECT_EQ(s["movies"], 4);
  EXPECT_DOUBLE_EQ(s["mean_length_frames"].get<double>(), (11 + 31 + 5 + 1) / 4.0);
  EXPECT_EQ(s["close_reasons"]["resize"], 1);
  EXPECT_EQ(s["movies_per_level"]["0"], 2);
}

TEST(TextureIntervalsFormat, EmptyIsValid) {
  TextureIntervals iv = sample();
  iv.movies.clear();
  std::string path = tempPath("rad_fmt_iv_empty.rti");
  writeTextureIntervals(path, iv, provenance(), {});
  EXPECT_TRUE(readTextureIntervals(path).movies.empty());
}

TEST(TextureIntervalsFormat, TruncatedIsAnError) {
  std::string path = tempPath("rad_fmt_iv_cut.rti");
  writeTextureIntervals(path, sample(), provenance(), {});
  auto size = std::filesystem::file_size(path);
  for (auto cut : {size - 1, size / 2, uintmax_t(40), uintmax_t(10), uintmax_t(0)}) {
    std::filesystem::resize_file(path, cut);
    expectInputError([&] { readTextureIntervals(path); }, path + ": ");
  }
}

TEST(TextureIntervalsFormat, WrongKindAndFutureVersionAreRefused) {
  std::string path = tempPath("rad_fmt_iv_kind.rti");
  ContainerWriter other("linkhier", 1, 0);
  other.write(path);
  expectInputError([&] { readTextureIntervals(path); }, "expected intervals");
  ContainerWriter future("intervals", 2, 0);
  future.write(path);
  expectInputError([&] { readTextureIntervals(path); }, "intervals 2.0 is newer than supported");
}

// Containers that are valid as containers but not as intervals files.
TEST(TextureIntervalsFormat, InconsistentContentIsRejected) {
  std::string path = tempPath("rad_fmt_iv_bad.rti");
  auto write = [&](std::vector<int32_t> frames, std::vector<int32_t> size,
                   std::vector<uint8_t> reason, std::vector<uint64_t> patch) {
    ContainerWriter w("intervals", 1, 0);
    w.metadata() = {{"first_frame", 0},
                    {"last_frame", 9},
                    {"fps", 24.0},
                    {"image_width", 8},
                    {"image_height", 8}};
    w.addArray("movie_patch", patch);
    w.addArray("movie_frames", frames, {frames.size() / 2, 2});
    w.addArray("movie_size", size, {size.size() / 2, 2});
    w.addArray("movie_close_reason", reason);
    w.write(path);
  };
  uint64_t p = PatchId{1, 1}.packed();
  write({0, 9}, {4, 4}, {5}, {p});
  EXPECT_EQ(readTextureIntervals(path).movies.size(), 1u);
  write({0, 10}, {4, 4}, {5}, {p});
  expectInputError([&] { readTextureIntervals(path); }, "movie 0: frames outside the window");
  write({5, 4}, {4, 4}, {5}, {p});
  expectInputError([&] { readTextureIntervals(path); }, "movie 0: frames outside the window");
  write({0, 9}, {0, 4}, {5}, {p});
  expectInputError([&] { readTextureIntervals(path); }, "movie 0: invalid texture size");
  write({0, 9}, {4, 4}, {6}, {p});
  expectInputError([&] { readTextureIntervals(path); }, "movie 0: unknown close reason");
  write({0, 9}, {4, 4}, {5}, {uint64_t(1) << 32});
  expectInputError([&] { readTextureIntervals(path); }, "movie 0: invalid patch id");
  write({0, 9, 0, 9}, {4, 4}, {5}, {p});
  expectInputError([&] { readTextureIntervals(path); }, "movie arrays differ in length");
}

TEST(TextureIntervalsFormat, CloseReasonNames) {
  EXPECT_STREQ(movieEndName(MovieEnd::kLeftFrustum), "left_frustum");
  EXPECT_STREQ(movieEndName(MovieEnd::kHidden), "hidden");
  EXPECT_STREQ(movieEndName(MovieEnd::kLevelChange), "level_change");
  EXPECT_STREQ(movieEndName(MovieEnd::kResize), "resize");
  EXPECT_STREQ(movieEndName(MovieEnd::kMaxLength), "max_length");
  EXPECT_STREQ(movieEndName(MovieEnd::kWindow), "window");
}

}  // namespace
}  // namespace rad
