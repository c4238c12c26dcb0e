// rad-compose as a user runs it: a synthetic scene, global solution, intervals and movies
// written with the real writers; frames checked for radiance, fallback warnings, PNG encoding,
// provenance, determinism and atomic failure.
#include <filesystem>
#include <fstream>
#include <regex>

#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "formats/checksum.h"
#include "formats/frame_image.h"
#include "formats/link_hierarchy.h"
#include "formats/provenance.h"
#include "formats/texture_intervals.h"
#include "formats/texture_movie.h"
#include "libcommon/compose/frame_composer.h"
#include "libcommon/gl/item_buffer.h"
#include "tests/cli/cli_util.h"
#include "tests/unit/compose_fixture.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;
constexpr ImageSize kSize{64, 48};
constexpr double kFps = 4.0;
const glm::dvec3 kWallH0(2.0, 4.0, 8.0);  // movie 0 (frames 0-1), constant
const glm::dvec3 kWallKey0(1.0, 1.0, 1.0), kWallKey1(3.0, 5.0, 7.0);  // movie 2 keys at 2, 3
const glm::dvec3 kWallB(0.7, 0.8, 0.9);  // global solution radiosity of the wall
const glm::dvec3 kLampB = kPi * kLampEmission + glm::dvec3(0.1);

TextureMovie constantMovie(uint32_t id, PatchId patch, int first, int last, glm::dvec3 h) {
  TextureMovie m;
  m.movie = id;
  m.patch = patch;
  m.firstFrame = first;
  m.lastFrame = last;
  m.width = 3;
  m.height = 2;
  m.keyFrames = {first};
  m.keyTimes = {first / kFps};
  m.keys.emplace_back();
  for (int i = 0; i < 6; ++i)
    m.keys[0].insert(m.keys[0].end(), {float(h.x), float(h.y), float(h.z)});
  m.provenanceJson =
      makeProvenance("rad-movies", 0, nullptr, {{"max-samples", 64}}).toJson().dump();
  return m;
}

class RadCompose : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() /
          ("rad_compose_test_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir / "movies");
    scenePath = writeComposeScene(dir.string());
    scene = readGltfScene(scenePath);
    GlobalSolution g = makeSolution(
        scene, {0.0, 1.0}, false, [](int node, int) { return node == kLampTop ? kLampB : kWallB; });
    Provenance p = makeProvenance("rad-global", 0, nullptr, {{"eps", 0.01}});
    writeLinkHierarchy((dir / "global.rlh").string(), g, p, nlohmann::json::object());

    TextureIntervals iv;
    iv.firstFrame = 0;
    iv.lastFrame = 3;
    iv.fps = kFps;
    iv.imageWidth = kSize.width;
    iv.imageHeight = kSize.height;
    auto add = [&](uint32_t id, int top, int first, int last) {
      MovieExtent t;
      t.movie = id;
      t.patch = PatchId{uint32_t(top), 1};
      t.firstFrame = first;
      t.lastFrame = last;
      t.width = 3;
      t.height = 2;
      iv.movies.push_back(t);
    };
    add(0, kWallTop, 0, 1);
    add(1, kLampTop, 0, 1);
    add(2, kWallTop, 2, 3);  // the lamp has no movie at frames 2-3: fallback
    writeTextureIntervals((dir / "intervals.rti").string(), iv,
                          makeProvenance("rad-intervals", 0, nullptr, {}),
                          nlohmann::json::object());

    writeTextureMovie(textureMoviePath((dir / "movies").string(), 0),
                      constantMovie(0, {kWallTop, 1}, 0, 1, kWallH0));
    writeTextureMovie(textureMoviePath((dir / "movies").string(), 1),
                      constantMovie(1, {kLampTop, 1}, 0, 1, glm::dvec3(0.0)));
    TextureMovie m2 = constantMovie(2, {kWallTop, 1}, 2, 3, kWallKey0);
    m2.keyFrames = {2, 3};
    m2.keyTimes = {2 / kFps, 3 / kFps};
    m2.keys.push_back({});
    for (int i = 0; i < 6; ++i)
      m2.keys[1].insert(m2.keys[1].end(),
                        {float(kWallKey1.x), float(kWallKey1.y), float(kWallKey1.z)});
    writeTextureMovie(textureMoviePath((dir / "movies").string(), 2), m2);

    std::vector<ItemTriangle> tris;
    auto tops = scene.inputPolygons();
    for (size_t i = 0; i < tops.size(); ++i)
      for (int k = 1; k + 1 < tops[i].local.count; ++k)
        tris.push_back(
            {{tops[i].local.v[0], tops[i].local.v[k], tops[i].local.v[k + 1]}, uint32_t(i + 1)});
    items = renderItemBuffer(tris, scene.cameraAt(scene.cameraNode(""), 0.0), kSize);
  }
  void TearDown() override {
    if (!std::getenv("RAD_KEEP_TEST_DIR")) fs::remove_all(dir);
  }

  std::string command(const std::string& out, const std::string& extra = "") const {
    return tool("rad-compose") + " " + scenePath + " " + (dir / "global.rlh").string() + " " +
           (dir / "intervals.rti").string() + " " + (dir / "movies").string() + " -o " + out + " " +
           extra;
  }
  long long count(uint32_t id) const { return std::count(items.id.begin(), items.id.end(), id); }

  fs::path dir;
  std::string scenePath;
  Scene scene;
  ItemBuffer items;
};

