// rad-diff as a user runs it: two EXR files or two frame directories, text and --json output,
// the one-line error on a size mismatch, and every part's pixel checksum verified.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "formats/exr_image.h"
#include "formats/gltf_scene.h"
#include "formats/item_buffer_exr.h"
#include "formats/texture_movie.h"
#include "tests/cli/cli_util.h"
#include "tests/format/exr_layout.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

// Removes this process's scratch directory when the test program ends.
struct TempRootCleanup {
  ~TempRootCleanup() {
    std::error_code ec;
    fs::remove_all(fs::temp_directory_path() / ("rad_diff_test_" + std::to_string(::getpid())), ec);
  }
} cleanupAtExit;

fs::path freshDir(const std::string& name) {
  fs::path d = fs::temp_directory_path() / ("rad_diff_test_" + std::to_string(::getpid())) / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

FloatImage constant(int w, int h, float value) {
  FloatImage im(w, h, {"R", "G", "B"});
  for (float& v : im.pixels) v = value;
  return im;
}

TEST(RadDiff, TwoFilesJson) {
  fs::path d = freshDir("files");
  writeExrImage((d / "a.exr").string(), constant(5, 3, 1.25f));
  writeExrImage((d / "b.exr").string(), constant(5, 3, 1.0f));
  CommandResult r = runCommand(tool("rad-diff") + " " + (d / "a.exr").string() + " " +
                               (d / "b.exr").string() + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_DOUBLE_EQ(j["difference"]["rmse"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(j["difference"]["relative_l2"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(j["difference"]["max_abs"].get<double>(), 0.25);
  EXPECT_NEAR(j["difference"]["psnr_db"].get<double>(), 20.0 * std::log10(4.0), 1e-12);
  EXPECT_EQ(j["difference"]["samples"].get<int>(), 45);

  // Identical: zero error, infinite PSNR (null in JSON, "inf" in text).
  r = runCommand(tool("rad-diff") + " " + (d / "a.exr").string() + " " + (d / "a.exr").string() +
                 " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["difference"]["rmse"].get<double>(), 0.0);
  EXPECT_TRUE(j["difference"]["psnr_db"].is_null());
  r = runCommand(tool("rad-diff") + " " + (d / "a.exr").string() + " " + (d / "a.exr").string());
  EXPECT_NE(r.out.find("psnr inf"), std::string::npos) << r.out;

  // One channel only.
  FloatImage g = constant(5, 3, 1.0f);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) g.at(x, y, 1) = 3.0f;
  writeExrImage((d / "g.exr").string(), g);
  r = runCommand(tool("rad-diff") + " " + (d / "g.exr").string() + " " + (d / "b.exr").string() +
                 " --json --channels R,B");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["difference"]["rmse"].get<double>(), 0.0);
}

TEST(RadDiff, SizeMismatchIsOneLineExit1) {
  fs::path d = freshDir("mismatch");
  writeExrImage((d / "a.exr").string(), constant(5, 3, 1.0f));
  writeExrImage((d / "b.exr").string(), constant(4, 3, 1.0f));
  CommandResult r =
      runCommand(tool("rad-diff") + " " + (d / "a.exr").string() + " " + (d / "b.exr").string());
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_EQ(countLines(r.err), 1) << r.err;
  EXPECT_EQ(r.err, "rad-diff: " + (d / "a.exr").string() +
                       ": size 5x3 differs from the reference's 4x3\n");
  // A missing channel names the channels the file has.
  r = runCommand(tool("rad-diff") + " " + (d / "a.exr").string() + " " + (d / "a.exr").string() +
                 " --channels Z");
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.err.find("no channel 'Z' (channels: B,G,R)"), std::string::npos) << r.err;
}

TEST(RadDiff, DirectoriesMatchFramesByNameAndMeasureFlicker) {
  fs::path test = freshDir("seq/test"), ref = freshDir("seq/ref");
  // Reference static everywhere; test alternates 1, 1.5, 1, 1.5: flicker exactly 0.5.
  for (int f = 1; f <= 4; ++f) {
    char name[16];
    std::snprintf(name, sizeof name, "%04d.exr", f);
    writeExrImage((ref / name).string(), constant(3, 2, 1.0f));
    writeExrImage((test / name).string(), constant(3, 2, f % 2 ? 1.0f : 1.5f));
  }
  writeExrImage((test / "0005.exr").string(), constant(3, 2, 1.0f));  // no reference: skipped
  writeExrImage((ref / "other.exr").string(), constant(9, 9, 1.0f));  // not a frame name
  CommandResult r =
      runCommand(tool("rad-diff") + " " + test.string() + " " + ref.string() + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["frames_compared"].get<int>(), 4);
  EXPECT_EQ(j["frames_only_in_test"].get<int>(), 1);
  EXPECT_DOUBLE_EQ(j["flicker"]["mean_abs"].get<double>(), 0.5);
  EXPECT_EQ(j["flicker"]["frame_pairs"].get<int>(), 3);
  EXPECT_EQ(j["flicker"]["static_pixels"].get<int>(), 3 * 6);
  EXPECT_DOUBLE_EQ(j["difference"]["rmse"].get<double>(), std::sqrt(0.125));
  ASSERT_EQ(j["per_frame"].size(), 4u);
  EXPECT_EQ(j["per_frame"][1]["rmse"].get<double>(), 0.5);

  r = runCommand(tool("rad-diff") + " " + test.string() + " " + ref.string());
  EXPECT_EQ(r.exitCode, 0);
  EXPECT_NE(r.out.find("flicker: mean |test(n+1)-test(n)| 0.5"), std::string::npos) << r.out;

  // File against directory is a usage error.
  r = runCommand(tool("rad-diff") + " " + (test / "0001.exr").string() + " " + ref.string());
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(countLines(r.err), 1);
}

// A 10x10 room: walls of radiance `wall` (grey), a 2x2 light of 100 at x 4-5, y 0-1. With
// `noise`, wall pixel (x, y) gets noise * a or noise * b, a and b = +-1 by the parity of x and
// of y: over the walls (24 pixels of each of the four (a, b)), mean a = mean b = mean ab = 0,
// so two references made with a and with b have independent noise of sigma = noise exactly.
FloatImage room(float wall, float noise, bool useB) {
  FloatImage im(10, 10, {"R", "G", "B"});
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 10; ++x) {
      const bool light = x >= 4 && x < 6 && y < 2;
      const float sign = (useB ? y % 2 : x % 2) ? 1.0f : -1.0f;
      for (int c = 0; c < 3; ++c) im.at(x, y, c) = light ? 100.0f : wall + noise * sign;
    }
  return im;
}

// docs/design.md §10 figures in --json, with values in closed form (binary fractions, exact in
// float): the walls 12.5 % too dark, the light right.
TEST(RadDiff, JsonLeadsWithTheNonEmitterFigure) {
  fs::path d = freshDir("honest");
  const std::string t = (d / "t.exr").string(), r1 = (d / "r1.exr").string(),
                    r2 = (d / "r2.exr").string(), small = (d / "small.exr").string();
  writeExrImage(t, room(0.875f, 0.0f, false));
  writeExrImage(r1, room(1.0f, 0.125f, false));
  writeExrImage(r2, room(1.0f, 0.125f, true));
  writeExrImage(small, constant(4, 3, 1.0f));

  // One reference: its noise (sigma 0.125) adds to the error: sqrt(0.125^2 + 0.125^2).
  CommandResult r = runCommand(tool("rad-diff") + " " + t + " " + r1 + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out)["difference"];
  EXPECT_DOUBLE_EQ(j["rmse_over_mean"].get<double>(), 0.125 * std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(j["bias"].get<double>(), -0.125);
  EXPECT_EQ(j["emitter_pixels"].get<int>(), 4);
  EXPECT_EQ(j["surface_pixels"].get<int>(), 96);
  EXPECT_EQ(j["emitter_rmse_over_mean"].get<double>(), 0.0);
  EXPECT_FALSE(j.contains("noise_over_mean"));
  // The old figure, over every sample and divided by the reference RMS, reads under 1 %.
  EXPECT_NEAR(j["relative_l2"].get<double>(), std::sqrt(9.0 / (292.5 + 120000.0)), 1e-12);
  EXPECT_DOUBLE_EQ(j["rmse"].get<double>(), std::sqrt(9.0 / 300.0));

  // Two references: their noise is removed and the error of the walls comes out exactly.
  r = runCommand(tool("rad-diff") + " " + t + " " + r1 + " --ref2 " + r2 + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  j = nlohmann::json::parse(r.out)["difference"];
  EXPECT_DOUBLE_EQ(j["rmse_over_mean"].get<double>(), 0.125);
  EXPECT_DOUBLE_EQ(j["noise_over_mean"].get<double>(), 0.125);
  EXPECT_DOUBLE_EQ(j["raw_rmse_over_mean"].get<double>(), 0.125 * std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(j["bias"].get<double>(), -0.125);
  EXPECT_EQ(j["emitter_pixels"].get<int>(), 4);

  // An absolute threshold above the light makes every pixel a surface.
  r = runCommand(tool("rad-diff") + " " + t + " " + r1 + " --emitter-threshold 1000 --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["difference"]["emitter_pixels"].get<int>(), 0);

  // The text leads with the figure and labels the relative L2.
  r = runCommand(tool("rad-diff") + " " + t + " " + r1 + " --ref2 " + r2);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("rmse/mean 0.125  bias -0.125  (noise/mean 0.125"), std::string::npos)
      << r.out;
  EXPECT_LT(r.out.find("rmse/mean"), r.out.find("relative L2"));
  EXPECT_NE(r.out.find("relative L2 (normalised by the reference RMS; dominated by visible "
                       "emitters)"),
            std::string::npos);

  // A second reference of another size: one line, exit 1.
  r = runCommand(tool("rad-diff") + " " + t + " " + r1 + " --ref2 " + small);
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_EQ(countLines(r.err), 1) << r.err;
  EXPECT_EQ(r.err, "rad-diff: " + small + ": size 4x3 differs from the reference's 10x10\n");
  // An emitter mask (one channel, > 0.5) replaces the luminance rule: here it marks the light
  // and the first wall row as emitters, so 4 + 8 pixels are left out of the figure.
  FloatImage mask(10, 10, {"Y"});
  for (int x = 0; x < 10; ++x) mask.at(x, 9, 0) = 1.0f;
  for (int y = 0; y < 2; ++y)
    for (int x = 4; x < 6; ++x) mask.at(x, y, 0) = 0.75f;
  mask.at(0, 9, 0) = mask.at(9, 9, 0) = 0.5f;  // not above 0.5: a surface
  const std::string m = (d / "mask.exr").string();
  writeExrImage(m, mask);
  r = runCommand(tool("rad-diff") + " " + t + " " + r1 + " --emitter-mask " + m + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["difference"]["emitter_pixels"].get<int>(), 4 + 8);
  EXPECT_EQ(j["difference"]["surface_pixels"].get<int>(), 88);
  EXPECT_TRUE(j["difference"]["emitter_threshold"].is_null());
  EXPECT_EQ(j["emitter_mask"].get<std::string>(), m);
  r = runCommand(tool("rad-diff") + " " + t + " " + r1 + " --emitter-mask " + small);
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_EQ(r.err, "rad-diff: " + small + ": size 4x3 differs from the reference's 10x10\n");
  r = runCommand(tool("rad-diff") + " " + t + " " + r1 + " --emitter-mask " + m +
                 " --emitter-threshold 3");
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(countLines(r.err), 1) << r.err;

  // A negative threshold is a usage error.
  r = runCommand(tool("rad-diff") + " " + t + " " + r1 + " --emitter-threshold -1");
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(countLines(r.err), 1) << r.err;
}

// Directories with --ref2: per-frame and pooled figures; a frame missing from the second
// reference is named.
TEST(RadDiff, DirectoriesWithSecondReference) {
  fs::path test = freshDir("seq2/test"), ref = freshDir("seq2/ref"), ref2 = freshDir("seq2/ref2");
  for (int f = 1; f <= 2; ++f) {
    char name[16];
    std::snprintf(name, sizeof name, "%04d.exr", f);
    writeExrImage((test / name).string(), room(0.875f, 0.0f, false));
    writeExrImage((ref / name).string(), room(1.0f, 0.125f, false));
    writeExrImage((ref2 / name).string(), room(1.0f, 0.125f, true));
  }
  CommandResult r = runCommand(tool("rad-diff") + " " + test.string() + " " + ref.string() +
                               " --ref2 " + ref2.string() + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_DOUBLE_EQ(j["difference"]["rmse_over_mean"].get<double>(), 0.125);
  EXPECT_DOUBLE_EQ(j["difference"]["bias"].get<double>(), -0.125);
  EXPECT_EQ(j["difference"]["emitter_pixels"].get<int>(), 8);
  ASSERT_EQ(j["per_frame"].size(), 2u);
  EXPECT_DOUBLE_EQ(j["per_frame"][1]["noise_over_mean"].get<double>(), 0.125);
  EXPECT_EQ(j["per_frame"][1]["emitter_pixels"].get<int>(), 4);

  // A folder of masks, one per frame: here every pixel of frame 1 is marked, none of frame 2.
  fs::path masks = freshDir("seq2/masks");
  FloatImage all(10, 10, {"A"}), none(10, 10, {"A"});
  for (float& v : all.pixels) v = 1.0f;
  writeExrImage((masks / "0001.exr").string(), all);
  writeExrImage((masks / "0002.exr").string(), none);
  r = runCommand(tool("rad-diff") + " " + test.string() + " " + ref.string() + " --ref2 " +
                 ref2.string() + " --emitter-mask " + masks.string() + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["per_frame"][0]["emitter_pixels"].get<int>(), 100);
  EXPECT_EQ(j["per_frame"][1]["emitter_pixels"].get<int>(), 0);
  EXPECT_EQ(j["difference"]["emitter_pixels"].get<int>(), 100);
  EXPECT_EQ(j["difference"]["surface_pixels"].get<int>(), 100);

  fs::remove(ref2 / "0002.exr");
  r = runCommand(tool("rad-diff") + " " + test.string() + " " + ref.string() + " --ref2 " +
                 ref2.string());
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_EQ(countLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(ref2.string() + ": no frame 2"), std::string::npos) << r.err;
}

// --surfaces: the figures per glTF node and material seen in rad-intervals' item buffer. A
// test frame 50 % too bright on the red wall alone and exact elsewhere reads bias +0.5 there
// and 0 on every other surface, and the groups' pixels add up to the covered pixels.
// rad-diff compares the first part of a file; a multi-part file's other parts are read and
// checked against their rad.pixelChecksum too (before: part 0's only, so a corrupted byte in
// part 1 passed).
TEST(RadDiff, VerifiesTheChecksumOfEveryPart) {
  fs::path d = freshDir("parts");
  TextureMovie m;
  m.movie = 1;
  m.patch = PatchId{0, 1};
  m.firstFrame = 0;
  m.lastFrame = 1;
  m.width = 4;
  m.height = 3;
  for (int k = 0; k < 2; ++k) {
    m.keyFrames.push_back(k);
    m.keyTimes.push_back(k / 24.0);
    m.keys.emplace_back(size_t(m.width) * m.height * 3, 0.5f + float(k));
  }
  const std::string file = (d / "movie.exr").string();
  writeTextureMovie(file, m);
  CommandResult r = runCommand(tool("rad-diff") + " " + file + " " + file + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const Layout layout = layoutOf(file);
  ASSERT_EQ(layout.pixelData.size(), 6u);  // 3 scan lines a part, one chunk each
  {
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(std::streamoff(layout.pixelData[4].first + 1));  // part 1, line 1
    f.put(char(0x7f));
  }
  r = runCommand(tool("rad-diff") + " " + file + " " + file + " --json");
  EXPECT_EQ(r.exitCode, 1) << r.out;
  EXPECT_EQ(countLines(r.err), 1) << r.err;
  EXPECT_EQ(r.err.rfind("rad-diff: " + file + ": part 1: pixel checksum mismatch", 0), 0u) << r.err;
}

TEST(RadDiff, PerSurfaceBiasNamesTheWrongSurface) {
  const std::string scene = RAD_SOURCE_DIR "/pipelines/scenes/cornell-moving.gltf";
  fs::path d = freshDir("surfaces");
  CommandResult r =
      runCommand(tool("rad-intervals") + " " + scene + " -o " + (d / "i.rti").string() +
                 " --frames 0-0 --size 88x60 --item-buffers " + (d / "items").string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const ItemBuffer items = readItemBufferExr((d / "items" / "0000.exr").string());
  const Scene sc = readGltfScene(scene);
  const uint64_t T = sc.inputPolygons().size();
  FloatImage ref = constant(88, 60, 0.1f), test = ref;
  long long red = 0, covered = 0;
  for (size_t p = 0; p < items.id.size(); ++p) {
    if (items.id[p] == 0) continue;
    ++covered;
    uint64_t node = items.id[p] - 1;  // formats/texture_intervals.md: parent of j >= T is (j-T)/4
    while (node >= T) node = (node - T) / 4;
    const InputPolygon& top = sc.inputPolygons()[size_t(node)];
    if (sc.nodes[size_t(top.node)].name != "red_wall") continue;
    ++red;
    for (int c = 0; c < 3; ++c) test.pixels[3 * p + size_t(c)] = 0.15f;
  }
  ASSERT_GT(red, 0);
  writeExrImage((d / "test.exr").string(), test);
  writeExrImage((d / "ref.exr").string(), ref);
  r = runCommand(tool("rad-diff") + " " + (d / "test.exr").string() + " " +
                 (d / "ref.exr").string() + " --surfaces " + (d / "items" / "0000.exr").string() +
                 " --scene " + scene + " --emitter-threshold 1 --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  long long pixels = 0;
  bool sawRed = false;
  for (const nlohmann::json& g : j["per_surface"]) {
    pixels += g["pixels"].get<long long>();
    if (g["surface"] == "red_wall (red)") {
      sawRed = true;
      EXPECT_EQ(g["pixels"].get<long long>(), red);
      EXPECT_NEAR(g["bias"].get<double>(), 0.5, 1e-6);
    } else {
      EXPECT_EQ(g["bias"].get<double>(), 0.0) << g["surface"];
    }
  }
  EXPECT_TRUE(sawRed);
  EXPECT_EQ(pixels, covered);
  // --surfaces without --scene is a usage error, one line.
  r = runCommand(tool("rad-diff") + " " + (d / "test.exr").string() + " " +
                 (d / "ref.exr").string() + " --surfaces " + (d / "items" / "0000.exr").string());
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_NE(r.err.find("--surfaces and --scene go together"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace rad::test
