// Provenance strings that are not UTF-8 (issue 18): argv and paths are bytes, JSON strings must
// be UTF-8, and nlohmann::json throws type_error 316 when it dumps one that is not. A tool run
// with such an argument must still write its outputs (the bytes shown as U+FFFD), and a damaged
// provenance read from a file is one line naming it.
#include "formats/provenance.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "formats/container.h"
#include "libcommon/core/error.h"

namespace fs = std::filesystem;

namespace rad {
namespace {

const std::string kReplacement = "\xef\xbf\xbd";  // U+FFFD

TEST(ProvenanceUtf8, ArgumentsThatAreNotUtf8AreWrittenReplaced) {
  const fs::path dir =
      fs::path(::testing::TempDir()) / ("rad_provenance_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string latin1 = "caf\xe9";  // "café" in Latin-1
  const char* argv[] = {"rad-test", "-o", latin1.c_str()};
  Provenance p = makeProvenance("rad-test", 3, argv, {{"output", latin1}, {latin1, 1}});
  InputRecord in;
  in.path = "scene-\xff.gltf";
  in.hash = "fnv1a64:0000000000000000";
  p.inputs.push_back(in);
  const nlohmann::json j = p.toJson();
  EXPECT_NO_THROW(j.dump());
  EXPECT_EQ(j["command_line"], "rad-test -o 'caf" + kReplacement + "'");
  EXPECT_EQ(j["parameters"]["output"], "caf" + kReplacement);
  EXPECT_TRUE(j["parameters"].contains("caf" + kReplacement));
  EXPECT_EQ(j["inputs"][0]["path"], "scene-" + kReplacement + ".gltf");
  // A container carrying it is written and read back.
  ContainerWriter w("sample", 1, 0);
  w.setProvenance(p);
  w.addArray<float>("x", {1.0f});
  const std::string path = (dir / "sample.rad").string();
  w.write(path);
  EXPECT_EQ(ContainerReader::open(path).provenance().commandLine,
            "rad-test -o 'caf" + kReplacement + "'");
  fs::remove_all(dir);
}

TEST(ProvenanceUtf8, ValidationFollowsRfc3629) {
  EXPECT_EQ(firstInvalidUtf8("plain ascii"), std::string::npos);
  EXPECT_EQ(firstInvalidUtf8("caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80"), std::string::npos);
  EXPECT_EQ(firstInvalidUtf8("ab\xc0\xaf"), 2u);         // overlong '/'
  EXPECT_EQ(firstInvalidUtf8("\xed\xa0\x80"), 0u);       // surrogate U+D800
  EXPECT_EQ(firstInvalidUtf8("x\xf4\x90\x80\x80"), 1u);  // above U+10FFFF
  EXPECT_EQ(firstInvalidUtf8("abc\xe2\x82"), 3u);        // cut short
  EXPECT_EQ(toValidUtf8("a\xff"
                        "b\xc3\xa9"),
            "a" + kReplacement + "b\xc3\xa9");
}

TEST(ProvenanceUtf8, DamagedProvenanceTextIsOneLineNamingTheFile) {
  auto errorOf = [](const std::string& text) {
    try {
      parseProvenanceJson(text, "movies/000001.exr: part 0: rad.provenance");
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ExitCode::kBadInput);
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(errorOf("{\"tool\":\"rad-m\xf6vies\"}"),
            "movies/000001.exr: part 0: rad.provenance: provenance is not valid UTF-8 (byte "
            "14): the file is damaged");
  EXPECT_EQ(errorOf("{\"tool\":\"rad-movies\"\n"),
            "movies/000001.exr: part 0: rad.provenance: provenance is not valid JSON (byte "
            "22): the file is damaged");
  EXPECT_NE(errorOf("[1, 2]").find("not a JSON object"), std::string::npos);
  EXPECT_EQ(errorOf("{\"tool\":\"rad-movies\"}"), "");
}

}  // namespace
}  // namespace rad