glm::dvec3 px(const FrameExr& f, size_t p) {
  return {f.rgb[3 * p], f.rgb[3 * p + 1], f.rgb[3 * p + 2]};
}
void expectRel(const glm::dvec3& got, const glm::dvec3& want, double rel, const std::string& at) {
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(got[a], want[a], rel * std::abs(want[a])) << at;
}

TEST_F(RadCompose, FramesHaveRadianceFallbackWarningsAndProvenance) {
  std::string out = (dir / "frames").string();
  CommandResult r = runCommand(command(out, "--report " + (dir / "report.json").string()));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const long long wallPixels = count(kWallTop + 1), lampPixels = count(kLampTop + 1);
  ASSERT_GT(wallPixels, 300);
  ASSERT_GT(lampPixels, 20);
  // One warning per fallback frame, counting exactly the lamp's pixels.
  std::string w2 = "rad-compose: frame 2: " + std::to_string(lampPixels) +
                   " pixels fell back to the global solution\n";
  std::string w3 = "rad-compose: frame 3: " + std::to_string(lampPixels) +
                   " pixels fell back to the global solution\n";
  EXPECT_EQ(r.err, w2 + w3);

  for (int f = 0; f < 4; ++f) {
    FrameExr e = readFrameExr(framePath(out, f, ".exr"));
    ASSERT_EQ(e.width, kSize.width);
    ASSERT_EQ(e.height, kSize.height);
    EXPECT_FALSE(e.half);
    EXPECT_EQ(e.attributes["rad.frame"], std::to_string(f));
    EXPECT_EQ(e.attributes["rad.fallbackPixels"], std::to_string(f >= 2 ? lampPixels : 0));
    EXPECT_DOUBLE_EQ(std::stod(e.attributes["rad.time"]), f / kFps);
    // Movie 2 is linear between its keys at frames 2 and 3.
    glm::dvec3 H = f < 2 ? kWallH0 : (f == 2 ? kWallKey0 : kWallKey1);
    for (size_t p = 0; p < items.id.size(); ++p) {
      std::string at = "frame " + std::to_string(f) + " pixel " + std::to_string(p);
      if (items.id[p] == kNoItem)
        EXPECT_EQ(px(e, p), glm::dvec3(0.0)) << at;
      else if (items.id[p] == kWallTop + 1)
        expectRel(px(e, p), 0.5 / kPi * H, 1e-5, at);
      else
        expectRel(px(e, p), f < 2 ? kLampEmission : kLampB / kPi, 1e-5, at);
    }
    nlohmann::json prov = nlohmann::json::parse(e.attributes["rad.provenance"]);
    EXPECT_EQ(prov["tool"], "rad-compose");
    ASSERT_EQ(prov["inputs"].size(), 4u);
    EXPECT_EQ(prov["inputs"][1]["history"]["tool"], "rad-global");
    EXPECT_EQ(prov["inputs"][2]["history"]["tool"], "rad-intervals");
    EXPECT_EQ(prov["inputs"][3]["history"]["tool"], "rad-movies");
    EXPECT_EQ(prov["parameters"]["fps"], kFps);
    EXPECT_EQ(prov["parameters"]["size"], "64x48");
  }
  nlohmann::json rep = nlohmann::json::parse(readWholeFile((dir / "report.json").string()));
  ASSERT_EQ(rep["frames"].size(), 4u);
  EXPECT_EQ(rep["fallback_pixels"], 2 * lampPixels);
  EXPECT_EQ(rep["frames"][3]["fallback_pixels"], lampPixels);
  EXPECT_EQ(rep["movies_read"], 3);
  EXPECT_EQ(rep["peak_loaded_movies"], 2);  // movies 0 and 1 evicted before movie 2 loads
  EXPECT_GE(rep["frames"][0]["seconds"].get<double>(), 0.0);
  EXPECT_GT(rep["peak_memory_mb"].get<double>(), 1.0);
}

