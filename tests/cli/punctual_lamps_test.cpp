// Punctual lamps through the real tools (issue 57; docs/design.md §4 "Lights"): a floor lit by
// one KHR_lights_punctual lamp seen from straight above (pipelines/scenes/make_lamp_floor.py),
// where a pixel showing the floor at x is exactly rho / pi x E(x): I cos / d^2 for a point lamp,
// times the extension's cone falloff for a spot, E cos for a sun. rad-reference meets the closed
// forms to rounding, the pipeline (rad-global, rad-intervals, rad-movies, rad-compose) to its
// texture interpolation; a moving lamp's shadow moves, and its coherent global solution equals
// the --no-coherence one bit for bit.
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "formats/exr_image.h"
#include "tests/cli/cli_util.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;
constexpr int kSize = 64;
constexpr double kHalf = 2.0, kRho = 0.5;  // make_lamp_floor.py's view and floor
const double kColour[3] = {1.0, 0.8, 0.6};

class PunctualLamps : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rad_lamps_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string scene(const std::string& name, const std::string& flags) {
    const std::string path = (dir_ / (name + ".gltf")).string();
    EXPECT_EQ(runCommand("python3 " + std::string(RAD_SOURCE_DIR) +
                         "/pipelines/scenes/make_lamp_floor.py " + path + " " + flags)
                  .exitCode,
              0);
    return path;
  }
  // Runs `command` and expects exit 0.
  void run(const std::string& command) {
    const CommandResult r = runCommand(command);
    ASSERT_EQ(r.exitCode, 0) << command << "\n" << r.err;
  }
  // The whole pipeline at kSize^2, pixel centres; returns the frames folder.
  std::string pipeline(const std::string& scene, const std::string& frames,
                       const std::string& globalFlags = "") {
    const std::string d = (dir_ / fs::path(scene).stem()).string();
    run(tool("rad-global") + " " + scene + " -o " + d + ".rlh --frames " + frames + " " +
        globalFlags);
    run(tool("rad-intervals") + " " + scene + " -o " + d + ".rti --frames " + frames +
        " --pixel-filter none --size " + std::to_string(kSize) + "x" + std::to_string(kSize));
    run(tool("rad-movies") + " " + scene + " " + d + ".rlh " + d + ".rti -o " + d + "-movies");
    run(tool("rad-compose") + " " + scene + " " + d + ".rlh " + d + ".rti " + d + "-movies -o " +
        d + "-frames");
    return d + "-frames";
  }
  fs::path dir_;
};

// rho / pi x the lamp's E at pixel (i, j)'s floor point, channel c.
double closedForm(const std::string& lamp, int i, int j, int c) {
  const double x = kHalf * (2.0 * (i + 0.5) / kSize - 1.0);
  const double z = kHalf * (2.0 * (j + 0.5) / kSize - 1.0);
  double E;
  if (lamp == "sun") {
    E = 2.0 * std::cos(30.0 * kPi / 180.0);
  } else {
    const double d2 = x * x + z * z + 1.0, cosine = 1.0 / std::sqrt(d2);
    double profile = 1.0;
    if (lamp == "spot") {
      const double t =
          std::clamp((cosine - std::cos(0.6)) / (std::cos(0.3) - std::cos(0.6)), 0.0, 1.0);
      profile = t * t;
    }
    E = 10.0 * profile * cosine / d2;
  }
  return kRho / kPi * E * kColour[c];
}

struct Agreement {
  double worst = 0.0;  // largest |t - r| / peak
  double ratio = 0.0;  // sum t / sum r
};

Agreement compare(const std::string& lamp, const std::string& exr) {
  const FloatImage image = readExrImage(exr);
  double peak = 0.0, sumT = 0.0, sumR = 0.0;
  for (int j = 0; j < kSize; ++j)
    for (int i = 0; i < kSize; ++i) peak = std::max(peak, closedForm(lamp, i, j, 0));
  Agreement a;
  for (int j = 0; j < kSize; ++j)
    for (int i = 0; i < kSize; ++i)
      for (int c = 0; c < 3; ++c) {
        const double t = image.at(i, j, c), r = closedForm(lamp, i, j, c);
        a.worst = std::max(a.worst, std::abs(t - r) / peak);
        sumT += t;
        sumR += r;
      }
  a.ratio = sumT / sumR;
  return a;
}

TEST_F(PunctualLamps, ReferenceMeetsClosedForms) {
  for (const std::string lamp : {"point", "spot", "sun"}) {
    const std::string s = scene(lamp, "--lamp " + lamp);
    const std::string out = (dir_ / ("ref-" + lamp)).string();
    run(tool("rad-reference") + " " + s + " -o " + out + " --spp 1 --pixel-filter none --size " +
        std::to_string(kSize) + "x" + std::to_string(kSize));
    const Agreement a = compare(lamp, out + "/0000.exr");
    EXPECT_LT(a.worst, 1e-5) << lamp;
    EXPECT_NEAR(a.ratio, 1.0, 1e-5) << lamp;
  }
}

// The pipeline's texels hold the exact E at their centres; the compose interpolates between
// them: the frame's mean within 0.5 % (issue 57's goal), each pixel within 2 % of the peak; a
// spot's within 5 %, at its inner cone, where the falloff's slope jumps within a texel.
TEST_F(PunctualLamps, PipelineMeetsClosedForms) {
  for (const std::string lamp : {"point", "spot", "sun"}) {
    const std::string frames = pipeline(scene(lamp, "--lamp " + lamp), "0-0");
    const Agreement a = compare(lamp, frames + "/0000.exr");
    EXPECT_LT(a.worst, lamp == "spot" ? 0.05 : 0.02) << lamp;
    EXPECT_NEAR(a.ratio, 1.0, 0.005) << lamp;
  }
}

