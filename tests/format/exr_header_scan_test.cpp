// The EXR header pre-scan (formats/exr_header_scan.h, issue 18): what rad writes passes; an
// attribute larger than the file, a huge data window on a tiny file, a chunk table that cannot
// fit, hostile counts inside values and every truncation of a header are refused with one line
// naming the file, by every EXR reader, before OpenEXR allocates what the header declares. The
// fuzzers' 476-byte frame (1.9 GB and 5.8 s in the frame readers before) is refused in bounded
// memory.
#include "formats/exr_header_scan.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include "formats/checksum.h"
#include "formats/exr_image.h"
#include "formats/exr_info.h"
#include "formats/frame_image.h"
#include "formats/item_buffer_exr.h"
#include "formats/pixel_checksum.h"
#include "formats/texture_movie.h"
#include "libcommon/core/error.h"

namespace fs = std::filesystem;

namespace rad {
namespace {

class ExrHeaderScanTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) /
           ("rad_exr_header_scan_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

std::vector<uint8_t> bytesOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

void writeBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

// An OpenEXR file byte by byte (the layout in formats/exr_header_scan.cpp).
struct ExrBytes {
  std::vector<uint8_t> b;
  explicit ExrBytes(uint32_t flags = 0) {
    u32(20000630);
    u32(2 | flags);
  }
  void u32(uint32_t v) {
    for (int i = 0; i < 4; ++i) b.push_back(uint8_t(v >> (8 * i)));
  }
  void text(const std::string& s) {
    b.insert(b.end(), s.begin(), s.end());
    b.push_back(0);
  }
  void attribute(const std::string& name, const std::string& type, uint32_t size,
                 const std::vector<uint8_t>& value) {
    text(name);
    text(type);
    u32(size);
    b.insert(b.end(), value.begin(), value.end());
  }
  // Channels of one pixel type (0 UINT, 1 HALF, 2 FLOAT), compression, data window: the
  // attributes the scan needs of a part.
  void part(const std::vector<std::string>& channels, int pixelType, int compression, int32_t x1,
            int32_t y1) {
    ExrBytes list(0);
    list.b.clear();
    for (const std::string& c : channels) {
      list.text(c);
      list.u32(uint32_t(pixelType));
      list.u32(0);  // pLinear, reserved
      list.u32(1);
      list.u32(1);  // sampling
    }
    list.b.push_back(0);
    attribute("channels", "chlist", uint32_t(list.b.size()), list.b);
    attribute("compression", "compression", 1, {uint8_t(compression)});
    ExrBytes box(0);
    box.b.clear();
    for (int32_t v : {0, 0, x1, y1}) box.u32(uint32_t(v));
    attribute("dataWindow", "box2i", 16, box.b);
  }
  void end() { b.push_back(0); }
  void zeros(size_t n) { b.insert(b.end(), n, 0); }
};

// The scan's error for these bytes ("" if it accepts them).
std::string scanError(const std::vector<uint8_t>& bytes) {
  try {
    scanExrHeaders(bytes.data(), bytes.size(), "x.exr");
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kBadInput);
    return e.what();
  }
  return "";
}

ComposedFrame sampleFrame(int w, int h) {
  ComposedFrame f;
  f.size = {w, h};
  f.rgb.resize(size_t(w) * size_t(h) * 3);
  for (size_t i = 0; i < f.rgb.size(); ++i) f.rgb[i] = 0.25f * float(i % 17);
  return f;
}

TextureMovie sampleMovie() {
  TextureMovie m;
  m.movie = 3;
  m.patch = PatchId{2, 1};
  m.firstFrame = 0;
  m.lastFrame = 6;
  m.width = 4;
  m.height = 3;
  for (int k = 0; k < 2; ++k) {
    m.keyFrames.push_back(6 * k);
    m.keyTimes.push_back(6 * k / 24.0);
    m.keys.emplace_back(size_t(m.width) * m.height * 3, float(k + 1));
  }
  return m;
}

TEST_F(ExrHeaderScanTest, AcceptsWhatRadWrites) {
  writeFrameExr(path("f.exr"), sampleFrame(7, 5), {}, false, 0);
  writeFrameExr(path("h.exr"), sampleFrame(7, 5), {}, true, 3);  // HALF, ZIP
  writeExrImage(path("i.exr"), FloatImage(6, 4, {"R", "G", "B", "A"}));
  writeTextureMovie(path("m.exr"), sampleMovie());
  ExrHeaderScan s = scanExrFile(path("f.exr"));
  ASSERT_EQ(s.parts.size(), 1u);
  EXPECT_EQ(s.parts[0].type, "scanlineimage");
  EXPECT_EQ(s.parts[0].width, 7);
  EXPECT_EQ(s.parts[0].height, 5);
  EXPECT_EQ(s.parts[0].decodedBytes, 7u * 5 * 3 * 4);
  EXPECT_EQ(s.parts[0].chunks, 5u);
  EXPECT_EQ(s.headerBytes + 8 * 5 + 5 * (8 + 7 * 3 * 4), s.fileBytes);
  s = scanExrFile(path("h.exr"));
  EXPECT_EQ(s.parts[0].decodedBytes, 7u * 5 * 3 * 2);
  EXPECT_EQ(s.parts[0].chunks, 1u);  // ZIP: 16 lines a chunk
  EXPECT_EQ(scanExrFile(path("i.exr")).parts[0].channels, 4);
  s = scanExrFile(path("m.exr"));
  ASSERT_EQ(s.parts.size(), 2u);
  EXPECT_EQ(s.parts[1].chunks, 3u);
}

// headerHash is FNV-1a 64 of the bytes before the offset tables (rad-compose's movies input,
// formats/frame_image.md): a movie with other pixels has another rad.pixelChecksum in its header
// and so another hash; readTextureMovieHeaders carries it.
TEST_F(ExrHeaderScanTest, HeaderHashIsOfTheHeadersBytes) {
  writeTextureMovie(path("m.exr"), sampleMovie());
  const ExrHeaderScan s = scanExrFile(path("m.exr"));
  const std::vector<uint8_t> bytes = bytesOf(path("m.exr"));
  ASSERT_LT(s.headerBytes, bytes.size());
  EXPECT_EQ(s.headerHash, fnv1a64(bytes.data(), size_t(s.headerBytes)));
  EXPECT_EQ(readTextureMovieHeaders(path("m.exr")).headerHash, s.headerHash);
  TextureMovie other = sampleMovie();
  other.keys[1][5] = 7.0f;
  writeTextureMovie(path("o.exr"), other);
  EXPECT_NE(scanExrFile(path("o.exr")).headerHash, s.headerHash);
}

TEST_F(ExrHeaderScanTest, AttributeLargerThanTheFile) {
  ExrBytes x;
  x.part({"R"}, 2, 0, 0, 0);
  x.attribute("rad.format", "string", 1u << 30, {'f', 'r', 'a', 'm', 'e'});
  x.zeros(64);
  const std::string e = scanError(x.b);
  EXPECT_EQ(e,
            "x.exr: part 0: attribute 'rad.format' (string) declares 1073741824 bytes, the "
            "file has 69 left");
  // A negative size, and one a byte past the end.
  ExrBytes n;
  n.part({"R"}, 2, 0, 0, 0);
  n.attribute("note", "string", 0xffffff00u, {});
  EXPECT_NE(scanError(n.b).find("declares -256 bytes"), std::string::npos) << scanError(n.b);
  ExrBytes p;
  p.part({"R"}, 2, 0, 0, 0);
  p.attribute("note", "string", 5, {'a', 'b', 'c', 'd'});
  EXPECT_NE(scanError(p.b).find("declares 5 bytes, the file has 4 left"), std::string::npos)
      << scanError(p.b);
}

TEST_F(ExrHeaderScanTest, HugeDataWindowOnATinyFile) {
  // 65536^2 FLOAT RGB (48 GiB) in a 200-byte file, uncompressed and ZIP.
  for (int compression : {0, 3}) {
    ExrBytes x;
    x.part({"B", "G", "R"}, 2, compression, 65535, 65535);
    x.end();
    x.zeros(64);
    const std::string e = scanError(x.b);
    EXPECT_EQ(e.rfind("x.exr: part 0: data window 65536x65536 of 3 channel(s) decodes to "
                      "51539607552 bytes, more than a " +
                          std::to_string(x.b.size()) + "-byte file can hold",
                      0),
              0u)
        << e;
  }
  // One line of 2^19 HALF (1 MiB) with ZIP, whose decoder holds 16 lines (OpenEXR allocates a
  // whole chunk's buffer whatever the window's height).
  ExrBytes wide;
  wide.part({"Y"}, 1, 3, (1 << 19) - 1, 0);
  wide.end();
  wide.zeros(64);
  EXPECT_NE(scanError(wide.b).find("part 0: a chunk of scan lines decodes to 16777216 bytes"),
            std::string::npos)
      << scanError(wide.b);
  // A tile of 2^20 x 2^20 on a 1x1 image.
  ExrBytes tile(0x200);
  tile.part({"Y"}, 1, 0, 0, 0);
  tile.attribute("tiles", "tiledesc", 9, {0, 0, 16, 0, 0, 0, 16, 0, 0});
  tile.end();
  tile.zeros(64);
  EXPECT_NE(scanError(tile.b).find("part 0: a tile decodes to"), std::string::npos)
      << scanError(tile.b);
}

TEST_F(ExrHeaderScanTest, ChunkTableThatCannotFit) {
  // 1 x 200000 HALF, uncompressed: 400 KB decoded (under the 1 MiB any file may decode to),
  // but 200000 chunks need a 1.6 MB offset table.
  ExrBytes x;
  x.part({"Y"}, 1, 0, 0, 199999);
  x.end();
  x.zeros(1000);
  EXPECT_NE(scanError(x.b).find("x.exr: chunk offset tables of 200000 chunks (1600000 bytes) do "
                                "not fit in the 1000 bytes after the headers"),
            std::string::npos)
      << scanError(x.b);
  // A multi-part file's chunkCount counts too.
  ExrBytes m(0x1000);
  m.part({"Y"}, 1, 0, 0, 0);
  m.attribute("chunkCount", "int", 4, {0, 0, 0, 1});
  m.attribute("type", "string", 13,
              {'s', 'c', 'a', 'n', 'l', 'i', 'n', 'e', 'i', 'm', 'a', 'g', 'e'});
  m.end();
  m.end();
  m.zeros(100);
  EXPECT_NE(scanError(m.b).find("chunk offset tables of 16777216 chunks"), std::string::npos)
      << scanError(m.b);
}

TEST_F(ExrHeaderScanTest, HostileCountsInsideValues) {
  ExrBytes preview;  // 65535^2 RGBA pixels declared in an 8-byte preview
  preview.part({"R"}, 2, 0, 0, 0);
  preview.attribute("preview", "preview", 8, {0xff, 0xff, 0, 0, 0xff, 0xff, 0, 0});
  preview.end();
  preview.zeros(64);
  EXPECT_NE(scanError(preview.b).find("preview 'preview' declares 65535x65535 pixels in 8 bytes"),
            std::string::npos)
      << scanError(preview.b);
  ExrBytes strings;  // a 2^30-byte string declared inside a 6-byte string vector
  strings.part({"R"}, 2, 0, 0, 0);
  strings.attribute("names", "stringvector", 6, {0, 0, 0, 0x40, 'a', 'b'});
  strings.end();
  strings.zeros(64);
  EXPECT_NE(scanError(strings.b).find("string vector 'names' declares a string of 1073741824"),
            std::string::npos)
      << scanError(strings.b);
  // A fixed-size type of another size: OpenEXR reads 16 bytes of a box2i whatever its size
  // says and parses the rest as the next attributes (the fuzzers' box2i-wrong-size.exr: a
  // 126-byte displayWindow, then a 1.6 GB string OpenEXR tried to read).
  ExrBytes box;
  box.part({"R"}, 2, 0, 0, 0);
  box.attribute("displayWindow", "box2i", 20, std::vector<uint8_t>(20, 0));
  box.end();
  box.zeros(64);
  EXPECT_NE(scanError(box.b).find("part 0: attribute 'displayWindow' has 20 bytes, expected 16"),
            std::string::npos)
      << scanError(box.b);
  ExrBytes list;  // a channel list whose end marker comes before the attribute's end
  list.part({"R"}, 2, 0, 0, 0);
  list.attribute("extra", "chlist", 4, {0, 'x', 'y', 0});
  list.end();
  list.zeros(64);
  EXPECT_NE(scanError(list.b).find("channel list ends before its attribute does"),
            std::string::npos)
      << scanError(list.b);
  ExrBytes sampling;
  sampling.part({"R"}, 2, 0, 0, 0);
  sampling.b[8 + 9 + 7 + 4 + 2 + 8] = 0;  // R's xSampling: 0
  EXPECT_NE(scanError(sampling.b).find("channel 'R' has sampling 0x1"), std::string::npos)
      << scanError(sampling.b);
}

TEST_F(ExrHeaderScanTest, EveryTruncatedHeaderIsRefused) {
  writeFrameExr(path("f.exr"), sampleFrame(3, 2), {}, false, 0);
  writeTextureMovie(path("m.exr"), sampleMovie());
  for (const char* name : {"f.exr", "m.exr"}) {
    const std::vector<uint8_t> bytes = bytesOf(path(name));
    const uint64_t headerBytes = scanExrFile(path(name)).headerBytes;
    for (size_t n = 0; n < headerBytes; ++n) {
      const std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + std::ptrdiff_t(n));
      const std::string e = scanError(cut);
      EXPECT_FALSE(e.empty()) << name << " cut at " << n;
      EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
    // Through the file, as the readers call it.
    writeBytes(path("cut.exr"), std::vector<uint8_t>(bytes.begin(), bytes.begin() + 100));
    EXPECT_THROW(scanExrFile(path("cut.exr")), Error);
  }
  EXPECT_EQ(scanError({0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0, 'c'}),
            "x.exr: OpenEXR header cut short at byte 9");
  EXPECT_EQ(scanError({'P', 'K', 3, 4, 2, 0, 0, 0}),
            "x.exr: not an OpenEXR file (no magic number 20000630)");
}

// An attribute larger than the file, through every reader of EXR files: one line naming the
// file, the scan's message (not OpenEXR's, which came after allocating the size).
TEST_F(ExrHeaderScanTest, EveryReaderRefusesBeforeOpenExrReads) {
  writeFrameExr(path("f.exr"), sampleFrame(3, 2), {}, false, 0);
  std::vector<uint8_t> bytes = bytesOf(path("f.exr"));
  const char kName[] = "rad.format";
  auto at = std::search(bytes.begin(), bytes.end(), kName, kName + sizeof kName);
  ASSERT_NE(at, bytes.end());
  const size_t size = size_t(at - bytes.begin()) + sizeof kName + sizeof "string";
  bytes[size + 3] = 0x70;  // 1.9 GB
  const std::string file = path("hostile.exr");
  writeBytes(file, bytes);
  const std::vector<std::pair<const char*, std::function<void()>>> readers = {
      {"readFrameExr", [&] { readFrameExr(file); }},
      {"readExrImage", [&] { readExrImage(file); }},
      {"readExrInfo", [&] { readExrInfo(file); }},
      {"verifyExrPixels", [&] { verifyExrPixels(file); }},
      {"readTextureMovie", [&] { readTextureMovie(file); }},
      {"readTextureMovieHeaders", [&] { readTextureMovieHeaders(file); }},
      {"TextureMovieStream", [&] { TextureMovieStream stream(file); }},
      {"readItemBufferExr", [&] { readItemBufferExr(file); }},
  };
  for (const auto& [name, read] : readers) {
    try {
      read();
      ADD_FAILURE() << name << " accepted it";
    } catch (const Error& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind(file + ": part 0: attribute 'rad.format' (string) declares ", 0), 0u)
          << name << ": " << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << name << ": " << m;
    }
  }
}

