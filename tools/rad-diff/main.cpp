// rad-diff: how far a rendered image or frame sequence is from a reference (docs/design.md §8,
// "error vs converged reference" and "temporal flicker"; §10, "How error is measured"):
// RMSE / mean and bias over the non-emitter pixels (emitters apart, a second reference's noise
// removed with --ref2), then RMSE, relative L2, max abs difference and PSNR over every sample,
// and the flicker of the test sequence where the reference is static.
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>
#include <regex>
#include <sstream>

#include <nlohmann/json.hpp>

#include "formats/exr_image.h"
#include "formats/exr_info.h"
#include "formats/gltf_scene.h"
#include "formats/item_buffer_exr.h"
#include "libcommon/reference/image_difference.h"
#include "tools/common/tool_main.h"

namespace {

constexpr const char* kTool = "rad-diff";
namespace fs = std::filesystem;

struct Options {
  std::string test, reference, reference2, emitterMask, surfaces, scene;
  bool json = false;
  std::string channels = "R,G,B";
  double staticTolerance = 0.0;
  rad::EmitterRule emitters;
};

std::vector<std::string> splitChannels(const std::string& spec) {
  std::vector<std::string> names;
  std::stringstream in(spec);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item.empty()) throw rad::Error(rad::ExitCode::kUsage, "--channels", "empty channel name");
    names.push_back(item);
  }
  if (names.empty()) throw rad::Error(rad::ExitCode::kUsage, "--channels", "no channel named");
  return names;
}

// Frames NNNN.exr (any number of digits) of a directory, by frame number.
std::map<int, std::string> frameFiles(const std::string& dir) {
  static const std::regex pattern("([0-9]+)\\.exr");
  std::map<int, std::string> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    std::smatch m;
    const std::string name = e.path().filename().string();
    if (e.is_regular_file() && std::regex_match(name, m, pattern))
      files[std::stoi(m[1].str())] = e.path().string();
  }
  return files;
}

// JSON has no infinity: +inf PSNR (identical images) is written as null, text says "inf".
nlohmann::json number(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json();
}
std::string text(double x) {
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  if (std::isnan(x)) return "n/a";
  std::ostringstream os;
  os << std::setprecision(6) << x;
  return os.str();
}

// One "difference" object: the docs/design.md §10 figures first (over non-emitter pixels, emitters
// apart), then the figures over every sample that bench.py and tradeoff.py read (rmse,
// relative_l2 normalised by the reference RMS, max_abs, psnr_db), with their meaning unchanged.
nlohmann::json statsJson(const rad::DifferenceStats& s, const rad::ErrorFigures& e, bool oneFrame) {
  const rad::PixelSetStats &n = e.surfaces, &m = e.emitters;
  nlohmann::json j = {{"rmse_over_mean", number(n.rmseOverMean())},
                      {"bias", number(n.bias())},
                      {"mean_reference", n.meanReference()},
                      {"surface_pixels", n.pixels},
                      {"emitter_pixels", m.pixels},
                      {"emitter_rmse_over_mean", number(m.rmseOverMean())},
                      {"emitter_bias", number(m.bias())},
                      {"samples", s.samples},
                      {"non_finite", s.nonFinite},
                      {"rmse", number(s.rmse())},
                      {"relative_l2", number(s.relativeL2())},
                      {"max_abs", s.maxAbsDifference},
                      {"psnr_db", number(s.psnr())},
                      {"reference_peak", number(s.referencePeak)}};
  if (n.twoReferences) {
    j["noise_over_mean"] = number(n.noiseOverMean());
    j["raw_rmse_over_mean"] = number(n.rawRmseOverMean());
  }
  if (oneFrame) j["emitter_threshold"] = number(e.emitterThreshold);
  return j;
}

std::string errorText(const rad::ErrorFigures& e) {
  const rad::PixelSetStats &n = e.surfaces, &m = e.emitters;
  std::ostringstream os;
  os << "rmse/mean " << text(n.rmseOverMean()) << "  bias " << text(n.bias());
  if (n.twoReferences)
    os << "  (noise/mean " << text(n.noiseOverMean()) << ", raw rmse/mean "
       << text(n.rawRmseOverMean()) << ")";
  os << " over " << n.pixels << " non-emitter px;  emitters " << m.pixels << " px";
  if (m.pixels > 0) os << " rmse/mean " << text(m.rmseOverMean());
  return os.str();
}

