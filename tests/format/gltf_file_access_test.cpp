// The glTF reader's file access (formats/gltf_scene.md "Files", "Materials", "Inputs"; issue
// 54): one rule for a texture that cannot be read or decoded, only regular files read, reads
// bounded by declared sizes, decoded images bounded, out of memory as exit 4, rad-inspect
// --inputs' list.
#include <sys/stat.h>
#include <sys/types.h>

#include <chrono>
#include <filesystem>

#include <gtest/gtest.h>

#include "formats/gltf_file_access.h"
#include "formats/gltf_inputs.h"
#include "formats/gltf_scene.h"
#include "formats/provenance.h"
#include "libcommon/core/error.h"
#include "tests/format/gltf_test_files.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

class GltfFileAccess : public TexturedTriangleFolder {
 protected:
  GltfFileAccess() : TexturedTriangleFolder("rad_gltf_access_") {}
  std::string scene(const std::string& imageUri, double yfov = 0.8) {
    writeFile(at("scene.gltf"), texturedTriangleGltf(imageUri, yfov));
    return at("scene.gltf");
  }
  // Loads; expects exactly one warning, naming the texture's image and `why`, and the
  // reflectance of baseColorFactor alone.
  void expectTextureIgnored(const std::string& imageUri, const std::string& why) {
    SCOPED_TRACE(imageUri);
    const auto start = std::chrono::steady_clock::now();
    Scene s = readGltfScene(scene(imageUri));
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
    ASSERT_EQ(s.warnings.size(), 1u) << ::testing::PrintToString(s.warnings);
    const std::string& w = s.warnings[0];
    EXPECT_EQ(w.rfind("texture 0: image 0 '", 0), 0u) << w;
    EXPECT_NE(w.find(why), std::string::npos) << w;
    EXPECT_NE(w.find("texture ignored, reflectance = baseColorFactor only"), std::string::npos)
        << w;
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].baseColorTexture, -1);
    EXPECT_DOUBLE_EQ(s.materials[0].reflectance.x, 0.5);
    EXPECT_DOUBLE_EQ(s.materials[0].reflectance.y, 0.25);
    EXPECT_DOUBLE_EQ(s.materials[0].reflectance.z, 0.125);
    EXPECT_TRUE(s.textures.empty());
  }
  void expectRefused(const std::string& path, const std::string& fragment,
                     ExitCode code = ExitCode::kBadInput) {
    const auto start = std::chrono::steady_clock::now();
    try {
      readGltfScene(path);
      ADD_FAILURE() << path << ": no error";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), code) << e.what();
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
      EXPECT_NE(what.find(fragment), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  }
};

TEST_F(GltfFileAccess, ReadableTextureIsUsed) {
  writeFile(at("tex.png"), encodedImage(4, 4, false));
  Scene s = readGltfScene(scene("tex.png"));
  EXPECT_TRUE(s.warnings.empty()) << ::testing::PrintToString(s.warnings);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].width, 4);
  EXPECT_EQ(s.materials[0].baseColorTexture, 0);
}

TEST_F(GltfFileAccess, UnreadableTextureIsOneWarning) {
  expectTextureIgnored("missing.png", "no such file");
  fs::create_directories(at("folder.png"));
  expectTextureIgnored("folder.png", "not a regular file (a directory)");
  expectTextureIgnored("../../../../../../../../dev/zero",
                       "not a regular file (a character device)");
  expectTextureIgnored("/dev/zero", "no such file (looked for");
  expectTextureIgnored("http://example.com/tex.png", "URI scheme 'http:' is not read");
  expectTextureIgnored("https://example.com/tex.png", "URI scheme 'https:' is not read");
  expectTextureIgnored("file:///tmp/tex.png", "URI scheme 'file:' is not read");
  writeFile(at("empty.png"), "");
  expectTextureIgnored("empty.png", "empty file");
  writeFile(at("text.png"), "not an image at all");
  expectTextureIgnored("text.png", "not an image stb_image reads");
}

TEST_F(GltfFileAccess, FifoTextureIsOneWarningWithoutWaiting) {
  ASSERT_EQ(::mkfifo(at("pipe.png").c_str(), 0600), 0);
  expectTextureIgnored("pipe.png", "not a regular file (a FIFO)");
}

TEST_F(GltfFileAccess, TruncatedImagesAreOneWarning) {
  const std::string jpeg = encodedImage(64, 64, true), png = encodedImage(64, 64, false);
  writeFile(at("cut.jpg"), jpeg.substr(0, jpeg.size() / 2));
  expectTextureIgnored("cut.jpg", "cannot be decoded");
  writeFile(at("cut.png"), png.substr(0, png.size() / 2));
  expectTextureIgnored("cut.png", "cannot be decoded");
}

// A 12,000^2 PNG (~140 KB) decodes to 144 MB; above the limit it is not decoded at all.
TEST_F(GltfFileAccess, TextureAboveThePixelLimitIsNotDecoded) {
  writeFile(at("huge.png"), zeroPng(12000, 12000));
  expectTextureIgnored("huge.png",
                       "12000x12000 pixels (144.0 megapixels), above the limit of "
                       "67.1 megapixels (--max-texture-pixels)");
  GltfReadOptions small;
  small.maxTexturePixels = 15;
  writeFile(at("tex.png"), encodedImage(4, 4, false));
  Scene s = readGltfScene(scene("tex.png"), small);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("4x4 pixels"), std::string::npos) << s.warnings[0];
  small.maxTexturePixels = 16;
  EXPECT_TRUE(readGltfScene(scene("tex.png"), small).warnings.empty());
}

