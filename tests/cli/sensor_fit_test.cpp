// The image follows the camera's aspect as Blender's sensor fit does (issue 57, docs/design.md
// §4 "Cameras"): a ball rendered at an aspect other than the camera's aspectRatio stays round in
// every stage that projects (rad-intervals' item buffers, rad-reference's rays); it became an
// ellipse, the camera's field stretched over the image. Where the aspects agree, the frames are
// those of the lens as written, bit for bit.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "formats/exr_image.h"
#include "formats/item_buffer_exr.h"
#include "tests/cli/cli_util.h"
#include "tests/cli/gltf_builder.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

// An emissive UV sphere of radius 0.5 at the origin (outward CCW faces), seen from 4 m along +z
// by a camera of yfov 0.9 and `aspectRatio` (absent when 0).
std::string writeBall(const fs::path& dir, const std::string& name, double aspectRatio) {
  const int rings = 16, segments = 32;
  std::vector<glm::vec3> pos;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      const double th = M_PI * i / rings, ph = 2.0 * M_PI * j / segments;
      pos.push_back({float(0.5 * std::sin(th) * std::cos(ph)), float(0.5 * std::cos(th)),
                     float(-0.5 * std::sin(th) * std::sin(ph))});
    }
  std::vector<uint32_t> idx;
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const uint32_t a = uint32_t(i * (segments + 1) + j), b = a + segments + 1;
      idx.insert(idx.end(), {a, a + 1, b, a + 1, b + 1, b});
    }
  GltfBuilder g;
  const int glow = g.addMaterial({{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}}},
                                  {"emissiveFactor", {1, 1, 1}}});
  g.addNode({{"name", "ball"}, {"mesh", g.addMesh("ball", pos, idx, glow)}});
  nlohmann::json lens = {{"yfov", 0.9}, {"znear", 0.1}};
  if (aspectRatio > 0.0) lens["aspectRatio"] = aspectRatio;
  g.addCamera(lens, {{"name", "camera"}, {"translation", {0, 0, 4}}});
  return g.write((dir / name).string());
}

struct Extent {
  int across = 0, up = 0;  // pixels covered by the ball's widest row and column
};

template <class Covered>
Extent extentOf(int width, int height, Covered covered) {
  Extent e;
  for (int r = 0; r < height; ++r) {
    int n = 0;
    for (int c = 0; c < width; ++c) n += covered(c, r) ? 1 : 0;
    e.across = std::max(e.across, n);
  }
  for (int c = 0; c < width; ++c) {
    int n = 0;
    for (int r = 0; r < height; ++r) n += covered(c, r) ? 1 : 0;
    e.up = std::max(e.up, n);
  }
  return e;
}

Extent itemBufferExtent(const fs::path& dir, const std::string& scene, const std::string& size) {
  const fs::path items = dir / ("items-" + fs::path(scene).stem().string() + "-" + size);
  CommandResult r = runCommand(tool("rad-intervals") + " " + scene + " -o " +
                               (dir / "i.rti").string() + " --frames 0-0 --size " + size +
                               " --pixel-filter none --item-buffers " + items.string());
  EXPECT_EQ(r.exitCode, 0) << r.err;
  const ItemBuffer b = readItemBufferExr((items / "0000.exr").string());
  return extentOf(b.width, b.height, [&](int c, int r) { return b.idAt(c, r) != kNoItem; });
}

FloatImage referenceFrame(const fs::path& dir, const std::string& scene, const std::string& size) {
  const fs::path out = dir / ("ref-" + fs::path(scene).stem().string() + "-" + size);
  CommandResult r = runCommand(tool("rad-reference") + " " + scene + " -o " + out.string() +
                               " --frames 0-0 --size " + size + " --spp 1 --pixel-filter none");
  EXPECT_EQ(r.exitCode, 0) << r.err;
  return readExrImage((out / "0000.exr").string());
}

Extent referenceExtent(const FloatImage& f) {
  return extentOf(f.width, f.height,
                  [&](int c, int r) { return f.pixels[3 * (size_t(r) * f.width + c)] > 0.5f; });
}

class SensorFit : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("rad_sensor_fit_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  fs::path dir;
};

TEST_F(SensorFit, BallStaysRoundAtAnotherAspectInEveryStage) {
  // A square camera rendered wide and tall, a wide camera rendered square.
  struct Case {
    double cameraAspect;
    std::string size;
  };
  for (const Case& c : {Case{1.0, "160x80"}, Case{1.0, "80x160"}, Case{2.0, "120x120"}}) {
    const std::string scene = writeBall(dir, "ball.gltf", c.cameraAspect);
    const Extent items = itemBufferExtent(dir, scene, c.size);
    EXPECT_GT(items.up, 10) << c.size;
    EXPECT_LE(std::abs(items.across - items.up), 1)
        << "camera aspect " << c.cameraAspect << " at " << c.size << ": " << items.across << " x "
        << items.up << " pixels";
    const Extent ref = referenceExtent(referenceFrame(dir, scene, c.size));
    EXPECT_LE(std::abs(ref.across - ref.up), 1)
        << "rad-reference, camera aspect " << c.cameraAspect << " at " << c.size << ": "
        << ref.across << " x " << ref.up << " pixels";
  }
}

TEST_F(SensorFit, AgreeingAspectsRenderAsTheLensIsWritten) {
  // aspectRatio 2 at 120x60 equals no aspectRatio (the image's): identical pixels.
  const FloatImage a = referenceFrame(dir, writeBall(dir, "given.gltf", 2.0), "120x60");
  const FloatImage b = referenceFrame(dir, writeBall(dir, "absent.gltf", 0.0), "120x60");
  EXPECT_EQ(a.pixels, b.pixels);
  // The horizontal field is the camera's: the ball spans 2 r / (2 d tan(yfov/2) aspect) of the
  // width, as before sensor fit.
  const double expected = 120.0 * 0.5 / (4.0 * std::tan(0.45) * 2.0);
  EXPECT_NEAR(referenceExtent(a).across, expected, 1.5);
}

}  // namespace
}  // namespace rad::test
