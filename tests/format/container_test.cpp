// Container and provenance format tests: round trips; truncated, corrupted, future-version and
// wrong-kind files give the documented one-line error naming the file; adversarial input never
// crashes (docs/conventions.md §6 "Tests").
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

#include "formats/atomic_file.h"
#include "formats/build_info.h"
#include "formats/checksum.h"
#include "formats/container.h"
#include "formats/provenance.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace rad {
namespace {

class ContainerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) /
           ("rad_container_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

std::vector<uint8_t> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void writeBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

// Expects `f` to throw rad::Error whose message starts with `where + ": "` and contains `part`.
template <class F>
void expectError(F&& f, const std::string& where, const std::string& part,
                 ExitCode code = ExitCode::kBadInput) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one containing: " << part;
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(where + ": ", 0), 0u) << msg;
    EXPECT_NE(msg.find(part), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_EQ(e.code(), code) << msg;
  }
}

Provenance sampleProvenance() {
  const char* argv[] = {"rad-global", "--eps", "0.01", "-o", "out dir/global.rlh", "scene.gltf"};
  return makeProvenance("rad-global", 6, argv, {{"eps", 0.01}, {"levels", 6}, {"mode", "fast"}});
}

ContainerWriter sampleWriter() {
  ContainerWriter w("linkhier", 1, 2);
  w.setProvenance(sampleProvenance());
  w.metadata()["frames"] = 400;
  w.metadata()["name"] = "shot1";
  w.addArray<uint32_t>("links", {1, 2, 3, 4, 5, 6}, {3, 2});
  w.addArray<float>("radiosity", {0.5f, 1e30f, -0.0f});
  w.addArray<uint8_t>("flags", {1, 0, 1});
  return w;
}

// A file with an arbitrary header text and a correct header checksum, to reach the JSON
// validation past the checksum.
std::vector<uint8_t> craft(const std::string& header, const std::vector<uint8_t>& data,
                           uint32_t major = 1, uint32_t minor = 0) {
  std::vector<uint8_t> out = ContainerWriter("x", 1, 0).serialize();
  out.resize(8);  // keep the magic
  auto put = [&](auto v) {
    const auto* p = reinterpret_cast<const uint8_t*>(&v);
    out.insert(out.end(), p, p + sizeof v);
  };
  put(major);
  put(minor);
  put(static_cast<uint64_t>(header.size()));
  put(fnv1a64(header.data(), header.size(), fnv1a64(out.data(), 24)));
  out.insert(out.end(), header.begin(), header.end());
  out.resize((out.size() + 63) / 64 * 64, 0);
  out.insert(out.end(), data.begin(), data.end());
  return out;
}

template <class T>
void roundTripDtype(const std::string& path, DType expected) {
  using L = std::numeric_limits<T>;
  std::vector<T> values = {L::lowest(), L::max(), T(0), T(1), L::min()};
  if constexpr (L::has_quiet_NaN) values.push_back(L::quiet_NaN());
  if constexpr (L::has_infinity) values.push_back(-L::infinity());
  const std::vector<std::vector<uint64_t>> shapes = {
      {}, {values.size()}, {1, values.size()}, {values.size(), 1, 1}};
  ContainerWriter w("test", 1, 0);
  for (std::size_t i = 0; i < shapes.size(); ++i)
    w.addArray("a" + std::to_string(i), values, shapes[i]);
  w.addArray("empty", std::vector<T>{});
  w.addArray("empty2d", std::vector<T>{}, {0, 7});
  w.write(path);

  const ContainerReader r = ContainerReader::open(path);
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    const std::string name = "a" + std::to_string(i);
    const ArrayInfo& a = r.info(name);
    EXPECT_EQ(a.dtype, expected);
    EXPECT_EQ(a.shape, shapes[i].empty() ? std::vector<uint64_t>{values.size()} : shapes[i]);
    EXPECT_EQ(a.offset % kContainerAlignment, 0u);
    EXPECT_EQ(reinterpret_cast<uintptr_t>(r.data(a)) % 8, 0u);
    const std::vector<T> back = r.array<T>(name);
    ASSERT_EQ(back.size(), values.size());
    // Bit-exact, NaN included.
    EXPECT_EQ(std::memcmp(back.data(), values.data(), values.size() * sizeof(T)), 0) << name;
  }
  EXPECT_TRUE(r.array<T>("empty").empty());
  EXPECT_EQ(r.info("empty2d").shape, (std::vector<uint64_t>{0, 7}));
  EXPECT_TRUE(r.array<T>("empty2d").empty());
}