TEST_F(GltfFileAccess, SceneMustBeARegularFile) {
  fs::create_directories(at("dir.gltf"));
  expectRefused(at("dir.gltf"), "not a regular file (a directory)");
  expectRefused("/dev/zero", "not a regular file (a character device)");
  ASSERT_EQ(::mkfifo(at("pipe.gltf").c_str(), 0600), 0);
  expectRefused(at("pipe.gltf"), "not a regular file (a FIFO)");
  expectRefused(at("none.gltf"), "cannot open file");
}

// Sparse files: refused from their size, nothing read.
TEST_F(GltfFileAccess, FilesOverTheSizeLimitsAreNotRead) {
  writeFile(at("big.gltf"), "{");
  fs::resize_file(at("big.gltf"), kMaxSceneFileBytes + 1);
  expectRefused(at("big.gltf"), "file of 1073741825 bytes, beyond the limit of 1073741824");
  writeFile(at("big.png"), "");
  fs::resize_file(at("big.png"), kMaxImageFileBytes + 1);
  expectTextureIgnored("big.png", "file of 1073741825 bytes, beyond the limit of 1073741824");
}

TEST_F(GltfFileAccess, BufferMustBeARegularFileOfItsByteLength) {
  ASSERT_EQ(::mkfifo(at("pipe.bin").c_str(), 0600), 0);
  writeFile(at("scene.gltf"), texturedTriangleGltf("", 0.8, "pipe.bin"));
  expectRefused(at("scene.gltf"), "buffer 0 'pipe.bin': not a regular file (a FIFO)");
  writeFile(at("scene.gltf"), texturedTriangleGltf("", 0.8, "http://example.com/tri.bin"));
  expectRefused(at("scene.gltf"), "URI scheme 'http:' is not read");
  writeFile(at("short.bin"), texturedTriangleBin().substr(0, 40));
  writeFile(at("scene.gltf"), texturedTriangleGltf("", 0.8, "short.bin"));
  expectRefused(at("scene.gltf"),
                "buffer 0 'short.bin': file has 40 bytes, byteLength declares 68");
  // A longer file is read to byteLength only.
  writeFile(at("long.bin"), texturedTriangleBin() + std::string(1000, '\x7f'));
  writeFile(at("scene.gltf"), texturedTriangleGltf("", 0.8, "long.bin"));
  Scene s = readGltfScene(at("scene.gltf"));
  EXPECT_EQ(s.meshes[0].triangles.size(), 1u);
}

// The working directory is not searched when a URI is missing beside the scene.
TEST_F(GltfFileAccess, UrisResolveAgainstTheScenesFolderOnly) {
  const fs::path cwd = fs::current_path();
  fs::create_directories(dir / "sub");
  writeFile(at("sub/scene.gltf"), texturedTriangleGltf("tex.png"));
  writeFile(at("sub/tri.bin"), texturedTriangleBin());
  writeFile(at("tex.png"), encodedImage(4, 4, false));
  fs::current_path(dir);
  Scene s = readGltfScene(at("sub/scene.gltf"));
  fs::current_path(cwd);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("no such file"), std::string::npos) << s.warnings[0];
}

TEST_F(GltfFileAccess, ImageViewOutsideItsBufferIsRefused) {
  std::string gltf = texturedTriangleGltf("x.png");
  gltf.replace(gltf.find(R"({"uri": "x.png"})"), 16,
               R"({"bufferView": 3, "mimeType": "image/png"})");
  gltf.replace(gltf.find(R"("byteLength": 24}])"), 18,
               R"("byteLength": 24}, {"buffer": 0, "byteOffset": 60, "byteLength": 100000}])");
  writeFile(at("scene.gltf"), gltf);
  expectRefused(at("scene.gltf"),
                "image 0: bufferView 3 (offset 60, length 100000) exceeds buffer 0");
}

TEST_F(GltfFileAccess, TinyYfovIsRefused) {
  expectRefused(scene("", 1e-9), "camera 0: yfov 1e-09 is below the limit 0.001 rad");
  EXPECT_NO_THROW(readGltfScene(scene("", 0.002)));
}

TEST_F(GltfFileAccess, WarningHandlerGetsEachWarning) {
  std::vector<std::string> got;
  setGltfWarningHandler(
      [&](const std::string& path, const std::string& w) { got.push_back(path + "|" + w); });
  readGltfScene(scene("missing.png"));
  setGltfWarningHandler(nullptr);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].rfind(at("scene.gltf") + "|texture 0: image 0 'missing.png': no such file", 0),
            0u)
      << got[0];
}

TEST_F(GltfFileAccess, InputsListSceneBufferAndImages) {
  writeFile(at("tex%20a.png"), "");  // a decoy: the URI is percent-decoded to "tex a.png"
  writeFile(at("tex a.png"), encodedImage(4, 4, false));
  writeFile(at("scene.gltf"), texturedTriangleGltf("tex%20a.png"));
  std::vector<GltfInput> in = gltfInputs(at("scene.gltf"));
  ASSERT_EQ(in.size(), 3u);
  EXPECT_EQ(in[0].path, at("scene.gltf"));
  EXPECT_EQ(in[1].path, at("tri.bin"));
  EXPECT_EQ(in[2].path, at("tex a.png"));
  EXPECT_EQ(in[1].hash, hashFile(at("tri.bin")));
  EXPECT_EQ(in[2].hash.rfind("fnv1a64:", 0), 0u);
  EXPECT_EQ(gltfInputsText(in).substr(0, 8 + 16 + 1), in[0].hash + "\t");
  fs::remove(at("tex a.png"));
  EXPECT_EQ(gltfInputs(at("scene.gltf"))[2].hash, "missing");
  fs::remove(at("tri.bin"));
  try {
    gltfInputs(at("scene.gltf"));
    ADD_FAILURE() << "a missing buffer is an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("buffer 0 '"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rad::test
