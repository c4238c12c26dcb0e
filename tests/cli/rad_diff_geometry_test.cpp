// rad-diff's figures that need an item buffer (docs/design.md §10.3 edge and interior pixels,
// §10.4 structured error, §10.5 seams), as a user runs them: on synthetic images and item
// buffers whose answers are known, and on a frame of a tiny scene made by the real tools.
//
// The scene: a floor of two coplanar unit quads of one material side by side (top-level patches
// 0 and 1, meeting along x = 1), a light quad facing it outside the view (patch 2), and a camera
// looking straight down at the seam.
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "formats/exr_image.h"
#include "formats/gltf_scene.h"
#include "formats/item_buffer_exr.h"
#include "tests/cli/cli_util.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

fs::path scratch() {
  return fs::temp_directory_path() / ("rad_diff_geometry_test_" + std::to_string(::getpid()));
}

struct ScratchCleanup {
  ~ScratchCleanup() {
    std::error_code ec;
    if (!std::getenv("RAD_KEEP_TEST_DIR")) fs::remove_all(scratch(), ec);
  }
} cleanupAtExit;

fs::path freshDir(const std::string& name) {
  const fs::path d = scratch() / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// Writes the scene (floor.gltf and floor.bin) into `dir`; returns the glTF's path.
std::string writeFloorScene(const fs::path& dir) {
  const float positions[30] = {0,    0,     0, 1,    0,     0, 2,    0,     0, 0,    1,     0,
                               1,    1,     0, 2,    1,     0,  // floor
                               1.6f, 0.25f, 1, 1.6f, 0.75f, 1, 2.1f, 0.75f, 1, 2.1f, 0.25f, 1};
  const uint16_t indices[18] = {0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4,  // quad 0, quad 1 (+z)
                                0, 1, 2, 0, 2, 3};                   // the light (-z)
  std::ofstream bin(dir / "floor.bin", std::ios::binary);
  bin.write(reinterpret_cast<const char*>(positions), sizeof positions);
  bin.write(reinterpret_cast<const char*>(indices), sizeof indices);
  bin.close();
  std::ofstream(dir / "floor.gltf") << R"({"asset": {"version": "2.0"}, "scene": 0,
    "scenes": [{"nodes": [0, 1, 2]}],
    "nodes": [{"name": "floor", "mesh": 0}, {"name": "lamp", "mesh": 1},
              {"name": "camera", "camera": 0, "translation": [1, 0.5, 1.4]}],
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 2, "material": 0}]},
               {"primitives": [{"attributes": {"POSITION": 1}, "indices": 3, "material": 1}]}],
    "materials": [{"name": "white", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1]}},
                  {"name": "light", "emissiveFactor": [1, 1, 1],
                   "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]}}],
    "buffers": [{"uri": "floor.bin", "byteLength": 156}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 72},
                    {"buffer": 0, "byteOffset": 72, "byteLength": 48},
                    {"buffer": 0, "byteOffset": 120, "byteLength": 24},
                    {"buffer": 0, "byteOffset": 144, "byteLength": 12}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 6,
                   "min": [0, 0, 0], "max": [2, 1, 0]},
                  {"bufferView": 1, "componentType": 5126, "type": "VEC3", "count": 4,
                   "min": [1.6, 0.25, 1], "max": [2.1, 0.75, 1]},
                  {"bufferView": 2, "componentType": 5123, "type": "SCALAR", "count": 12},
                  {"bufferView": 3, "componentType": 5123, "type": "SCALAR", "count": 6}]})";
  return (dir / "floor.gltf").string();
}

constexpr int W = 40, H = 40;