TEST_F(ContainerTest, RoundTripsEveryDtypeAndShape) {
  roundTripDtype<uint8_t>(file("u8.rc"), DType::kU8);
  roundTripDtype<uint16_t>(file("u16.rc"), DType::kU16);
  roundTripDtype<uint32_t>(file("u32.rc"), DType::kU32);
  roundTripDtype<uint64_t>(file("u64.rc"), DType::kU64);
  roundTripDtype<int32_t>(file("i32.rc"), DType::kI32);
  roundTripDtype<int64_t>(file("i64.rc"), DType::kI64);
  roundTripDtype<float>(file("f32.rc"), DType::kF32);
  roundTripDtype<double>(file("f64.rc"), DType::kF64);
}

// write() streams the arrays to the file instead of assembling it in memory, and views
// (addArrayView / addRawView: the caller's bytes, not a copy) give the same file as copies:
// the bytes of serialize(), padding and empty arrays included.
TEST_F(ContainerTest, StreamedWriteAndViewsGiveTheSerializedBytes) {
  const std::vector<uint32_t> links = {1, 2, 3, 4, 5, 6};
  const std::vector<float> radiosity = {0.5f, 1e30f, -0.0f};
  const std::vector<uint8_t> flags = {1, 0, 1};
  const std::vector<double> empty;
  std::vector<uint8_t> odd(129);  // not a multiple of the alignment: padding follows
  for (std::size_t i = 0; i < odd.size(); ++i) odd[i] = uint8_t(i * 7 + 1);
  ContainerWriter copies("linkhier", 1, 2), views("linkhier", 1, 2);
  for (ContainerWriter* w : {&copies, &views}) {
    w->setProvenance(sampleProvenance());
    w->metadata()["frames"] = 400;
  }
  copies.addArray("links", links, {3, 2});
  copies.addArray("radiosity", radiosity);
  copies.addArray("empty", empty);
  copies.addArray("odd", odd);
  copies.addArray("flags", flags);
  views.addArrayView("links", links, {3, 2});
  views.addRawView("radiosity", DType::kF32, {3}, radiosity.data(), radiosity.size() * 4);
  views.addArrayView("empty", empty);
  views.addArrayView("odd", odd);
  views.addArrayView("flags", flags);
  const std::vector<uint8_t> serialized = copies.serialize();
  EXPECT_EQ(views.serialize(), serialized);
  copies.write(file("copies.rc"));
  views.write(file("views.rc"));
  EXPECT_EQ(readBytes(file("copies.rc")), serialized);
  EXPECT_EQ(readBytes(file("views.rc")), serialized);
  const ContainerReader r = ContainerReader::open(file("views.rc"));
  EXPECT_EQ(r.array<uint8_t>("odd"), odd);
  EXPECT_EQ(r.array<uint8_t>("flags"), flags);
  EXPECT_TRUE(r.array<double>("empty").empty());
  // A view's shape is checked like a copy's.
  EXPECT_THROW(views.addArrayView("bad", links, {4, 2}), Error);
}

TEST_F(ContainerTest, LayoutIsAlignedAndSelfDescribing) {
  const std::vector<uint8_t> bytes = sampleWriter().serialize();
  EXPECT_EQ(bytes.size() % 64, 0u);
  EXPECT_EQ(std::memcmp(bytes.data(), "\x89RAD\r\n\x1a\n", 8), 0);
  uint32_t major, minor;
  uint64_t length;
  std::memcpy(&major, &bytes[8], 4);
  std::memcpy(&minor, &bytes[12], 4);
  std::memcpy(&length, &bytes[16], 8);
  EXPECT_EQ(major, 1u);
  EXPECT_EQ(minor, 0u);
  const json h = json::parse(bytes.begin() + 32, bytes.begin() + 32 + static_cast<long>(length));
  EXPECT_EQ(h["kind"], "linkhier");
  EXPECT_EQ(h["kind_version"], json({1, 2}));
  EXPECT_EQ(h["arrays"][0]["name"], "links");
  EXPECT_EQ(h["arrays"][0]["dtype"], "u32");
  EXPECT_EQ(h["arrays"][1]["offset"], 64);  // 24 bytes of links, padded to 64
  const uint64_t dataStart = (32 + length + 63) / 64 * 64;
  uint32_t first;
  std::memcpy(&first, &bytes[dataStart], 4);
  EXPECT_EQ(first, 1u);
}

