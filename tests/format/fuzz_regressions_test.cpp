// Replays every input the fuzz harnesses found (tests/data/fuzz-regressions/<reader>/) through
// the same reader calls as the harness (tests/fuzz/fuzz_readers.h), in the normal build: each
// must give rad::Error or succeed. A signal kills this test; any other exception fails it.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/fuzz/fuzz_readers.h"

namespace fs = std::filesystem;
using Feed = std::function<void(const uint8_t*, size_t)>;

namespace {

std::vector<uint8_t> bytesOf(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

// The reader's reproducers, and always the empty input and a lone byte (so every reader is
// exercised even before its first reproducer).
std::vector<std::vector<uint8_t>> inputsOf(const std::string& reader) {
  std::vector<std::vector<uint8_t>> inputs{{}, {0x7b}};
  const fs::path dir = fs::path(RAD_TEST_DATA) / "fuzz-regressions" / reader;
  if (fs::is_directory(dir))
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file()) inputs.push_back(bytesOf(e.path()));
  return inputs;
}

void replay(const std::string& reader, const Feed& feed) {
  for (const std::vector<uint8_t>& input : inputsOf(reader))
    EXPECT_NO_THROW(feed(input.data(), input.size())) << reader << ", " << input.size() << " bytes";
}

}  // namespace

TEST(FuzzRegressions, DirectoryIsWhereTheHarnessesSayItIs) {
  EXPECT_TRUE(fs::exists(fs::path(RAD_TEST_DATA) / "fuzz-regressions" / "README.md"));
}

TEST(FuzzRegressions, Gltf) {
  rad::fuzz::copyGltfSidecars(RAD_SOURCE_DIR);
  replay("gltf", rad::fuzz::feedGltf);
}

TEST(FuzzRegressions, Container) {
  replay("container", rad::fuzz::feedContainer);
}

TEST(FuzzRegressions, LinkHierarchy) {
  replay("link_hierarchy", [](const uint8_t* data, size_t size) {
    rad::fuzz::feedLinkHierarchy(data, size, rad::fuzz::bundledScene());
  });
}

TEST(FuzzRegressions, KeyWindow) {
  replay("key_window", [](const uint8_t* data, size_t size) {
    rad::fuzz::feedKeyWindow(data, size, rad::fuzz::bundledScene());
  });
}

TEST(FuzzRegressions, Intervals) {
  replay("intervals", rad::fuzz::feedIntervals);
}
TEST(FuzzRegressions, TextureMovie) {
  replay("texture_movie", rad::fuzz::feedTextureMovie);
}
TEST(FuzzRegressions, Frame) {
  replay("frame", rad::fuzz::feedFrame);
}
