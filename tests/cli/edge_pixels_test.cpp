// Pixels at a polygon's border through the real tools (issue 56, "correct edge pixels"): a
// floor lit by a lamp strip that hangs just above and beyond one of its edges, so the irradiance
// is steepest at that border, and nothing else reflects (the lamp's reflectance is 0), so every
// floor point's radiance is known in closed form:
//   $L(x) = \frac{\rho}{\pi} \pi L_e F(dA_x \to \text{lamp})$
// with the exact point-to-polygon form factor. The four stages run at the defaults and each
// floor pixel is compared with L at the point its centre's ray meets (the sampling of
// rad-compose and rad-reference with --pixel-filter none). rad-movies bakes texels at their centres
// ((i+.5)/w); the outer half texel at the border lies beyond every texel centre, so the lookup
// there extrapolates from the last two texels. The camera is turned 7 degrees about its axis so
// that along the edge the pixel centres fall at every distance from it. Held flat
// (clamp-to-edge), the border pixels were several times further off than the pixels inside.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "formats/frame_image.h"
#include "formats/gltf_scene.h"
#include "libcommon/radiosity/form_factor.h"
#include "libcommon/scene/camera_projection.h"
#include "tests/cli/cli_util.h"

namespace rad {
namespace {

namespace fs = std::filesystem;
using test::runCommand;
using test::tool;

constexpr double kPi = 3.14159265358979323846;
constexpr double kFloorRho = 0.5;
constexpr double kLampRadiance = 10.0;  // emissiveFactor 1 x emissiveStrength 10
const ImageSize kSize{88, 60};

std::vector<glm::dvec3> floorCorners() {
  return {{-0.5, 0, -0.5}, {-0.5, 0, 0.5}, {0.5, 0, 0.5}, {0.5, 0, -0.5}};
}
std::vector<glm::dvec3> lampCorners() {
  return {{0.5, 0.05, -0.45}, {0.54, 0.05, -0.45}, {0.54, 0.05, 0.45}, {0.5, 0.05, 0.45}};
}

std::string base64(const std::string& bytes) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    unsigned v = (unsigned char)bytes[i] << 16;
    if (i + 1 < bytes.size()) v |= (unsigned char)bytes[i + 1] << 8;
    if (i + 2 < bytes.size()) v |= (unsigned char)bytes[i + 2];
    out += k[(v >> 18) & 63];
    out += k[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? k[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? k[v & 63] : '=';
  }
  return out;
}

std::string base64Buffer() {
  std::vector<float> pos;
  for (const auto& list : {floorCorners(), lampCorners()})
    for (const glm::dvec3& v : list) pos.insert(pos.end(), {float(v.x), float(v.y), float(v.z)});
  const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
  std::string bin(reinterpret_cast<const char*>(pos.data()), pos.size() * sizeof(float));
  bin += std::string(reinterpret_cast<const char*>(idx), sizeof idx);
  return base64(bin);
}

// Floor [-0.5, 0.5]^2 at y = 0 facing up; a lamp strip 4 cm x 90 cm, 5 cm above it, facing
// down, from the floor's +x edge outwards; a camera 1.2 m above the floor's centre looking down,
// turned 7 degrees about the vertical.
std::string writeScene(const fs::path& dir) {
  const std::string gltf = R"({
  "asset": {"version": "2.0"},
  "extensionsUsed": ["KHR_materials_emissive_strength"],
  "scene": 0,
  "scenes": [{"nodes": [0, 1, 2]}],
  "nodes": [
    {"name": "floor", "mesh": 0},
    {"name": "lamp", "mesh": 1},
    {"name": "camera", "camera": 0, "translation": [0, 1.2, 0],
     "rotation": [-0.70578788450236973, 0.043167836286632337, 0.04316783628663233, 0.70578788450236984]}
  ],
  "cameras": [{"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.01}}],
  "materials": [
    {"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}},
    {"name": "lamp", "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]},
     "emissiveFactor": [1, 1, 1],
     "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 10}}}
  ],
  "meshes": [
    {"primitives": [{"attributes": {"POSITION": 0}, "indices": 2, "material": 0}]},
    {"primitives": [{"attributes": {"POSITION": 1}, "indices": 2, "material": 1}]}
  ],
  "buffers": [{"uri": "data:application/octet-stream;base64,)" +
                           base64Buffer() + R"(", "byteLength": 108}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 48},
    {"buffer": 0, "byteOffset": 48, "byteLength": 48},
    {"buffer": 0, "byteOffset": 96, "byteLength": 12}
  ],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
     "min": [-0.5, 0, -0.5], "max": [0.5, 0, 0.5]},
    {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3",
     "min": [0.5, 0.05, -0.45], "max": [0.54, 0.05, 0.45]},
    {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}
  ]
})";
  fs::create_directories(dir);
  const std::string path = (dir / "edge.gltf").string();
  std::ofstream(path) << gltf;
  return path;
}

class EdgePixels : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("rad_edge_pixels_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    scenePath = writeScene(dir);
  }
  void TearDown() override {
    if (!std::getenv("RAD_KEEP_TEST_DIR")) fs::remove_all(dir);
  }
  // Runs the four stages at their defaults but for the pixel filter: none, one sample through
  // each pixel centre (rad-compose takes rad-intervals'), which the closed form is evaluated at;
  // the frame's path.
  std::string render() const {
    const std::string d = dir.string(), size = " --size 88x60 --pixel-filter none";
    for (const std::string& cmd :
         {tool("rad-global") + " " + scenePath + " -o " + d + "/global.rlh",
          tool("rad-intervals") + " " + scenePath + " -o " + d + "/intervals.rti" + size,
          tool("rad-movies") + " " + scenePath + " " + d + "/global.rlh " + d +
              "/intervals.rti -o " + d + "/movies",
          tool("rad-compose") + " " + scenePath + " " + d + "/global.rlh " + d + "/intervals.rti " +
              d + "/movies -o " + d + "/frames"}) {
      const test::CommandResult r = runCommand(cmd);
      EXPECT_EQ(r.exitCode, 0) << cmd << "\n" << r.err;
    }
    return framePath(d + "/frames", 0, ".exr");
  }