TEST_F(ContainerTest, MetadataAndProvenanceRoundTrip) {
  const std::string path = file("global.rlh");
  sampleWriter().write(path);
  const ContainerReader r = ContainerReader::open(path);
  EXPECT_EQ(r.path(), path);
  EXPECT_EQ(r.kind(), "linkhier");
  EXPECT_EQ(r.kindVersion(), std::make_pair(1, 2));
  EXPECT_EQ(r.containerVersion(), std::make_pair(kContainerMajor, kContainerMinor));
  EXPECT_EQ(r.metadata()["frames"], 400);
  EXPECT_EQ(r.metadata()["name"], "shot1");
  EXPECT_TRUE(r.has("links"));
  EXPECT_FALSE(r.has("nope"));
  EXPECT_EQ(r.array<uint32_t>("links"), (std::vector<uint32_t>{1, 2, 3, 4, 5, 6}));
  const Provenance& p = r.provenance();
  EXPECT_EQ(p.tool, "rad-global");
  EXPECT_EQ(p.version, RAD_VERSION);
  EXPECT_EQ(p.gitRevision, gitRevision());
  EXPECT_EQ(p.commandLine, "rad-global --eps 0.01 -o 'out dir/global.rlh' scene.gltf");
  EXPECT_EQ(p.parameters, json({{"eps", 0.01}, {"levels", 6}, {"mode", "fast"}}));
  EXPECT_EQ(p.toJson(), sampleProvenance().toJson());
  EXPECT_NE(r.summary().find("links u32 [3, 2] 24 bytes fnv1a64:"), std::string::npos)
      << r.summary();
}

TEST_F(ContainerTest, NestedHistoryRoundTripsAndPrintsOldestFirst) {
  const std::string scene = file("scene.gltf");
  writeBytes(scene, {'{', '}'});
  Provenance g = sampleProvenance();
  addInput(g, scene);
  ASSERT_EQ(g.inputs.size(), 1u);
  EXPECT_TRUE(g.inputs[0].history.is_null());
  EXPECT_EQ(g.inputs[0].hash, hashFile(scene));

  ContainerWriter gw = sampleWriter();
  gw.setProvenance(g);
  const std::string global = file("global.rlh");
  gw.write(global);

  const char* argv[] = {"rad-movies", "global.rlh"};
  Provenance m = makeProvenance("rad-movies", 2, argv, {{"size", 64}});
  addInput(m, global);
  ASSERT_EQ(m.inputs.size(), 1u);
  EXPECT_EQ(m.inputs[0].path, global);
  EXPECT_EQ(m.inputs[0].hash, hashFile(global));
  EXPECT_EQ(m.inputs[0].history, g.toJson());

  // Same through an open reader (no second read).
  Provenance m2 = m;
  m2.inputs.clear();
  addInput(m2, ContainerReader::open(global));
  EXPECT_EQ(m2.toJson(), m.toJson());

  // Two levels down survive another round trip.
  ContainerWriter mw("movies", 1, 0);
  mw.setProvenance(m);
  mw.write(file("movies.rc"));
  const Provenance back = ContainerReader::open(file("movies.rc")).provenance();
  EXPECT_EQ(back.toJson(), m.toJson());
  const Provenance inner = Provenance::fromJson(back.inputs[0].history, "x");
  EXPECT_EQ(inner.inputs[0].path, scene);

  const std::string text = back.toText();
  const auto gPos =
      text.find(std::string("rad-global " RAD_VERSION " (git ") + gitRevision() + "): rad-global");
  const auto mPos = text.find("rad-movies " RAD_VERSION);
  EXPECT_NE(gPos, std::string::npos) << text;
  EXPECT_NE(mPos, std::string::npos) << text;
  EXPECT_LT(gPos, mPos) << text;
  EXPECT_NE(text.find("    input " + scene + " fnv1a64:"), std::string::npos) << text;
  EXPECT_NE(text.find("    parameters {\"eps\":0.01"), std::string::npos) << text;

  // A history shared by two inputs prints once.
  Provenance twice = m;
  twice.inputs.push_back(twice.inputs[0]);
  const std::string t2 = twice.toText();
  EXPECT_EQ(t2.find("rad-global " RAD_VERSION), t2.rfind("rad-global " RAD_VERSION)) << t2;
}

