// rad-inspect: shows what is inside any file of the toolchain (docs/design.md §6.5 "rad-inspect"),
// like Radiance's getinfo: a container's header, provenance and arrays; what the toolchain
// sees in a glTF scene; an OpenEXR file's parts and attributes.
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>

#include "formats/container.h"
#include "formats/exr_info.h"
#include "formats/file_kind.h"
#include "formats/gltf_file_access.h"
#include "formats/gltf_inputs.h"
#include "formats/gltf_scene.h"
#include "formats/gltf_scene_file.h"
#include "formats/inspect_kinds.h"
#include "formats/pixel_checksum.h"
#include "formats/provenance.h"
#include "formats/texture_movie.h"
#include "libcommon/radiosity/global_stage.h"
#include "libcommon/scene/frame_range.h"
#include "libcommon/scene/render_readiness.h"
#include "libcommon/scene/scene_summary.h"
#include "tools/common/tool_main.h"

namespace {

constexpr const char* kTool = "rad-inspect";

struct Options {
  std::vector<std::string> files;
  bool json = false;
  bool check = false;
  std::string array;          // dump one array of a container
  std::string inputs;         // --inputs: the files a scene is made of, with hashes
  std::string defaultFrames;  // --default-frames: the frames a stage covers without --frames
  std::string preflight;      // --preflight: can the pipeline render this scene at all
  double fps = rad::GlobalOptions{}.fps;  // --fps for --default-frames: the stages' default
};

// count, min, max and non-finite count of one array, whatever its dtype.
template <class T>
nlohmann::json statsOf(const rad::ContainerReader& r, const rad::ArrayInfo& a) {
  std::vector<T> v = r.array<T>(a.name);
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  uint64_t nonFinite = 0;
  for (const T& x : v) {
    double d = double(x);
    if (!std::isfinite(d)) {
      ++nonFinite;
      continue;
    }
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  nlohmann::json s = {{"count", v.size()}, {"non_finite", nonFinite}};
  if (lo <= hi) s["min"] = lo, s["max"] = hi;
  return s;
}

nlohmann::json arrayStats(const rad::ContainerReader& r, const rad::ArrayInfo& a) {
  switch (a.dtype) {
    case rad::DType::kU8:
      return statsOf<uint8_t>(r, a);
    case rad::DType::kU16:
      return statsOf<uint16_t>(r, a);
    case rad::DType::kU32:
      return statsOf<uint32_t>(r, a);
    case rad::DType::kU64:
      return statsOf<uint64_t>(r, a);
    case rad::DType::kI32:
      return statsOf<int32_t>(r, a);
    case rad::DType::kI64:
      return statsOf<int64_t>(r, a);
    case rad::DType::kF32:
      return statsOf<float>(r, a);
    case rad::DType::kF64:
      return statsOf<double>(r, a);
  }
  return {};
}

template <class T>
nlohmann::json valuesOf(const rad::ContainerReader& r, const std::string& name) {
  return r.array<T>(name);
}

nlohmann::json arrayValues(const rad::ContainerReader& r, const rad::ArrayInfo& a) {
  switch (a.dtype) {
    case rad::DType::kU8:
      return valuesOf<uint8_t>(r, a.name);
    case rad::DType::kU16:
      return valuesOf<uint16_t>(r, a.name);
    case rad::DType::kU32:
      return valuesOf<uint32_t>(r, a.name);
    case rad::DType::kU64:
      return valuesOf<uint64_t>(r, a.name);
    case rad::DType::kI32:
      return valuesOf<int32_t>(r, a.name);
    case rad::DType::kI64:
      return valuesOf<int64_t>(r, a.name);
    case rad::DType::kF32:
      return valuesOf<float>(r, a.name);
    case rad::DType::kF64:
      return valuesOf<double>(r, a.name);
  }
  return {};
}

nlohmann::json inspectContainer(const std::string& path, const Options& o, std::string& text) {
  rad::ContainerReader r = rad::ContainerReader::open(path);
  if (!o.array.empty()) {
    const rad::ArrayInfo& a = r.info(o.array);
    nlohmann::json values = arrayValues(r, a);
    // Rows of the last dimension, one per line, so the output pipes into awk or gnuplot.
    size_t row = a.shape.size() > 1 ? size_t(a.shape.back()) : 1;
    std::ostringstream os;
    for (size_t i = 0; i < values.size(); ++i) {
      os << values[i].dump() << ((i + 1) % row == 0 ? "\n" : " ");
    }
    text = os.str();
    return {{"path", path}, {"array", a.name}, {"shape", a.shape}, {"values", values}};
  }
  nlohmann::json j;
  j["path"] = path;
  j["type"] = "container";
  j["kind"] = r.kind();
  j["kind_version"] = {r.kindVersion().first, r.kindVersion().second};
  j["provenance"] = r.provenance().toJson();
  j["metadata"] = r.metadata();
  nlohmann::json arrays = nlohmann::json::array();
  std::ostringstream os;
  os << r.summary();
  os << "provenance:\n" << r.provenance().toText();
  os << "array summaries:\n";
  for (const rad::ArrayInfo& a : r.arrays()) {
    nlohmann::json s = arrayStats(r, a);
    arrays.push_back(
        {{"name", a.name}, {"dtype", rad::dtypeName(a.dtype)}, {"shape", a.shape}, {"stats", s}});
    os << "  " << a.name << ": " << s.dump() << "\n";
  }
  j["arrays"] = arrays;
  // What the stage that wrote it knows about its content (movies, links, ...).
  nlohmann::json content = rad::summarizeContainerContent(r);
  if (!content.is_null()) {
    j["content"] = content;
    os << "content:\n" << rad::contentSummaryText(content);
  }
  text = os.str();
  return j;
}

// Every pixel of the file read and checked against its parts' checksums: a truncated or
// corrupted movie or frame is an error, not a header that looks fine. A texture movie is read
// as rad-compose reads it (every key, finite values, consistent parts).
nlohmann::json verifyExr(const std::string& path, const nlohmann::json& info) {
  const nlohmann::json& attrs = info["parts"][0]["attributes"];
  const auto format = attrs.find("rad.format");
  if (info["written_by_rad"].get<bool>() && format != attrs.end() && format->is_string() &&
      format->get<std::string>().rfind("texture-movie ", 0) == 0) {
    const rad::TextureMovie movie = rad::readTextureMovie(path);
    return {{"parts", movie.keys.size()}, {"checksummed_parts", movie.keys.size()}};
  }
  return rad::verifyExrPixels(path);
}

nlohmann::json inspectOne(const std::string& path, const Options& o, std::string& text) {
  if (std::filesystem::is_directory(path)) {
    nlohmann::json s = rad::summarizeTextureMovieDirectory(path);
    std::ostringstream os;
    os << path << ": texture movies\n";
    for (const auto& [k, v] : s.items())
      if (k != "type" && k != "path") os << "  " << k << ": " << v.dump() << "\n";
    text = os.str();
    return s;
  }
  // A FIFO or device is refused before detectFileKind opens it (a FIFO would block).
  if (const std::string why = rad::regularFileProblem(path); !why.empty() && why != "no such file")
    throw rad::inputError(path, why);
  rad::FileKind kind = rad::detectFileKind(path);
  switch (kind) {
    case rad::FileKind::kMissing:
      throw rad::inputError(path, std::filesystem::is_directory(path)
                                      ? "is a directory"
                                      : "cannot open (missing or unreadable)");
    case rad::FileKind::kContainer:
      return inspectContainer(path, o, text);
    case rad::FileKind::kGltfJson:
    case rad::FileKind::kGltfBinary: {
      rad::Scene scene = rad::readGltfScene(path);
      nlohmann::json s = rad::summarizeScene(scene);
      s["type"] = "gltf";
      text = rad::sceneSummaryText(s);
      return s;
    }
    case rad::FileKind::kOpenExr: {
      nlohmann::json info = rad::readExrInfo(path);
      info["path"] = rad::toValidUtf8(path);
      info["type"] = "openexr";
      info["pixels"] = verifyExr(path, info);
      std::ostringstream os;
      // A valid OpenEXR file rad did not write (or another program re-saved): summarised, not
      // an error; its rad.* attributes, if any, are those of the file it was made from.
      if (!info["written_by_rad"].get<bool>())
        os << path << ": EXR not written by rad (" << info["foreign_writer"].get<std::string>()
           << "), " << info["parts"].size() << " part(s), pixels read\n";
      else
        os << path << ": OpenEXR, " << info["parts"].size() << " part(s), pixels read, "
           << info["pixels"]["checksummed_parts"] << " verified against rad.pixelChecksum\n";
      for (const auto& p : info["parts"]) {
        os << "  part '" << p["name"].get<std::string>() << "' " << p["width"] << "x" << p["height"]
           << " channels " << p["channels"].dump() << " compression "
           << p["compression"].get<std::string>() << "\n";
        for (const auto& [k, v] : p["attributes"].items())
          os << "    " << k << " = " << v.dump() << "\n";
      }
      text = os.str();
      return info;
    }
    default:
      throw rad::inputError(
          path, std::string("not a file rad-inspect knows (") + rad::fileKindName(kind) + ")");
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Shows what is inside a rad file (container, glTF scene, OpenEXR, texture-movie folder)."};
  Options o;
  rad::setUpApp(app, kTool, "rad-inspect out/global.rlh --array radiosity");
  CLI::Option* files =
      app.add_option("FILE", o.files, "files to inspect (required unless --inputs)");
  app.add_flag("--json", o.json, "print JSON on stdout instead of text");
  app.add_flag("--check", o.check, "validate only: print 'FILE: ok' or the error");
  app.add_option("--array", o.array, "dump one array of a container file");
  app.add_option("--inputs", o.inputs,
                 "instead: print 'HASH<TAB>PATH' for SCENE and each external buffer and image it "
                 "references (a missing image: 'missing'), for make's dependencies; decodes "
                 "nothing")
      ->option_text("SCENE")
      ->excludes(files);
  CLI::Option* defaultFrames =
      app.add_option("--default-frames", o.defaultFrames,
                     "instead: print the frames every stage covers without --frames, FIRST-LAST "
                     "(the scene's animation at --fps, docs/design.md §1), for a Makefile")
          ->option_text("SCENE")
          ->excludes(files)
          ->excludes("--inputs");
  app.add_option("--preflight", o.preflight,
                 "instead: check that SCENE has a camera and something that emits, before the "
                 "pipeline's first stage (docs/design.md §7); print 'SCENE: ok' or one line "
                 "saying what to export, exit 1")
      ->option_text("SCENE")
      ->excludes(files)
      ->excludes("--inputs")
      ->excludes(defaultFrames);
  app.add_option("--fps", o.fps, "frames per second for --default-frames")
      ->capture_default_str()
      ->check(rad::positiveFinite())
      ->needs(defaultFrames);
  if (int rc = rad::parseCommandLine(app, kTool, argc, argv); rc >= 0) return rc;
  // The summary shows a scene's warnings; stderr need not repeat them.
  rad::setGltfWarningHandler(nullptr);
  if (!o.defaultFrames.empty())
    return rad::runTool(kTool, [&]() {
      std::cout << rad::animationFrames(rad::readGltfScene(o.defaultFrames), o.fps).toString()
                << "\n";
      return 0;
    });
  if (!o.preflight.empty())
    return rad::runTool(kTool, [&]() {
      rad::requireRenderReadiness(rad::readGltfScene(o.preflight));
      std::cout << o.preflight << ": ok\n";
      return 0;
    });
  if (!o.inputs.empty())
    return rad::runTool(kTool, [&]() {
      std::cout << rad::gltfInputsText(rad::gltfInputs(o.inputs));
      return 0;
    });
  if (o.files.empty()) {
    std::cerr << kTool << ": FILE is required (try --help)\n";
    return int(rad::ExitCode::kUsage);
  }

  int worst = 0;
  nlohmann::json all = nlohmann::json::array();
  for (const std::string& path : o.files) {
    int rc = rad::runTool(kTool, [&]() {
      std::string text;
      nlohmann::json j = inspectOne(path, o, text);
      if (o.check) {
        std::cout << path << ": ok\n";
      } else if (o.json) {
        all.push_back(j);
      } else {
        std::cout << text;
      }
      return 0;
    });
    worst = std::max(worst, rc);
  }
  if (o.json && !o.check)
    std::cout << (all.size() == 1 ? all[0] : all)
                     .dump(1, ' ', false, nlohmann::json::error_handler_t::replace)
              << "\n";
  return rad::finishStdout(kTool, worst);
}