// The fuzzers' frame (tests/data/fuzz-regressions/frame/oom-string-attributes.exr, 476 bytes):
// before the scan OpenEXR allocated and zero-filled its declared strings, 1.9 GB of resident
// memory in each frame reader. Measured in a child process (its peak resident size, before and
// after), so this test's own allocations do not count.
// A fuzzed frame, through every EXR reader in a child process: refused with one line naming the
// file, and the child's peak memory grows by less than 16 MiB.
void expectRefusedInBoundedMemory(const std::string& name) {
  SCOPED_TRACE(name);
  const std::string file = std::string(RAD_TEST_DATA) + "/fuzz-regressions/frame/" + name;
  ASSERT_TRUE(fs::exists(file));
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::close(fds[0]);
    struct rusage before, after;
    ::getrusage(RUSAGE_SELF, &before);
    std::string report;
    for (const auto& read : std::vector<std::function<void()>>{
             [&] { readFrameExr(file); }, [&] { readExrImage(file); }, [&] { readExrInfo(file); },
             [&] { verifyExrPixels(file); }}) {
      try {
        read();
        report += "accepted;";
      } catch (const Error& e) {
        const std::string m = e.what();
        if (m.rfind(file + ": ", 0) != 0 || m.find('\n') != std::string::npos)
          report += "bad message: " + m + ";";
      } catch (const std::exception& e) {
        report += std::string("not rad::Error: ") + e.what() + ";";
      }
    }
    ::getrusage(RUSAGE_SELF, &after);
    report = std::to_string(after.ru_maxrss - before.ru_maxrss) + " " + report;
    if (::write(fds[1], report.data(), report.size()) < 0) ::_exit(2);
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string report;
  char buffer[512];
  for (ssize_t n; (n = ::read(fds[0], buffer, sizeof buffer)) > 0;)
    report.append(buffer, size_t(n));
  ::close(fds[0]);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "child died: " << status;
  const long growthKb = std::stol(report);
  const std::string problems = report.substr(report.find(' ') + 1);
  EXPECT_EQ(problems, "");
  // 16 MiB: the readers need kilobytes for a file of a few hundred bytes.
  EXPECT_LT(growthKb, 16 * 1024) << "peak resident memory grew by " << growthKb << " KiB";
}

// 476 bytes declaring a string attribute of 1.9 GB, which OpenEXR allocated (before the scan).
TEST_F(ExrHeaderScanTest, FuzzedFrameIsRefusedInBoundedMemory) {
  expectRefusedInBoundedMemory("oom-string-attributes.exr");
}

// 214 bytes, single-part, flagged deep (0x800) but without a "type" attribute: OpenEXR reads it
// as a scan line image of 134 M x 1 pixels (1.6 GB of floats); the scan had taken the flag's
// word for it and bounded it as deep data, whose sizes are in its chunks (the frame harness's
// long run, 463,164 executions in).
TEST_F(ExrHeaderScanTest, DeepFlagWithoutATypeIsBoundedAsTheImageOpenExrReads) {
  expectRefusedInBoundedMemory("deep-flag-without-type.exr");
}

}  // namespace
}  // namespace rad