TEST_F(ContainerTest, ProvenanceFromJsonRejectsMalformed) {
  expectError([] { Provenance::fromJson(json::array(), "f.rlh: provenance"); }, "f.rlh: provenance",
              "not a JSON object");
  expectError([] { Provenance::fromJson({{"tool", 3}}, "f"); }, "f", "\"tool\" is not a string");
  expectError([] { Provenance::fromJson({{"inputs", {1}}}, "f"); }, "f", "not an object");
  expectError([] { Provenance::fromJson({{"parameters", "x"}}, "f"); }, "f", "parameters");
  // Absent keys are tolerated (older or hand-made files).
  EXPECT_EQ(Provenance::fromJson(json::object(), "f").tool, "");
}

TEST_F(ContainerTest, HashFileIsFnv1a64) {
  writeBytes(file("empty"), {});
  writeBytes(file("a"), {'a'});
  EXPECT_EQ(hashFile(file("empty")), "fnv1a64:cbf29ce484222325");
  EXPECT_EQ(hashFile(file("a")), "fnv1a64:af63dc4c8601ec8c");
  // Larger than the 1 MiB read chunk: same as hashing in one piece.
  std::vector<uint8_t> big(3 << 20);
  for (std::size_t i = 0; i < big.size(); ++i) big[i] = static_cast<uint8_t>(i * 2654435761u >> 13);
  writeBytes(file("big"), big);
  EXPECT_EQ(hashFile(file("big")), formatFnv1a64(fnv1a64(big.data(), big.size())));
  expectError([&] { hashFile(file("missing")); }, file("missing"), "cannot open");
  expectError([&] { hashFile(dir_.string()); }, dir_.string(), "not a regular file");
}

TEST_F(ContainerTest, ShellQuoteAndParameterMismatch) {
  EXPECT_EQ(shellQuote("frames/%04d.exr"), "frames/%04d.exr");
  EXPECT_EQ(shellQuote(""), "''");
  EXPECT_EQ(shellQuote("a b"), "'a b'");
  EXPECT_EQ(shellQuote("it's"), "'it'\\''s'");
  EXPECT_EQ(shellQuote("$HOME"), "'$HOME'");

  const json built = {{"eps", 0.02}, {"levels", 6}, {"mode", "fast"}, {"old", true}};
  const json expected = {{"eps", 0.01}, {"levels", 6.0}, {"mode", "slow"}, {"new", 3}};
  const auto m = parameterMismatch(built, expected, {"eps", "levels", "mode", "new", "old", "x"});
  ASSERT_EQ(m.size(), 4u);
  EXPECT_EQ(m[0], "built with --eps 0.02; this run expects 0.01");
  EXPECT_EQ(m[1], "built with --mode fast; this run expects slow");
  EXPECT_EQ(m[2], "built without --new; this run expects 3");
  EXPECT_EQ(m[3], "built with --old true; this run does not set it");
  EXPECT_TRUE(parameterMismatch(built, built, {"eps", "mode"}).empty());
  EXPECT_EQ(parameterMismatch(nullptr, expected, {"eps"}).size(), 1u);
}

TEST_F(ContainerTest, AtomicWriteLeavesNothingOnFailure) {
  const std::string bad = file("no-such-dir/global.rlh");
  expectError([&] { sampleWriter().write(bad); }, bad, "cannot create temporary file",
              ExitCode::kOutput);
  EXPECT_FALSE(fs::exists(bad));

  // Target is a directory: the rename fails after the temporary was written.
  const std::string asDir = file("taken");
  fs::create_directories(fs::path(asDir) / "child");
  expectError([&] { sampleWriter().write(asDir); }, asDir, "cannot rename", ExitCode::kOutput);

  // Success overwrites, and nothing but the targets remains in the directory.
  const std::string good = file("global.rlh");
  writeBytes(good, {'o', 'l', 'd'});
  sampleWriter().write(good);
  EXPECT_EQ(ContainerReader::open(good).kind(), "linkhier");
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"global.rlh", "taken"}));
}

