// Key window files (formats/key_window.md): write / read round trip; truncated, corrupted,
// inconsistent (checksums valid) and future-version files, another scene and another run's
// parameters are one-line errors naming the file, never a crash.
#include "formats/key_window.h"
#include "libcommon/radiosity/space_time_radiosity.h"

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>

#include <gtest/gtest.h>

#include "formats/gltf_scene.h"
#include "formats/provenance.h"
#include "libcommon/core/error.h"

namespace rad {
namespace {

std::string scenePath() {
  return std::string(RAD_SOURCE_DIR) + "/pipelines/scenes/cornell-moving.gltf";
}

std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("rad_keywindow_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

const std::vector<double> kKeys = {0.0, 0.25, 0.5, 0.75};

// Keys 1 and 2 of kKeys, coarse.
KeyWindow window(const Scene& scene) {
  SpaceTimeOptions o;
  o.radiosity.eps = 1e-2;
  o.radiosity.minArea = 1e-3;
  o.radiosity.rays = 4;
  return solveKeyWindow(scene, kKeys, 1, 2, o);
}

const nlohmann::json kParameters = {{"eps", 1e-2}, {"frames", "0-18"}};

Provenance provenance() {
  const char* argv[] = {"rad-global", "scene.gltf", "--window", "6-12"};
  Provenance p = makeProvenance("rad-global", 4, argv, kParameters);
  addInput(p, scenePath());
  return p;
}

std::string written(const Scene& scene, const std::string& name) {
  const std::string path = tempPath(name);
  writeKeyWindow(path, window(scene), provenance(),
                 {{"parameters", kParameters}, {"window", "6-12"}, {"run_key_count", 4}});
  return path;
}

// A one-line input error naming the file and `what`.
void expectOneLineError(const std::function<void()>& f, const std::string& path,
                        const std::string& what) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one about " << what;
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    EXPECT_NE(m.find(path), std::string::npos) << m;
    EXPECT_NE(m.find(what), std::string::npos) << m;
    EXPECT_EQ(e.code(), ExitCode::kBadInput) << m;
  }
}

// The container at `path` in memory with array `name` replaced by `edit` applied to its u32
// values (checksums recomputed, so only the content checks can catch it), or with kind
// version `version`.
ContainerReader rewritten(const std::string& path, const std::string& name,
                          const std::function<void(std::vector<uint32_t>&)>& edit,
                          std::pair<int, int> version = {kKeyWindowMajor, kKeyWindowMinor}) {
  const ContainerReader r = ContainerReader::open(path);
  ContainerWriter w(r.kind(), version.first, version.second);
  w.setProvenance(r.provenance());
  w.metadata() = r.metadata();
  for (const ArrayInfo& a : r.arrays()) {
    if (a.name != name) {
      w.addRaw(a.name, a.dtype, a.shape, r.data(a), a.nbytes);
      continue;
    }
    std::vector<uint32_t> v = r.array<uint32_t>(name);
    edit(v);
    w.addArray(name, v, v.size() == a.count() ? a.shape : std::vector<uint64_t>{});
  }
  return ContainerReader::fromBytes(w.serialize(), path);
}

TEST(KeyWindowFile, RoundTrip) {
  const Scene scene = readGltfScene(scenePath());
  const KeyWindow w = window(scene);
  const std::string path = written(scene, "roundtrip.rkw");
  const ContainerReader reader = ContainerReader::open(path);
  EXPECT_EQ(reader.kind(), kKeyWindowKind);
  const KeyWindow r = readKeyWindow(reader, scene);
  EXPECT_EQ(r.firstKey, 1u);
  EXPECT_EQ(r.keyTimes, (std::vector<double>{0.25, 0.5}));
  ASSERT_EQ(r.hierarchy.size(), w.hierarchy.size());
  for (int i = 0; i < w.hierarchy.size(); ++i)
    EXPECT_EQ(r.hierarchy.node(i).id, w.hierarchy.node(i).id);
  EXPECT_EQ(r.nodeCount, w.nodeCount);
  EXPECT_TRUE(r.radiosity == w.radiosity);
  EXPECT_TRUE(r.exposure == w.exposure);
  EXPECT_TRUE(r.goodClosure == w.goodClosure);
  EXPECT_TRUE(r.clusterIrradiance == w.clusterIrradiance);
  ASSERT_EQ(r.links.size(), w.links.size());
  for (size_t i = 0; i < w.links.size(); ++i) {
    const GlobalLink &a = r.links[i], &b = w.links[i];
    EXPECT_TRUE(a.receiver == b.receiver && a.shooter == b.shooter && a.firstKey == b.firstKey &&
                a.lastKey == b.lastKey && a.sampleOffset == b.sampleOffset &&
                a.sampleCount == b.sampleCount && a.flags == b.flags)
        << i;
  }
  EXPECT_TRUE(r.linkValues == w.linkValues);
  EXPECT_TRUE(r.linkVisibility == w.linkVisibility);
  EXPECT_EQ(r.badPairs, w.badPairs);
  ASSERT_EQ(r.reports.size(), 2u);
  EXPECT_EQ(r.reports[1].links, w.reports[1].links);
  EXPECT_GT(w.links.size(), 0u);
  const nlohmann::json summary = summarizeKeyWindow(reader);
  EXPECT_EQ(summary["window"]["first_key"], 1) << summary.dump();
  EXPECT_EQ(summary["link_rows"]["total"], w.links.size()) << summary.dump();
  // The run check: same parameters and scene pass; others are named.
  requireSameRun(reader, kParameters, hashFile(scenePath()));
  expectOneLineError(
      [&] {
        requireSameRun(reader, {{"eps", 2e-2}}, hashFile(scenePath()));
      },
      path, "built with --eps 0.01; this run expects 0.02");
  expectOneLineError([&] { requireSameRun(reader, kParameters, "fnv1a64:0000000000000000"); }, path,
                     "was computed from another scene");
  std::filesystem::remove(path);
}

TEST(KeyWindowFile, TruncatedOrCorruptedFileIsOneLineError) {
  const Scene scene = readGltfScene(scenePath());
  const std::string path = written(scene, "corrupt.rkw");
  const std::string bytes = [&] {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }();
  auto readBytes = [&](const std::string& b) {
    readKeyWindow(ContainerReader::fromBytes(std::vector<uint8_t>(b.begin(), b.end()), path),
                  scene);
  };
  for (size_t keep : {bytes.size() - 1, bytes.size() / 2, size_t(20)})
    expectOneLineError([&] { readBytes(bytes.substr(0, keep)); }, path, "truncated");
  std::mt19937 rng(17);
  for (int i = 0; i < 200; ++i) {
    std::string b = bytes;
    b[rng() % b.size()] ^= char(1 + rng() % 255);
    expectOneLineError([&] { readBytes(b); }, path, "");
  }
  std::filesystem::remove(path);
}

// Checksums valid, content not: every index the merge uses is checked before it is used.
TEST(KeyWindowFile, InconsistentContentIsOneLineError) {
  const Scene scene = readGltfScene(scenePath());
  const std::string path = written(scene, "content.rkw");
  auto read = [&](const ContainerReader& r) { readKeyWindow(r, scene); };
  expectOneLineError(
      [&] { read(rewritten(path, "links", [](std::vector<uint32_t>& v) { v[0] = 1u << 30; })); },
      path, "link row 0 is out of range");
  expectOneLineError(
      [&] { read(rewritten(path, "links", [](std::vector<uint32_t>& v) { v[3] = 7; })); }, path,
      "link row 0 is out of range");  // last key past the window
  expectOneLineError(
      [&] {
        read(rewritten(path, "links", [](std::vector<uint32_t>& v) { v[4] = ~uint32_t(0); }));
      },
      path, "link row 0 is out of range");  // value offset past the values
  expectOneLineError(
      [&] { read(rewritten(path, "key_node_count", [](std::vector<uint32_t>& v) { v[0] += 1; })); },
      path, "node count");
  expectOneLineError(
      [&] {
        read(rewritten(path, "key_node_count", [](std::vector<uint32_t>& v) { v.pop_back(); }));
      },
      path, "array 'key_node_count' has 1 values; expected 2");
  expectOneLineError(
      [&] { read(rewritten(path, "bad_pairs", [](std::vector<uint32_t>& v) { v[0] = 9999; })); },
      path, "bad pair 0");
  expectOneLineError(
      [&] {
        read(rewritten(path, "", nullptr, {2, 0}));
      },
      path, "keywindow 2.0 is newer than supported 1.x");
  Scene other = scene;
  other.nodes[size_t(other.meshNodes().back())].mesh = -1;  // one object fewer
  expectOneLineError([&] { readKeyWindow(ContainerReader::open(path), other); }, path,
                     "top-level patches");
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace rad