// The lamp moves 1 m along +X over 2 s over a board at x in [0.2, 0.6], 0.5 m up: its shadow on
// the floor is x in [0.4, 1.2] at t = 0 and [-0.58, 0.22] at frame 47. The coherent global
// solution (lamp values kept where nothing moved) equals --no-coherence's bit for bit.
TEST_F(PunctualLamps, MovingLampShadowMovesAndCoherenceIsExact) {
  const std::string s = scene("moving", "--blocker --move");
  const std::string frames = pipeline(s, "0-47x47");
  const FloatImage first = readExrImage(frames + "/0000.exr");
  const FloatImage last = readExrImage(frames + "/0047.exr");
  const auto pixel = [](double x) { return int((x / kHalf + 1.0) * 0.5 * kSize); };
  const int row = kSize / 2, a = pixel(0.9), b = pixel(-0.3);
  EXPECT_EQ(first.at(a, row, 0), 0.0f);  // in the board's shadow at t = 0
  EXPECT_GT(last.at(a, row, 0), 0.1f);   // lit at frame 47
  EXPECT_GT(first.at(b, row, 0), 0.1f);
  EXPECT_EQ(last.at(b, row, 0), 0.0f);
  const std::string g = (dir_ / "moving").string();
  run(tool("rad-global") + " " + s + " -o " + g + "-scratch.rlh --frames 0-47 --no-coherence");
  run(tool("rad-global") + " " + s + " -o " + g + "-coherent.rlh --frames 0-47");
  const auto arrays = [&](const std::string& f) {
    std::string out;
    std::istringstream lines(runCommand(tool("rad-inspect") + " " + f).out);
    for (std::string line; std::getline(lines, line);)
      if (line.find("fnv1a64") != std::string::npos && line.find("parameters") == std::string::npos)
        out += line + "\n";
    return out;
  };
  EXPECT_EQ(arrays(g + "-coherent.rlh"), arrays(g + "-scratch.rlh"));
}

// A static lamp over a moving board: the lamp's values on receivers the board's swept bounds
// do not reach are kept between key times (the report counts them), and the result is still
// --no-coherence's.
TEST_F(PunctualLamps, StaticLampValuesAreKeptAcrossKeyTimes) {
  const std::string s = scene("board", "--move-blocker");
  const std::string g = (dir_ / "board").string();
  run(tool("rad-global") + " " + s + " -o " + g + ".rlh --frames 0-47 --report " + g + ".json");
  const std::string report = readWholeFile(g + ".json");
  const auto value = [&](const std::string& key) {
    const size_t at = report.find("\"" + key + "\":", report.find("\"totals\""));
    return at == std::string::npos ? -1L : std::stol(report.substr(at + key.size() + 3));
  };
  EXPECT_GT(value("lamp_values"), 0);
  EXPECT_GT(value("lamp_values_reused"), value("lamp_values") / 2);
  run(tool("rad-global") + " " + s + " -o " + g + "-scratch.rlh --frames 0-47 --no-coherence");
  EXPECT_EQ(runCommand(tool("rad-inspect") + " " + g + ".rlh --array node_radiosity").out,
            runCommand(tool("rad-inspect") + " " + g + "-scratch.rlh --array node_radiosity").out);
}

// A closed box of reflectance rho with a point lamp of I = 1 cd inside (make_lamp_box.py): the
// walls absorb the lamp's 4 pi I W, so each wall's mean radiosity (by symmetry) is
// rho 4 pi I / (A (1 - rho)), A = 6 m^2: rad-global's lamp term and interreflection conserve
// power, within 0.5 %.
TEST_F(PunctualLamps, ClosedBoxConservesTheLampsPower) {
  for (const double rho : {0.5, 0.9}) {
    const std::string s = (dir_ / "box.gltf").string(), g = (dir_ / "box.rlh").string();
    run("python3 " + std::string(RAD_SOURCE_DIR) + "/pipelines/scenes/make_lamp_box.py " +
        std::to_string(rho) + " " + s);
    run(tool("rad-global") + " " + s + " -o " + g);
    std::istringstream rows(
        runCommand(tool("rad-inspect") + " " + g + " --array node_radiosity").out);
    const double expected = rho * 4.0 * kPi / (6.0 * (1.0 - rho));
    for (int wall = 0; wall < 6; ++wall) {  // the top-level patches come first
      double r = 0, gr = 0, b = 0;
      ASSERT_TRUE(rows >> r >> gr >> b) << wall;
      EXPECT_NEAR(r, expected, 0.005 * expected) << "rho " << rho << " wall " << wall;
    }
  }
}

// A Blender export's lamps are in Blender's units: the same floor written as Blender's exporter
// would (generator named) renders 683 times darker unless --light-units gltf says otherwise.
TEST_F(PunctualLamps, BlenderExportIsReadInBlenderUnits) {
  const std::string s = scene("blender", "--lamp point --blender");
  const std::string out = (dir_ / "ref-blender").string();
  run(tool("rad-reference") + " " + s + " -o " + out + " --spp 1 --pixel-filter none --size " +
      std::to_string(kSize) + "x" + std::to_string(kSize));
  EXPECT_NEAR(compare("point", out + "/0000.exr").ratio, 1.0 / 683.0, 1e-8);
  run(tool("rad-reference") + " " + s + " -o " + out + "-gltf --light-units gltf --spp 1 " +
      "--pixel-filter none --size " + std::to_string(kSize) + "x" + std::to_string(kSize));
  EXPECT_NEAR(compare("point", out + "-gltf/0000.exr").ratio, 1.0, 1e-5);
}

}  // namespace
}  // namespace rad::test