std::string statsText(const rad::DifferenceStats& s, const char* relativeLabel) {
  std::ostringstream os;
  os << "rmse " << text(s.rmse()) << "  " << relativeLabel << " " << text(s.relativeL2())
     << "  max_abs " << text(s.maxAbsDifference) << "  psnr " << text(s.psnr()) << " dB (peak "
     << text(s.referencePeak) << ")";
  if (s.nonFinite > 0) os << "  non_finite " << s.nonFinite;
  return os.str();
}

constexpr const char* kLongRelative =
    "relative L2 (normalised by the reference RMS; dominated by visible emitters)";

std::string emitterRuleText(const Options& o) {
  if (o.emitterMask.empty()) return o.emitters.toString();
  return "first channel > 0.5 in " + o.emitterMask;
}

// An emitter mask: the first channel the file lists (EXR lists channels by name, so a mask
// should have one channel), read alone.
rad::FloatImage readEmitterMask(const std::string& path) {
  const nlohmann::json info = rad::readExrInfo(path);
  const nlohmann::json& channels = info["parts"][0]["channels"];
  if (channels.empty()) throw rad::inputError(path, "emitter mask has no channel");
  return rad::readExrImage(path, {channels[0]["name"].get<std::string>()});
}

// Per-surface figures (--surfaces ITEMS --scene SCENE): each pixel's group is the glTF node and
// material of the patch rad-intervals' item buffer saw there. Item ids are dense node indices + 1
// of the regular subdivision (formats/texture_intervals.md): the top-level patches 0..T-1, then
// four children per node in order, so node j >= T has parent (j - T) / 4.
struct SurfaceGroups {
  std::vector<std::string> names;  // per group: "node (material)"
  const rad::Scene* scene = nullptr;
  std::vector<int> groupOfTop;  // per top-level patch

  explicit SurfaceGroups(const rad::Scene& s) : scene(&s) {
    const std::vector<rad::InputPolygon>& tops = s.inputPolygons();
    std::map<std::pair<int, int>, int> groupOf;  // (mesh node, material)
    for (const rad::InputPolygon& p : tops) {
      auto [it, fresh] = groupOf.emplace(std::pair(p.node, p.material), int(names.size()));
      if (fresh) names.push_back(nameOf(s, p));
      groupOfTop.push_back(it->second);
    }
  }

  // "node (material)", by glTF name where there is one.
  static std::string nameOf(const rad::Scene& s, const rad::InputPolygon& p) {
    std::string node =
        p.node >= 0 && p.node < int(s.nodes.size()) && !s.nodes[size_t(p.node)].name.empty()
            ? s.nodes[size_t(p.node)].name
            : "node " + std::to_string(p.node);
    std::string material =
        p.material < 0 ? "default"
        : p.material < int(s.materials.size()) && !s.materials[size_t(p.material)].name.empty()
            ? s.materials[size_t(p.material)].name
            : "material " + std::to_string(p.material);
    return node + " (" + material + ")";
  }

  rad::PixelGroups of(const std::string& itemsPath, const rad::FloatImage& like) const {
    const rad::ItemBuffer items = rad::readItemBufferExr(itemsPath);
    if (items.width != like.width || items.height != like.height)
      throw rad::inputError(itemsPath, "item buffer is " + std::to_string(items.width) + "x" +
                                           std::to_string(items.height) + ", the images " +
                                           std::to_string(like.width) + "x" +
                                           std::to_string(like.height));
    const uint64_t T = groupOfTop.size();
    rad::PixelGroups g;
    g.count = int(names.size());
    g.ofPixel.assign(items.id.size(), -1);
    for (size_t p = 0; p < items.id.size(); ++p) {
      if (items.id[p] == rad::kNoItem || items.id[p] == 0) continue;
      uint64_t node = items.id[p] - 1;
      while (node >= T) node = (node - T) / 4;
      g.ofPixel[p] = groupOfTop[size_t(node)];
    }
    return g;
  }
};

nlohmann::json surfacesJson(const rad::ErrorFigures& e, const SurfaceGroups& sg) {
  nlohmann::json a = nlohmann::json::array();
  for (size_t g = 0; g < e.groups.size(); ++g) {
    const rad::PixelSetStats& s = e.groups[g];
    if (s.pixels == 0) continue;
    a.push_back({{"surface", sg.names[g]},
                 {"pixels", s.pixels},
                 {"mean_reference", s.meanReference()},
                 {"bias", number(s.bias())},
                 {"rmse_over_mean", number(s.rmseOverMean())}});
  }
  return a;
}