TEST_F(RadCompose, PngIsSrgbOfExposureScaledRadiance) {
  std::string out = (dir / "frames").string();
  CommandResult r = runCommand(command(out, "--frames 1 --exposure -1.5"));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_FALSE(fs::exists(framePath(out, 0, ".exr")));
  FrameExr e = readFrameExr(framePath(out, 1, ".exr"));
  EXPECT_DOUBLE_EQ(std::stod(e.attributes["rad.exposureEV"]), -1.5);
  auto in = OIIO::ImageInput::open(framePath(out, 1, ".png"));
  ASSERT_TRUE(in);
  const OIIO::ImageSpec& spec = in->spec();
  ASSERT_EQ(spec.width, kSize.width);
  ASSERT_EQ(spec.nchannels, 3);
  std::vector<uint8_t> png(size_t(kSize.pixelCount()) * 3);
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, png.data()));
  EXPECT_EQ(png, toSrgb8(e.rgb, -1.5));
  // The provenance travels in the PNG too (zTXt "Description", read back by OpenImageIO).
  std::string description = spec.get_string_attribute("ImageDescription");
  EXPECT_EQ(description.rfind("rad frame 1, exposure -1.5 EV; provenance {", 0), 0u) << description;
  EXPECT_NE(description.find("rad-compose"), std::string::npos);
  // A wall pixel by hand: L = 0.5/pi * 8 (blue) at 2^-1.5.
  size_t wall =
      std::find(items.id.begin(), items.id.end(), uint32_t(kWallTop + 1)) - items.id.begin();
  double blue = 0.5 / kPi * kWallH0.z * std::exp2(-1.5);
  EXPECT_EQ(png[3 * wall + 2],
            uint8_t(std::lround(255 * (1.055 * std::pow(blue, 1 / 2.4) - 0.055))));
}

// Frames are uncompressed by default; --compression changes the bytes, never the pixels.
TEST_F(RadCompose, CompressionChangesBytesNotPixels) {
  std::string plain = (dir / "plain").string(), zip = (dir / "zip").string();
  ASSERT_EQ(runCommand(command(plain, "--frames 1 --no-png")).exitCode, 0);
  CommandResult r = runCommand(command(zip, "--frames 1 --no-png --compression zip"));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  Imf::InputFile a(framePath(plain, 1, ".exr").c_str()), b(framePath(zip, 1, ".exr").c_str());
  EXPECT_EQ(a.header().compression(), Imf::NO_COMPRESSION);
  EXPECT_EQ(b.header().compression(), Imf::ZIP_COMPRESSION);
  EXPECT_EQ(readFrameExr(framePath(plain, 1, ".exr")).rgb,
            readFrameExr(framePath(zip, 1, ".exr")).rgb);
  CommandResult bad = runCommand(command(zip, "--compression lzw"));
  EXPECT_EQ(bad.exitCode, 2);
  EXPECT_EQ(countLines(bad.err), 1) << bad.err;
}

TEST_F(RadCompose, AutoExposureIsOneValueForTheSequence) {
  std::string out = (dir / "frames").string();
  CommandResult r = runCommand(command(out, "--auto-exposure --no-png"));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("auto exposure"), std::string::npos) << r.err;
  // Only the wall reflects: luminance of kWallB / pi maps to 1.
  double want = -std::log2(luminance(kWallB / kPi));
  for (int f = 0; f < 4; ++f) {
    FrameExr e = readFrameExr(framePath(out, f, ".exr"));
    EXPECT_NEAR(std::stod(e.attributes["rad.exposureEV"]), want, 1e-6);
    EXPECT_FALSE(fs::exists(framePath(out, f, ".png")));
  }
  EXPECT_NE(runCommand(command(out, "--auto-exposure --exposure 1")).exitCode, 0);
}