TEST_F(ContainerTest, AtomicFileTempNameAndCleanup) {
  const std::string target = file("frames.exr");
  std::string temp;
  {
    AtomicFile f(target);
    temp = f.tempPath();
    EXPECT_EQ(fs::path(temp).parent_path(), dir_);
    const std::string name = fs::path(temp).filename().string();
    EXPECT_EQ(name.rfind(".frames.tmp.", 0), 0u) << name;  // hidden, not the target
    EXPECT_EQ(fs::path(temp).extension(), ".exr");         // OIIO picks the format by it
    writeBytes(temp, {1, 2, 3});
  }  // not committed
  EXPECT_FALSE(fs::exists(temp));
  EXPECT_FALSE(fs::exists(target));
  {
    AtomicFile f(target);
    writeBytes(f.tempPath(), {1, 2, 3});
    f.commit();
    EXPECT_TRUE(f.committed());
    EXPECT_FALSE(fs::exists(f.tempPath()));
  }
  EXPECT_EQ(readBytes(target), (std::vector<uint8_t>{1, 2, 3}));
  // Two at once get distinct temporaries; a bare name stays in the current directory.
  AtomicFile a("x.rlh"), b("x.rlh");
  EXPECT_NE(a.tempPath(), b.tempPath());
  EXPECT_EQ(a.tempPath().find('/'), std::string::npos);
  // Nothing written and not committed: commit reports it.
  AtomicFile c(file("never.rlh"));
  expectError([&] { c.commit(); }, file("never.rlh"), "cannot open temporary file",
              ExitCode::kOutput);
}

TEST_F(ContainerTest, AtomicFileDeferredDurability) {
  // kDeferred renames without syncing; the tool syncs the file system once at the end.
  const std::string target = file("000001.exr");
  std::string temp;
  {
    AtomicFile f(target, AtomicFile::Durability::kDeferred);
    temp = f.tempPath();
    writeBytes(temp, {4, 5});
    EXPECT_FALSE(fs::exists(target));  // invisible until committed
    f.commit();
  }
  EXPECT_FALSE(fs::exists(temp));
  EXPECT_EQ(readBytes(target), (std::vector<uint8_t>{4, 5}));
  {
    AtomicFile f(file("dropped.exr"), AtomicFile::Durability::kDeferred);
    temp = f.tempPath();
    writeBytes(temp, {6});
  }  // not committed: removed, as with kEachFile
  EXPECT_FALSE(fs::exists(temp));
  EXPECT_FALSE(fs::exists(file("dropped.exr")));
  // Nothing to rename: a one-line output error, not a silent success.
  AtomicFile never(file("never.exr"), AtomicFile::Durability::kDeferred);
  expectError([&] { never.commit(); }, file("never.exr"), "cannot rename", ExitCode::kOutput);
  syncFileSystemOf(dir_.string());
  expectError([&] { syncFileSystemOf(file("missing/dir")); }, file("missing/dir"),
              "cannot open to sync", ExitCode::kOutput);
}

TEST_F(ContainerTest, MissingFileAndNotAContainer) {
  expectError([&] { ContainerReader::open(file("missing.rlh")); }, file("missing.rlh"),
              "cannot open");
  writeBytes(file("scene.gltf"), {'{', '"', 'a', '"', ':', '1', '}', '\n'});
  expectError([&] { ContainerReader::open(file("scene.gltf")); }, file("scene.gltf"),
              "bad magic: not a rad container");
  EXPECT_FALSE(ContainerReader::looksLikeContainer(file("scene.gltf")));
  writeBytes(file("empty.rlh"), {});
  expectError([&] { ContainerReader::open(file("empty.rlh")); }, file("empty.rlh"), "truncated");
  expectError([&] { ContainerReader::open(dir_.string()); }, dir_.string(), "not a regular file");
}

TEST_F(ContainerTest, TruncatedByOneByte) {
  const std::string path = file("global.rlh");
  std::vector<uint8_t> bytes = sampleWriter().serialize();
  bytes.pop_back();
  writeBytes(path, bytes);
  expectError([&] { ContainerReader::open(path); }, path, "truncated: header says");
  bytes.push_back(0);
  bytes.push_back(0);
  writeBytes(path, bytes);
  expectError([&] { ContainerReader::open(path); }, path, "trailing data");
  // Cut inside the preamble and inside the header.
  for (std::size_t n : {std::size_t{5}, std::size_t{31}, std::size_t{40}}) {
    std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + static_cast<long>(n));
    expectError([&] { ContainerReader::fromBytes(cut, "cut.rlh"); }, "cut.rlh", "truncated");
  }
}