std::string surfacesText(const rad::ErrorFigures& e, const SurfaceGroups& sg) {
  std::ostringstream os;
  os << "  per surface (node and material; non-emitter pixels): pixels, mean(ref), bias, "
        "rmse/mean\n";
  for (size_t g = 0; g < e.groups.size(); ++g) {
    const rad::PixelSetStats& s = e.groups[g];
    if (s.pixels == 0) continue;
    os << "    " << std::left << std::setw(28) << sg.names[g] << std::right << std::setw(8)
       << s.pixels << "  " << std::setw(10) << text(s.meanReference()) << "  " << std::setw(10)
       << text(s.bias()) << "  " << text(s.rmseOverMean()) << "\n";
  }
  return os.str();
}

std::string legend(const Options& o) {
  return std::string(
             "  rmse/mean and bias over the pixels that are not emitters (docs/design.md "
             "§10)") +
         (o.reference2.empty() ? "" : ", the references' noise removed") +
         "; emitters: " + emitterRuleText(o) + "\n";
}

// Two single files.
void compareFiles(const Options& o, const std::vector<std::string>& channels, nlohmann::json& j,
                  std::ostream& out) {
  rad::FloatImage test = rad::readExrImage(o.test, channels);
  rad::FloatImage reference = rad::readExrImage(o.reference, channels);
  rad::FloatImage reference2;
  if (!o.reference2.empty()) reference2 = rad::readExrImage(o.reference2, channels);
  rad::FloatImage mask;
  if (!o.emitterMask.empty()) mask = readEmitterMask(o.emitterMask);
  rad::DifferenceStats s = rad::compareImages(test, reference, o.test);
  std::optional<rad::Scene> scene;
  std::optional<SurfaceGroups> sg;
  rad::PixelGroups groups;
  if (!o.surfaces.empty()) {
    scene = rad::readGltfScene(o.scene);
    sg.emplace(*scene);
    groups = sg->of(o.surfaces, reference);
  }
  rad::ErrorFigures e = rad::measureError(
      test, reference, o.reference2.empty() ? nullptr : &reference2, o.emitters, o.test,
      o.reference2, o.emitterMask.empty() ? nullptr : &mask, o.emitterMask, sg ? &groups : nullptr);
  j["size"] = {test.width, test.height};
  j["difference"] = statsJson(s, e, true);
  if (sg) j["per_surface"] = surfacesJson(e, *sg);
  out << o.test << " vs " << o.reference;
  if (!o.reference2.empty()) out << " and " << o.reference2;
  out << " (" << test.width << "x" << test.height << ", " << o.channels << "):\n"
      << legend(o) << "  " << errorText(e);
  if (o.emitterMask.empty()) out << " (emitter threshold " << text(e.emitterThreshold) << ")";
  out << "\n  every pixel: " << statsText(s, kLongRelative) << "\n";
  if (sg) out << surfacesText(e, *sg);
}