TEST_F(RadCompose, HalfFrames) {
  std::string out = (dir / "frames").string();
  ASSERT_EQ(runCommand(command(out, "--frames 0 --half --no-png")).exitCode, 0);
  FrameExr e = readFrameExr(framePath(out, 0, ".exr"));
  EXPECT_TRUE(e.half);
  for (size_t p = 0; p < items.id.size(); ++p)
    if (items.id[p] == kWallTop + 1) expectRel(px(e, p), 0.5 / kPi * kWallH0, 1e-3, "half");
}

TEST_F(RadCompose, BitIdenticalAcrossRuns) {
  std::string out = (dir / "frames").string();
  ASSERT_EQ(runCommand(command(out)).exitCode, 0);
  std::map<std::string, std::string> first;
  for (const auto& e : fs::directory_iterator(out))
    first[e.path().filename().string()] = readWholeFile(e.path().string());
  EXPECT_EQ(first.size(), 8u);  // 4 EXR + 4 PNG, no temporaries
  fs::remove_all(out);
  ASSERT_EQ(runCommand(command(out)).exitCode, 0);
  for (const auto& [name, bytes] : first)
    EXPECT_TRUE(readWholeFile((fs::path(out) / name).string()) == bytes) << name;
}

// The frames' movies input (formats/frame_image.md, frame 2.2): FNV-1a 64 over the header hashes
// of the movies the frames use, each the FNV-1a 64 of the file's bytes before its chunk offset
// tables, so that a compose task reads no pixels of keys its frames do not show (issue 58: every
// farm chunk hashed every movie file's bytes). Before, it was each whole file's hash.
TEST_F(RadCompose, MoviesInputHashIsOfTheUsedMoviesHeaders) {
  auto moviesHash = [&](const std::string& frames) {
    const std::string out = (dir / ("frames" + frames)).string();
    CommandResult r = runCommand(command(out, "--frames " + frames));
    EXPECT_EQ(r.exitCode, 0) << r.err;
    FrameExr e = readFrameExr(framePath(out, frames == "2-3" ? 2 : 0, ".exr"));
    nlohmann::json prov = nlohmann::json::parse(e.attributes["rad.provenance"]);
    EXPECT_EQ(prov["inputs"][3]["history"]["tool"], "rad-movies");
    return prov["inputs"][3]["hash"].get<std::string>();
  };
  // Movie 2: 2 parts of 3x2 texels, one chunk per scan line (uncompressed): after its headers,
  // 4 offsets of 8 bytes and 4 chunks of part number, y and size (4 bytes each) and 3 channels x 3
  // floats.
  auto headerHash = [&](uint32_t id) {
    const std::string bytes = readWholeFile(textureMoviePath((dir / "movies").string(), id));
    const size_t headers = bytes.size() - 4 * 8 - 4 * (12 + 3 * 3 * 4);
    return formatFnv1a64(fnv1a64(bytes.data(), headers));
  };
  const std::string expected = headerHash(2);
  const std::string got = moviesHash("2-3");
  EXPECT_EQ(got, formatFnv1a64(fnv1a64(expected.data(), expected.size()))) << got;

  // Other pixels in a key: another rad.pixelChecksum in its header, another hash.
  TextureMovie m2 = constantMovie(2, {kWallTop, 1}, 2, 3, kWallKey1);
  m2.keyFrames = {2, 3};
  m2.keyTimes = {2 / kFps, 3 / kFps};
  m2.keys.push_back(m2.keys[0]);
  m2.keys[1][0] += 1.0f;
  writeTextureMovie(textureMoviePath((dir / "movies").string(), 2), m2);
  EXPECT_NE(moviesHash("2-3"), got);
  // Frames 0-1 use movies 0 and 1, not 2.
  EXPECT_NE(moviesHash("0-1"), got);
}

TEST_F(RadCompose, UnwritableOutputIsOneLineExit3) {
  writeBytes((dir / "plain").string(), "not a directory");
  std::string out = (dir / "plain" / "frames").string();
  CommandResult r = runCommand(command(out));
  EXPECT_EQ(r.exitCode, 3) << r.err;
  EXPECT_EQ(countLines(r.err), 1) << r.err;
  EXPECT_EQ(r.err.rfind("rad-compose: " + out + ": ", 0), 0u) << r.err;
}