TEST_F(ContainerTest, EverySingleFlippedByteIsDetected) {
  const std::vector<uint8_t> good = sampleWriter().serialize();
  ASSERT_NO_THROW(ContainerReader::fromBytes(good, "g.rlh"));
  std::mt19937 rng(1);
  int detected = 0;
  for (std::size_t i = 0; i < good.size(); ++i) {
    for (uint8_t mask : {uint8_t{0x01}, uint8_t{0x80}, static_cast<uint8_t>(1 + rng() % 255)}) {
      std::vector<uint8_t> bad = good;
      bad[i] ^= mask;
      try {
        ContainerReader::fromBytes(bad, "g.rlh");
        ADD_FAILURE() << "flip 0x" << std::hex << int(mask) << " at byte " << std::dec << i
                      << " not detected";
      } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()).rfind("g.rlh: ", 0), 0u) << e.what();
        ++detected;
      }
    }
  }
  EXPECT_EQ(detected, static_cast<int>(good.size() * 3));
}

TEST_F(ContainerTest, FlippedBytesInEachRegionGiveTheRightMessage) {
  const std::string path = file("global.rlh");
  const std::vector<uint8_t> good = sampleWriter().serialize();
  uint64_t length;
  std::memcpy(&length, &good[16], 8);
  const std::size_t dataStart = (32 + length + 63) / 64 * 64;
  struct Case {
    std::size_t at;
    const char* message;
  };
  const Case cases[] = {
      {0, "bad magic"},
      {4, "bad magic"},
      {13, "header checksum mismatch"},  // minor version
      {17, "truncated"},                 // header length
      {26, "header checksum mismatch"},  // the checksum itself
      {40, "header checksum mismatch"},  // JSON text
      {32 + length - 1, "header checksum mismatch"},
      {dataStart - 1, "nonzero padding"},  // padding after the header
      {dataStart, "array 'links': checksum mismatch"},
      {dataStart + 30, "nonzero padding"},  // between arrays
      {dataStart + 64 + 4, "array 'radiosity': checksum mismatch"},
      {good.size() - 1, "nonzero padding"},  // tail padding
  };
  for (const Case& c : cases) {
    ASSERT_LT(c.at, good.size());
    std::vector<uint8_t> bad = good;
    bad[c.at] ^= 0x10;
    writeBytes(path, bad);
    SCOPED_TRACE("byte " + std::to_string(c.at));
    expectError([&] { ContainerReader::open(path); }, path, c.message);
  }
}

TEST_F(ContainerTest, FutureVersionsAreRefused) {
  const std::string path = file("global.rlh");
  std::vector<uint8_t> bytes = sampleWriter().serialize();
  bytes[8] = 2;  // container major
  writeBytes(path, bytes);
  expectError([&] { ContainerReader::open(path); }, path,
              "container 2.0 is newer than supported 1.x");
  bytes[8] = 0;
  writeBytes(path, bytes);
  expectError([&] { ContainerReader::open(path); }, path, "container 0.0 is older than supported");

  // A newer container minor only adds: accepted.
  EXPECT_NO_THROW(ContainerReader::fromBytes(
      craft(R"({"kind":"k","kind_version":[1,0],"metadata":{},"arrays":[],"future":1})", {}, 1, 7),
      "m.rc"));

  ContainerWriter w("linkhier", 2, 0);
  w.write(path);
  const ContainerReader r = ContainerReader::open(path);
  expectError([&] { r.requireKind("linkhier", 1); }, path,
              "linkhier 2.0 is newer than supported 1.x");
  expectError([&] { r.requireKind("linkhier", 3); }, path,
              "linkhier 2.0 is older than supported 3.x");
  EXPECT_NO_THROW(r.requireKind("linkhier", 2));
  ContainerWriter(std::string("linkhier"), 1, 9).write(path);
  EXPECT_NO_THROW(ContainerReader::open(path).requireKind("linkhier", 1));
}

TEST_F(ContainerTest, WrongKindAndArrayErrors) {
  const std::string path = file("shot.rti");
  ContainerWriter w("intervals", 1, 0);
  w.addArray<float>("times", {0.f, 1.f});
  w.write(path);
  const ContainerReader r = ContainerReader::open(path);
  expectError([&] { r.requireKind("linkhier", 1); }, path,
              "is an intervals file, expected linkhier");
  EXPECT_NO_THROW(r.requireKind("intervals", 1));
  expectError([&] { r.array<uint32_t>("times"); }, path, "array 'times' is f32, expected u32");
  expectError([&] { r.array<double>("times"); }, path, "array 'times' is f32, expected f64");
  expectError([&] { r.array<float>("links"); }, path, "no array 'links'");
  EXPECT_TRUE(r.provenance().tool.empty());  // none set: readable, empty
}