// Two (or three, with --ref2) frame directories, matched by frame number.
void compareDirectories(const Options& o, const std::vector<std::string>& channels,
                        nlohmann::json& j, std::ostream& out) {
  std::map<int, std::string> tests = frameFiles(o.test), refs = frameFiles(o.reference);
  std::map<int, std::string> refs2, masks, items;
  if (!o.reference2.empty()) refs2 = frameFiles(o.reference2);
  if (!o.emitterMask.empty()) masks = frameFiles(o.emitterMask);
  std::optional<rad::Scene> scene;
  std::optional<SurfaceGroups> sg;
  if (!o.surfaces.empty()) {
    items = frameFiles(o.surfaces);
    scene = rad::readGltfScene(o.scene);
    sg.emplace(*scene);
  }
  std::vector<int> frames;
  int onlyTest = 0;
  for (const auto& [f, p] : tests) {
    if (refs.count(f))
      frames.push_back(f);
    else
      ++onlyTest;
  }
  const int onlyReference = int(refs.size()) - int(frames.size());
  if (frames.empty())
    throw rad::inputError(o.test, "no frame NNNN.exr in common with " + o.reference);
  for (int f : frames)
    for (const auto& [dir, files] :
         {std::pair(&o.reference2, &refs2), std::pair(&o.emitterMask, &masks),
          std::pair(&o.surfaces, &items)})
      if (!dir->empty() && !files->count(f))
        throw rad::inputError(*dir, "no frame " + std::to_string(f) + " (" +
                                        fs::path(refs[f]).filename().string() +
                                        " is in the reference)");
  rad::SequenceDifference seq = rad::compareSequence(
      frames,
      [&](int f) {
        rad::FrameImages im{rad::readExrImage(tests[f], channels),
                            rad::readExrImage(refs[f], channels),
                            rad::FloatImage(),
                            rad::FloatImage(),
                            {}};
        rad::requireSameShape(im.test, im.reference, tests[f]);
        if (!o.reference2.empty()) {
          im.reference2 = rad::readExrImage(refs2[f], channels);
          rad::requireSameShape(im.reference2, im.reference, refs2[f]);
        }
        if (!o.emitterMask.empty()) im.emitterMask = readEmitterMask(masks[f]);
        if (sg) im.groups = sg->of(items[f], im.reference);
        return im;
      },
      o.staticTolerance, o.emitters);
  j["frames_compared"] = frames.size();
  j["frames_only_in_test"] = onlyTest;
  j["frames_only_in_reference"] = onlyReference;
  j["difference"] = statsJson(seq.total, seq.totalError, false);
  if (sg) j["per_surface"] = surfacesJson(seq.totalError, *sg);
  j["flicker"] = {{"mean_abs", seq.flicker.mean()},
                  {"max_abs", seq.flicker.maxAbsChange},
                  {"static_pixels", seq.flicker.staticPixels},
                  {"frame_pairs", seq.flicker.framePairs},
                  {"static_tolerance", o.staticTolerance}};
  nlohmann::json per = nlohmann::json::array();
  out << o.test << " vs " << o.reference;
  if (!o.reference2.empty()) out << " and " << o.reference2;
  out << ": " << frames.size() << " frame(s) compared";
  if (onlyTest + onlyReference > 0)
    out << " (" << onlyTest << " only in test, " << onlyReference << " only in reference)";
  out << "\n" << legend(o);
  for (const rad::FrameDifference& fd : seq.frames) {
    nlohmann::json fj = statsJson(fd.stats, fd.error, true);
    fj["frame"] = fd.frame;
    per.push_back(fj);
    out << "  frame " << std::setw(4) << std::setfill('0') << fd.frame << std::setfill(' ') << ": "
        << errorText(fd.error) << "  |  " << statsText(fd.stats, "relative_l2") << "\n";
  }
  j["per_frame"] = per;
  out << "  all frames (pooled): " << errorText(seq.totalError)
      << "\n  all frames, every pixel: " << statsText(seq.total, kLongRelative) << "\n";
  out << "  flicker: mean |test(n+1)-test(n)| " << text(seq.flicker.mean()) << " (max "
      << text(seq.flicker.maxAbsChange) << ") over " << seq.flicker.staticPixels
      << " static pixel(s) in " << seq.flicker.framePairs << " frame pair(s)\n";
  if (sg) out << surfacesText(seq.totalError, *sg);
}