// Every movie's headers are checked before the first frame is written (issue 18: a bad movie
// of a later interval used to leave the earlier frames behind).
TEST_F(RadCompose, BadMovieHeaderLeavesNoFrame) {
  // Movie 2 claims another patch than the intervals give it; it is first used at frame 2.
  TextureMovie bad = constantMovie(2, PatchId{kWallTop, 1}.child(1), 2, 3, kWallKey0);
  writeTextureMovie(textureMoviePath((dir / "movies").string(), 2), bad);
  std::string out = (dir / "frames").string();
  CommandResult r = runCommand(command(out));
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(countLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("000002.exr: patch 0/1 differs"), std::string::npos) << r.err;
  EXPECT_TRUE(!fs::exists(out) || fs::is_empty(out));
}

// A key whose pixels fail their checksum is found when it is loaded (frame 3 loads movie 2's
// key 1): exit 1, one line naming the movie, the part and the frames already written.
TEST_F(RadCompose, CorruptedKeyIsOneLineNamingTheFramesWritten) {
  const std::string movie = textureMoviePath((dir / "movies").string(), 2);
  // The file ends with the last scan line of its last part (key 1): flip a bit of it.
  std::string bytes = readWholeFile(movie);
  bytes.back() = char(bytes.back() ^ 0x01);
  std::ofstream(movie, std::ios::binary | std::ios::trunc) << bytes;
  std::string out = (dir / "frames").string();
  CommandResult r = runCommand(command(out));
  EXPECT_EQ(r.exitCode, 1) << r.err;
  // Frame 2's fallback warning (the lamp has no movie there), then the error on one line.
  EXPECT_EQ(countLines(r.err), 2) << r.err;
  const std::string error = r.err.substr(r.err.find('\n') + 1);
  EXPECT_EQ(error.rfind("rad-compose: " + movie + ": part 1: pixel checksum mismatch", 0), 0u)
      << r.err;
  EXPECT_NE(error.find("(after writing 3 of 4 frames, 0-2: the sequence is incomplete)\n"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(framePath(out, 3, ".exr")));
}

TEST_F(RadCompose, MissingMovieAndFramesOutsideTheWindow) {
  // Two movies missing: the headers are read in parallel, and the first in interval order is
  // the one reported, on one line.
  const std::string second = textureMoviePath((dir / "movies").string(), 2);
  fs::remove(textureMoviePath((dir / "movies").string(), 1));
  fs::rename(second, second + ".away");
  CommandResult r = runCommand(command((dir / "frames").string()));
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find("000001.exr"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("000002.exr"), std::string::npos) << r.err;
  EXPECT_EQ(countLines(r.err), 1) << r.err;
  fs::rename(second + ".away", second);
  r = runCommand(command((dir / "frames2").string(), "--frames 2-9"));
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_NE(r.err.find("outside the intervals' window 0-3"), std::string::npos) << r.err;
}

// rad-compose refuses a global solution whose key times do not span the intervals' frames
// (here one key time, t = 0, for frames 0-23), with one line naming both files and both ranges,
// before it reads a movie or writes a frame.
TEST(RadComposeWindow, RefusesAGlobalSolutionThatDoesNotCoverTheIntervals) {
  const fs::path d =
      fs::temp_directory_path() / ("rad_compose_window_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d / "movies");
  const std::string scene = RAD_SOURCE_DIR "/pipelines/scenes/cornell-moving.gltf";
  const std::string global = (d / "global.rlh").string(), iv = (d / "intervals.rti").string();
  CommandResult g =
      runCommand(tool("rad-global") + " " + scene + " -o " + global + " --frames 0-0 --eps 0.05");
  ASSERT_EQ(g.exitCode, 0) << g.err;
  CommandResult i =
      runCommand(tool("rad-intervals") + " " + scene + " -o " + iv + " --frames 0-23 --size 44x30");
  ASSERT_EQ(i.exitCode, 0) << i.err;
  const std::string frames = (d / "frames").string();
  CommandResult r = runCommand(tool("rad-compose") + " " + scene + " " + global + " " + iv + " " +
                               (d / "movies").string() + " -o " + frames);
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(countLines(r.err), 1) << r.err;
  EXPECT_EQ(r.err.rfind("rad-compose: " + global + ": ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(iv), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("frames 0-0 "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("frames 0-23 "), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(frames));
  if (!std::getenv("RAD_KEEP_TEST_DIR")) fs::remove_all(d);
}

}  // namespace
}  // namespace rad::test