TEST_F(ContainerTest, WriterRejectsProgrammingErrors) {
  ContainerWriter w("k", 1, 0);
  w.addArray<float>("a", {1, 2, 3, 4}, {2, 2});
  EXPECT_THROW(w.addArray<float>("a", {1}), Error);
  EXPECT_THROW(w.addArray<float>("b", {1, 2, 3}, {2, 2}), Error);
  EXPECT_THROW(w.addArray<float>("", {1}), Error);
  try {
    w.addArray<float>("a", {1});
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kInternal);
  }
}

// Headers with a valid checksum but inconsistent content: the JSON validation itself.
TEST_F(ContainerTest, InconsistentHeadersAreRejected) {
  const std::vector<uint8_t> data(64, 0);
  const std::string ok = R"({"kind":"k","kind_version":[1,0],"metadata":{},"arrays":[)";
  const std::string zeroHash = formatFnv1a64(fnv1a64(data.data(), 8));
  auto arr = [&](const std::string& fields) { return ok + "{" + fields + "}]}"; };
  const std::string base = R"("name":"a","dtype":"u32","hash":")" + zeroHash + "\"";
  EXPECT_NO_THROW(ContainerReader::fromBytes(
      craft(arr(base + R"(,"shape":[2],"offset":0,"nbytes":8)"), data), "h.rc"));
  const std::pair<std::string, std::string> cases[] = {
      {"not json", "header is not valid JSON"},
      {"[1,2]", "header is not a JSON object"},
      {R"({"kind":"k","kind_version":[1,0],"arrays":[],"metadata":{"a":)" +
           std::string(100000, '[') + std::string(100000, ']') + "}}",
       "header nests deeper than 200 levels"},
      {R"({"kind":"k\nx","kind_version":[1,0],"metadata":{},"arrays":[]})", "unprintable"},
      {R"({"kind_version":[1,0],"metadata":{},"arrays":[]})",
       "missing, empty or unprintable \"kind\""},
      {R"({"kind":"k","kind_version":[1],"metadata":{},"arrays":[]})", "kind_version"},
      {R"({"kind":"k","kind_version":[-1,0],"metadata":{},"arrays":[]})", "kind_version"},
      {R"({"kind":"k","kind_version":[1,0],"metadata":[],"arrays":[]})", "metadata"},
      {R"({"kind":"k","kind_version":[1,0],"metadata":{}})", "\"arrays\" is not a list"},
      {R"({"kind":"k","kind_version":[1,0],"metadata":{},"arrays":[],"provenance":{"tool":1}})",
       "provenance: \"tool\" is not a string"},
      {ok + "3]}", "array #0 is not an object"},
      {arr(R"("dtype":"u32","shape":[2],"offset":0,"nbytes":8)"),
       "missing, empty or unprintable name"},
      {arr(R"("name":"a","dtype":"f16","shape":[2],"offset":0,"nbytes":8)"), "unknown dtype"},
      {arr(base + R"(,"shape":[2],"offset":0,"nbytes":12)"), "12 bytes do not match u32 shape [2]"},
      {arr(base + R"(,"shape":[-2],"offset":0,"nbytes":8)"), "bad shape"},
      {arr(base + R"(,"shape":[4294967296,4294967296],"offset":0,"nbytes":0)"), "do not match"},
      {arr(base + R"(,"shape":[2],"offset":4,"nbytes":8)"), "not 64-byte aligned"},
      {arr(base + R"(,"shape":[2],"offset":64,"nbytes":8)"), "truncated: header says"},
      {arr(base + R"(,"shape":[2],"offset":18446744073709551552,"nbytes":8)"),
       "extends past end of file"},
      {arr(base + R"(,"shape":[2],"nbytes":8)"), "missing offset or nbytes"},
      {arr(R"("name":"a","dtype":"u32","shape":[2],"offset":0,"nbytes":8)"), "missing hash"},
      {arr(R"("name":"a","dtype":"u32","hash":"fnv1a64:0000000000000000","shape":[2],)"
           R"("offset":0,"nbytes":8)"),
       "array 'a': checksum mismatch"},
      {ok + "{" + base + R"(,"shape":[2],"offset":0,"nbytes":8},{)" + base +
           R"(,"shape":[2],"offset":0,"nbytes":8}]})",
       "duplicate array 'a'"},
      {ok + "{" + base + R"(,"shape":[2],"offset":0,"nbytes":8},{)" +
           R"("name":"b","dtype":"u8","hash":"x","shape":[2],"offset":0,"nbytes":2}]})",
       "array 'b' overlaps the previous array"},
  };
  // Brackets inside strings (escaped quotes included) do not count as nesting.
  EXPECT_NO_THROW(ContainerReader::fromBytes(
      craft(R"({"kind":"k","kind_version":[1,0],"arrays":[],"metadata":{"s":"\"[)" +
                std::string(1000, '[') + "\"}}",
            {}),
      "h.rc"));
  for (const auto& [header, message] : cases) {
    SCOPED_TRACE(header);
    expectError([&] { ContainerReader::fromBytes(craft(header, data), "h.rc"); }, "h.rc", message);
  }
}