// A synthetic item buffer of the floor scene (T = 3 tops): rows 0-4 background, then patch 0
// (item 1) left of x = 20 and patch 1 right of it, seen through item 8: node 7, a child of
// patch 1 ((7 - 3) / 4 = 1), as rad-intervals writes a subdivided patch.
std::string writeItems(const fs::path& dir) {
  ItemBuffer b;
  b.width = W;
  b.height = H;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      b.id.push_back(y < 5 ? kNoItem : x < 20 ? 1 : 8);
      b.depth.push_back(y < 5 ? std::numeric_limits<float>::infinity() : 1.4f);
    }
  const std::string path = (dir / "items.exr").string();
  writeItemBufferExr(path, b, 0, 0.0);
  return path;
}

// Grey `left` left of x = 20 and `right` from it on, black in the background rows 0-4, plus
// `blotch` in the 16 x 16 square x 22..37, y 16..31 (on patch 1, clear of every edge).
std::string writeImage(const fs::path& path, float left, float right, float blotch = 0.0f) {
  FloatImage im(W, H, {"R", "G", "B"});
  for (int y = 5; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const bool inBlotch = x >= 22 && x < 38 && y >= 16 && y < 32;
      for (int c = 0; c < 3; ++c)
        im.at(x, y, c) = (x < 20 ? left : right) + (inBlotch ? blotch : 0.0f);
    }
  writeExrImage(path.string(), im);
  return path.string();
}