  fs::path dir;
  std::string scenePath;
};

// Per floor pixel: the relative error of the frame against the closed form, and the distance
// in pixels from its centre's floor point to the floor's +x edge, the lamp's side.
struct FloorPixel {
  double error = 0.0, edgeDistancePx = 0.0;
};

std::vector<FloorPixel> floorPixels(const Scene& scene, const FrameExr& frame) {
  const CameraView view = scene.cameraAt(scene.cameraNode(""), 0.0);
  const PrimaryRays rays(view, kSize);
  const double pixelMetres = 2.0 * 1.2 * std::tan(0.45) / kSize.height;
  std::vector<FloorPixel> out;
  for (int row = 0; row < kSize.height; ++row)
    for (int col = 0; col < kSize.width; ++col) {
      const Ray r = rays.pixelCentre(col, row);
      const double s = -r.origin.y / r.direction.y;
      const glm::dvec3 x = r.origin + s * r.direction;
      if (std::abs(x.x) > 0.5 || std::abs(x.z) > 0.4) continue;  // away from the other edges
      const double want = kFloorRho / kPi * kPi * kLampRadiance *
                          pointToPolygonFormFactor(x, glm::dvec3(0, 1, 0), lampCorners());
      const size_t p = size_t(row) * kSize.width + col;
      out.push_back({frame.rgb[3 * p] / want - 1.0, (0.5 - x.x) / pixelMetres});
    }
  return out;
}

TEST_F(EdgePixels, BorderPixelsFollowTheIrradianceToTheEdge) {
  const std::string framePathName = render();
  ASSERT_TRUE(fs::exists(framePathName));
  const FrameExr frame = readFrameExr(framePathName);
  ASSERT_EQ(frame.width, kSize.width);
  const Scene scene = readGltfScene(scenePath);
  const std::vector<FloorPixel> pixels = floorPixels(scene, frame);
  ASSERT_GT(pixels.size(), 2000u);
  // The column next to the lit edge (centres within a pixel of it) against the pixels inside
  // by the lamp (1 to 6 pixels in): the border is allowed what the inside gets, and a little.
  double border = 0.0, inside = 0.0;
  int borderCount = 0;
  for (const FloorPixel& p : pixels) {
    if (p.edgeDistancePx < 1.0) {
      border = std::max(border, std::abs(p.error));
      ++borderCount;
    } else if (p.edgeDistancePx < 6.0) {
      inside = std::max(inside, std::abs(p.error));
    }
  }
  EXPECT_GT(borderCount, 40);
  EXPECT_LT(border, 0.02) << "largest error at the border " << border << ", inside " << inside;
  EXPECT_LT(border, 2.0 * inside + 0.005) << "inside " << inside;
}

}  // namespace
}  // namespace rad
