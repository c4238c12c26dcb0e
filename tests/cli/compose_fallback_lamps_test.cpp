// rad-compose's fallback samples under a punctual lamp (issue 57; fallback_lamp_light.h): a floor
// lit by a point lamp of 10 cd 1 m above it, a board 0.5 m up casting a hard shadow
// (pipelines/scenes/make_lamp_floor.py --blocker), composed from rad-global's solution with no
// movie at all, so every pixel falls back. Each pixel shows the floor or the board and must read
// the closed form rho / pi x I cos / d^2, 0 in the board's shadow (neither sees the other's lit
// face nor itself, so there is no indirect light). Before, the fallback read the leaf's B / pi,
// whose lamp term is the leaf's average: the shadow's edges and the inverse square blurred over
// the leaves.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "formats/exr_image.h"
#include "formats/provenance.h"
#include "formats/texture_intervals.h"
#include "tests/cli/cli_util.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;
constexpr int kSize = 64;
constexpr double kHalf = 2.0, kRho = 0.5;  // make_lamp_floor.py's view and floor
const double kColour[3] = {1.0, 0.8, 0.6};

// rho / pi x E at what pixel (i, j) shows, seen from above at (x, z): the board
// [0.2, 0.6] x [-0.2, 0.2] at y = 0.5, else the floor at y = 0, in the board's shadow where the
// segment to the lamp at (0, 1, 0) crosses it (at (x/2, z/2)). Neither sees the other's lit face.
bool onBoard(double x, double z) {
  return x >= 0.2 && x <= 0.6 && std::abs(z) <= 0.2;
}
double closedForm(int i, int j, int c) {
  const double x = kHalf * (2.0 * (i + 0.5) / kSize - 1.0);
  const double z = kHalf * (2.0 * (j + 0.5) / kSize - 1.0);
  const double h = onBoard(x, z) ? 0.5 : 1.0;  // the lamp's height above the surface
  if (h == 1.0 && onBoard(x / 2, z / 2)) return 0.0;
  const double d2 = x * x + z * z + h * h;
  return kRho / kPi * 10.0 * h / (d2 * std::sqrt(d2)) * kColour[c];
}

class ComposeFallbackLamps : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rad_fallback_lamps_" + std::to_string(::getpid()));
    fs::create_directories(dir_ / "movies");
  }
  void TearDown() override {
    if (!std::getenv("RAD_KEEP_TEST_DIR")) fs::remove_all(dir_);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void run(const std::string& command) {
    const CommandResult r = runCommand(command);
    ASSERT_EQ(r.exitCode, 0) << command << "\n" << r.err;
  }
  fs::path dir_;
};

TEST_F(ComposeFallbackLamps, FallbackPixelsTakeTheLampsDirectLightWithHardShadows) {
  const std::string scene = path("floor.gltf");
  run("python3 " + std::string(RAD_SOURCE_DIR) + "/pipelines/scenes/make_lamp_floor.py " + scene +
      " --blocker");
  run(tool("rad-global") + " " + scene + " -o " + path("global.rlh") + " --frames 0-0");
  TextureIntervals none;  // frame 0 and no movie: every covered pixel falls back
  none.imageWidth = none.imageHeight = kSize;
  writeTextureIntervals(path("intervals.rti"), none,
                        makeProvenance("rad-intervals", 0, nullptr, {}), nlohmann::json::object());
  run(tool("rad-compose") + " " + scene + " " + path("global.rlh") + " " + path("intervals.rti") +
      " " + path("movies") + " -o " + path("frames") + " --pixel-filter none --size " +
      std::to_string(kSize) + "x" + std::to_string(kSize));
  const FloatImage image = readExrImage(path("frames") + "/0000.exr");
  double peak = 0.0, sumT = 0.0, sumR = 0.0, worst = 0.0;
  for (int j = 0; j < kSize; ++j)
    for (int i = 0; i < kSize; ++i) peak = std::max(peak, closedForm(i, j, 0));
  int shadowed = 0;
  for (int j = 0; j < kSize; ++j)
    for (int i = 0; i < kSize; ++i) {
      shadowed += closedForm(i, j, 0) == 0.0;
      for (int c = 0; c < 3; ++c) {
        const double t = image.at(i, j, c), r = closedForm(i, j, c);
        worst = std::max(worst, std::abs(t - r) / peak);
        sumT += t;
        sumR += r;
      }
    }
  EXPECT_GT(shadowed, 50);
  EXPECT_LT(worst, 1e-4);
  EXPECT_NEAR(sumT / sumR, 1.0, 1e-4);
}

}  // namespace
}  // namespace rad::test