// Random corruption must give rad::Error or a valid reader, never a crash or another exception.
TEST_F(ContainerTest, RandomCorruptionNeverCrashes) {
  const std::vector<uint8_t> good = sampleWriter().serialize();
  uint64_t length;
  std::memcpy(&length, &good[16], 8);
  const std::string headerText(good.begin() + 32, good.begin() + 32 + static_cast<long>(length));
  const std::vector<uint8_t> data(good.begin() + static_cast<long>((32 + length + 63) / 64 * 64),
                                  good.end());
  std::mt19937_64 rng(12345);
  auto pick = [&](std::size_t n) { return n ? static_cast<std::size_t>(rng() % n) : 0; };
  const char kJsonish[] = "{}[]\":,0123456789-eE.tfnul \\";
  int errors = 0, accepted = 0;
  for (int iter = 0; iter < 6000; ++iter) {
    std::vector<uint8_t> bad;
    if (iter % 2 == 0) {
      // Raw bytes: flips, truncation, extension, random sizes in the preamble.
      bad = good;
      switch (iter / 2 % 5) {
        case 0:
          for (int k = 0, n = 1 + static_cast<int>(pick(8)); k < n; ++k)
            bad[pick(bad.size())] ^= static_cast<uint8_t>(1 + pick(255));
          break;
        case 1:
          bad.resize(pick(bad.size()));
          break;
        case 2:
          for (int k = 0, n = 1 + static_cast<int>(pick(200)); k < n; ++k)
            bad.push_back(static_cast<uint8_t>(rng()));
          break;
        case 3: {
          const uint64_t v = rng() >> pick(64);
          std::memcpy(&bad[16], &v, 8);
          break;
        }
        case 4:
          bad.assign(pick(300), 0);
          for (auto& c : bad) c = static_cast<uint8_t>(rng());
          break;
      }
    } else {
      // JSON mutations with a recomputed checksum, to exercise the header validation.
      std::string h = headerText;
      for (int k = 0, n = 1 + static_cast<int>(pick(4)); k < n; ++k) {
        const std::size_t at = pick(h.size());
        switch (pick(4)) {
          case 0:
            h[at] = kJsonish[pick(sizeof kJsonish - 1)];
            break;
          case 1:
            h.erase(at, 1 + pick(20));
            break;
          case 2:
            h.insert(at, 1, kJsonish[pick(sizeof kJsonish - 1)]);
            break;
          case 3:
            h[at] = static_cast<char>(rng());
            break;
        }
      }
      bad = craft(h, data);
    }
    try {
      const ContainerReader r = ContainerReader::fromBytes(bad, "fuzz.rlh");
      // Whatever was accepted must be safe to use.
      for (const ArrayInfo& a : r.arrays()) {
        if (a.dtype == DType::kU8) (void)r.array<uint8_t>(a.name);
      }
      (void)r.summary();
      (void)r.provenance().toText();
      ++accepted;
    } catch (const Error& e) {
      ASSERT_EQ(std::string(e.what()).rfind("fuzz.rlh: ", 0), 0u) << e.what();
      ++errors;
    } catch (const std::exception& e) {
      FAIL() << "iteration " << iter << ": non-rad exception: " << e.what();
    }
  }
  EXPECT_EQ(errors + accepted, 6000);
  EXPECT_GT(errors, 5000);
}

}  // namespace
}  // namespace rad