// A step of known size along a known seam is reported with that size: the test steps from
// 0.55 to 0.45 (0.2 of the local mean 0.5), the reference from 0.51 to 0.49 (0.04).
TEST(RadDiffGeometry, AKnownStepAlongAKnownSeam) {
  const fs::path d = freshDir("seam");
  const std::string scene = writeFloorScene(d), items = writeItems(d);
  ASSERT_EQ(readGltfScene(scene).inputPolygons().size(), 3u);
  const std::string test = writeImage(d / "test.exr", 0.55f, 0.45f);
  const std::string ref = writeImage(d / "ref.exr", 0.51f, 0.49f);
  CommandResult r = runCommand(tool("rad-diff") + " " + test + " " + ref + " --seams " + items +
                               " --scene " + scene + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json seams = nlohmann::json::parse(r.out)["seams"];
  EXPECT_EQ(seams["seams_found"].get<int>(), 1);
  EXPECT_EQ(seams["seams_measured"].get<int>(), 1);
  // Rows 6..39: row 5 borders the background, so its pixels are edges and make no pair.
  EXPECT_EQ(seams["pairs"].get<int>(), H - 6);
  ASSERT_EQ(seams["seams"].size(), 1u);
  const nlohmann::json& seam = seams["seams"][0];
  EXPECT_EQ(seam["patches"], nlohmann::json({0, 1}));
  EXPECT_EQ(seam["surface"], "floor (white)");
  EXPECT_EQ(seam["pixel"], nlohmann::json({19, 6}));
  EXPECT_NEAR(seam["step_test"].get<double>(), 0.2, 1e-6);
  EXPECT_NEAR(seam["step_reference"].get<double>(), 0.04, 1e-6);
  EXPECT_NEAR(seam["excess"].get<double>(), 0.16, 1e-6);
  EXPECT_NEAR(seams["test"]["max_abs_step"].get<double>(), 0.2, 1e-6);
  EXPECT_NEAR(seams["reference"]["mean_abs_step"].get<double>(), 0.04, 1e-6);
  EXPECT_NEAR(seams["excess"]["max_abs"].get<double>(), 0.16, 1e-6);
  // The text names the seam and its figures.
  r = runCommand(tool("rad-diff") + " " + test + " " + ref + " --seams " + items + " --scene " +
                 scene);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("1 of 1 seam(s) with >= 32 pixel pairs, 34 pairs"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("patches 0|1 floor (white) at (19, 6): 34 pairs, step test 0.2"),
            std::string::npos)
      << r.out;
  // A seam shorter than --seam-min-pairs is found and left out of the summary.
  r = runCommand(tool("rad-diff") + " " + test + " " + ref + " --seams " + items + " --scene " +
                 scene + " --seam-min-pairs 35 --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["seams"]["seams_measured"].get<int>(), 0);
}

// Edge and interior pixels, and the structured error of a blotch of known amplitude: the test
// is the reference plus 0.03 over a 16 x 16 square, whose 10 x 10 centre (more than 5 % of
// the pixels clear of edges) reads 0.03 / mean(Y(ref)) and no pixel reads more.
TEST(RadDiffGeometry, RegionsAndTheStructuredErrorOfABlotch) {
  const fs::path d = freshDir("blotch");
  const std::string scene = writeFloorScene(d), items = writeItems(d);
  const std::string test = writeImage(d / "test.exr", 0.51f, 0.49f, 0.03f);
  const std::string ref = writeImage(d / "ref.exr", 0.51f, 0.49f);
  CommandResult r = runCommand(tool("rad-diff") + " " + test + " " + ref + " --surfaces " + items +
                               " --scene " + scene + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out)["difference"];
  // Rows 4 and 5 are edges (background beside the floor); the seam is none.
  EXPECT_EQ(j["regions"]["edge"]["pixels"].get<int>(), 2 * W);
  EXPECT_EQ(j["regions"]["interior"]["pixels"].get<int>(), (H - 6) * W);
  EXPECT_EQ(j["regions"]["background"]["pixels"].get<int>(), 4 * W);
  EXPECT_NEAR(j["regions"]["edge"]["rmse_over_mean"].get<double>(), 0.0, 1e-12);
  EXPECT_GT(j["regions"]["interior"]["rmse_over_mean"].get<double>(), 0.0);
  // The mean is over every non-emitter pixel, background included (as the figure's):
  // 35 rows of 0.5 in 40.
  const double mean = 0.5 * 35.0 / 40.0;
  const nlohmann::json& structured = j["structured_error"];
  EXPECT_NEAR(structured["mean_reference_luminance"].get<double>(), mean, 1e-6);
  EXPECT_NEAR(structured["p95"].get<double>(), 0.03 / mean, 1e-5);
  EXPECT_EQ(structured["pixels"].get<int>(), (H - 8) * W);  // rows 8..39: >= 3 from row 5
  EXPECT_FALSE(j.contains("structured_error_unavailable"));
  // --smoothed-error writes the smoothed difference image: the blotch's centre reads p95.
  r = runCommand(tool("rad-diff") + " " + test + " " + ref + " --surfaces " + items + " --scene " +
                 scene + " --smoothed-error " + (d / "smoothed.exr").string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const FloatImage smoothed = readExrImage((d / "smoothed.exr").string(), {"Y"});
  EXPECT_NEAR(smoothed.at(30, 24, 0), 0.03 / mean, 1e-5);
  EXPECT_EQ(smoothed.at(30, 6, 0), 0.0f);  // within 3 px of an edge: not measured
}

// Without an item buffer the structured error says it was not computed; the item-buffer
// options are checked before anything is read.
TEST(RadDiffGeometry, WithoutAnItemBufferTheStructuredErrorIsNotComputed) {
  const fs::path d = freshDir("plain");
  const std::string scene = writeFloorScene(d), items = writeItems(d);
  const std::string test = writeImage(d / "test.exr", 0.51f, 0.49f, 0.03f);
  const std::string ref = writeImage(d / "ref.exr", 0.51f, 0.49f);
  CommandResult r = runCommand(tool("rad-diff") + " " + test + " " + ref + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out)["difference"];
  EXPECT_TRUE(j["structured_error"].is_null());
  EXPECT_NE(j["structured_error_unavailable"].get<std::string>().find("needs an item buffer"),
            std::string::npos);
  EXPECT_FALSE(j.contains("regions"));
  r = runCommand(tool("rad-diff") + " " + test + " " + ref);
  EXPECT_NE(r.out.find("structured error: not computed: needs an item buffer"), std::string::npos)
      << r.out;
  for (const std::string& args :
       {" --seams " + items, " --scene " + scene, " --smoothed-error " + (d / "s.exr").string(),
        " --seams " + items + " --surfaces " + ref + " --scene " + scene}) {
    r = runCommand(tool("rad-diff") + " " + test + " " + ref + args);
    EXPECT_EQ(r.exitCode, 2) << args << ": " << r.err;
    EXPECT_EQ(countLines(r.err), 1) << r.err;
  }
  // An item buffer of another size is named.
  const std::string small = (d / "small.exr").string();
  writeExrImage(small, FloatImage(4, 3, {"R", "G", "B"}));
  r = runCommand(tool("rad-diff") + " " + small + " " + small + " --seams " + items + " --scene " +
                 scene);
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_EQ(r.err, "rad-diff: " + items + ": item buffer is 40x40, the images 4x3\n");
}

// Through the real tools: a frame of the floor scene, its item buffer from rad-intervals. The
// pipeline's seam is whatever it is; a copy of the frame with patch 1 made 10 % brighter has a
// step 0.1 x 2 B / (A + B) larger, which is -0.1 within the frame's own small step.
TEST(RadDiffGeometry, TheRealPipelinesSeam) {
  const fs::path d = freshDir("pipeline");
  const std::string scene = writeFloorScene(d), s = d.string();
  for (const std::string& command :
       {tool("rad-global") + " " + scene + " -o " + s + "/global.rlh --frames 0-0",
        tool("rad-intervals") + " " + scene + " -o " + s + "/intervals.rti --frames 0-0" +
            " --size 88x60 --item-buffers " + s + "/items",
        tool("rad-movies") + " " + scene + " " + s + "/global.rlh " + s + "/intervals.rti -o " + s +
            "/movies",
        tool("rad-compose") + " " + scene + " " + s + "/global.rlh " + s + "/intervals.rti " + s +
            "/movies -o " + s + "/frames --frames 0-0 --no-png"}) {
    const CommandResult r = runCommand(command);
    ASSERT_EQ(r.exitCode, 0) << command << ": " << r.err;
  }
  const std::string frame = s + "/frames/0000.exr", items = s + "/items/0000.exr";
  CommandResult r = runCommand(tool("rad-diff") + " " + frame + " " + frame + " --seams " + items +
                               " --scene " + scene + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["seams"]["seams_measured"].get<int>(), 1) << j["seams"].dump();
  const nlohmann::json seam = j["seams"]["seams"][0];
  EXPECT_EQ(seam["patches"], nlohmann::json({0, 1}));
  EXPECT_GE(seam["pairs"].get<int>(), 40);  // the floor's rows in view
  EXPECT_EQ(seam["excess"].get<double>(), 0.0);
  EXPECT_GT(j["difference"]["regions"]["edge"]["pixels"].get<int>(), 0);
  EXPECT_GT(j["difference"]["regions"]["background"]["pixels"].get<int>(), 0);
  EXPECT_EQ(j["difference"]["structured_error"]["p95"].get<double>(), 0.0);
  const double ownStep = seam["step_test"].get<double>();
  // Patch 1 made 10 % brighter, as the item buffer places it.
  FloatImage brighter = readExrImage(frame);
  const ItemBuffer ids = readItemBufferExr(items);
  for (size_t p = 0; p < ids.id.size(); ++p) {
    uint64_t node = ids.id[p] == kNoItem ? 0 : ids.id[p] - 1;
    while (node >= 3) node = (node - 3) / 4;
    if (ids.id[p] != kNoItem && node == 1)
      for (size_t c = 0; c < 3; ++c) brighter.pixels[3 * p + c] *= 1.1f;
  }
  writeExrImage(s + "/brighter.exr", brighter);
  r = runCommand(tool("rad-diff") + " " + s + "/brighter.exr " + frame + " --seams " + items +
                 " --scene " + scene + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  j = nlohmann::json::parse(r.out)["seams"]["seams"][0];
  EXPECT_NEAR(j["excess"].get<double>(), -0.1, 0.01 + std::abs(ownStep));
  EXPECT_NEAR(j["step_reference"].get<double>(), ownStep, 1e-12);
}

}  // namespace
}  // namespace rad::test