int run(const Options& o) {
  const std::vector<std::string> channels = splitChannels(o.channels);
  if (o.emitters.threshold && !(*o.emitters.threshold >= 0.0))
    throw rad::Error(rad::ExitCode::kUsage, "--emitter-threshold", "must be >= 0");
  std::vector<std::string> inputs = {o.test, o.reference};
  if (o.surfaces.empty() != o.scene.empty())
    throw rad::Error(rad::ExitCode::kUsage, o.surfaces.empty() ? "--scene" : "--surfaces",
                     "--surfaces and --scene go together");
  for (const std::string& p : {o.reference2, o.emitterMask, o.surfaces, o.scene})
    if (!p.empty()) inputs.push_back(p);
  for (const std::string& p : inputs)
    if (!fs::exists(p)) throw rad::inputError(p, "cannot open (missing)");
  const bool testDir = fs::is_directory(o.test), refDir = fs::is_directory(o.reference);
  if (testDir != refDir)
    throw rad::Error(rad::ExitCode::kUsage, o.test,
                     "TEST and REFERENCE must both be .exr files or both directories");
  for (const auto& [path, flag] :
       {std::pair(o.reference2, "--ref2"), std::pair(o.emitterMask, "--emitter-mask"),
        std::pair(o.surfaces, "--surfaces")})
    if (!path.empty() && fs::is_directory(path) != refDir)
      throw rad::Error(rad::ExitCode::kUsage, path,
                       std::string(flag) +
                           " must be of the reference's kind (.exr file or "
                           "directory)");
  nlohmann::json j;
  j["test"] = o.test;
  j["reference"] = o.reference;
  if (!o.reference2.empty()) j["reference2"] = o.reference2;
  j["channels"] = channels;
  if (!o.emitterMask.empty()) j["emitter_mask"] = o.emitterMask;
  j["emitter_rule"] = emitterRuleText(o);
  std::ostringstream out;
  if (!testDir)
    compareFiles(o, channels, j, out);
  else
    compareDirectories(o, channels, j, out);
  if (o.json)
    std::cout << j.dump(1) << "\n";
  else
    std::cout << out.str();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Compares a test image or frame directory (NNNN.exr) with a reference.\n"
      "\n"
      "First, the error figure of docs/design.md §10, over the pixels that are not emitters,\n"
      "channels pooled (JSON: rmse_over_mean, bias):\n"
      "  rmse/mean = sqrt(mean((test - ref)^2)) / mean(ref);  bias = mean(test - ref) / "
      "mean(ref).\n"
      "Emitter pixels (a visible light) are reported apart (emitter_pixels,\n"
      "emitter_rmse_over_mean). By default a pixel is an emitter when its reference luminance\n"
      "Y = 0.2126 R + 0.7152 G + 0.0722 B exceeds 10 x the median Y of the lit (Y > 0)\n"
      "reference pixels of its frame: the median, unlike the mean, is not lifted by the light it\n"
      "is to find, and lit diffuse walls stay within a few times the typical wall while a visible\n"
      "light is far above it. --emitter-threshold or --emitter-mask replace the rule.\n"
      "With --ref2 (a second reference of another seed) the references' own noise is removed:\n"
      "  noise^2 = mean((ref - ref2)^2) / 2 (noise_over_mean),\n"
      "  rmse^2 = (rmse(test, ref)^2 + rmse(test, ref2)^2) / 2 - noise^2,\n"
      "and mean and bias are taken against (ref + ref2) / 2.\n"
      "\n"
      "Then, over every sample and against REFERENCE alone: rmse, relative_l2 =\n"
      "||test - ref|| / ||ref|| (normalised by the reference RMS, so dominated by visible\n"
      "emitters), max abs difference, PSNR (peak = max of the reference) and, for sequences, the\n"
      "temporal flicker of the test where the reference does not change. Totals over a sequence\n"
      "pool the sums of every frame."};
  Options o;
  rad::setUpApp(app, kTool, "rad-diff out/frames ref-seed1/frames --ref2 ref-seed2/frames --json");
  app.add_option("TEST", o.test, "test .exr file or directory of NNNN.exr")->required();
  app.add_option("REFERENCE", o.reference, "reference .exr file or directory of NNNN.exr")
      ->required();
  app.add_option("--ref2", o.reference2,
                 "second reference of another seed (same kind and frames as REFERENCE): removes "
                 "the references' noise from rmse/mean");
  auto* threshold =
      app.add_option(
             "--emitter-threshold", o.emitters.threshold,
             "a pixel whose reference luminance Y exceeds this is an emitter (default: 10 x "
             "the median Y of the lit reference pixels, per frame)")
          ->check(rad::nonNegativeFinite());
  app.add_option("--emitter-mask", o.emitterMask,
                 "EXR (or directory of NNNN.exr, like REFERENCE) whose first channel > 0.5 marks "
                 "the emitter pixels; replaces the luminance rule")
      ->excludes(threshold);
  app.add_option(
      "--surfaces", o.surfaces,
      "item buffer (rad-intervals --item-buffers; a file, or a directory like "
      "REFERENCE) of the frames: adds the figures per surface (glTF node and material) seen, "
      "which say where a bias is; needs --scene");
  app.add_option("--scene", o.scene, "the scene of --surfaces (its patches and materials)");
  app.add_flag("--json", o.json, "print JSON on stdout instead of text");
  app.add_option("--channels", o.channels,
                 "comma-separated channels to compare (luminance: Rec. 709 when R, G, B are all "
                 "present, else the channels' mean)")
      ->capture_default_str();
  app.add_option("--static-tolerance", o.staticTolerance,
                 "flicker: a reference pixel is static when no channel changes by more")
      ->capture_default_str()
      ->check(rad::nonNegativeFinite());
  if (int rc = rad::parseCommandLine(app, kTool, argc, argv); rc >= 0) return rc;
  return rad::runTool(kTool, [&]() { return run(o); });
}
