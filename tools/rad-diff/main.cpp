// rad-diff: how far a rendered image or frame sequence is from a reference (docs/design.md §8,
// "error vs converged reference" and "temporal flicker"; §10, "How error is measured"):
// RMSE / mean and bias over the non-emitter pixels (emitters apart, a second reference's noise
// removed with --ref2), then RMSE, relative L2, max abs difference and PSNR over every sample,
// and the flicker of the test sequence where the reference is static. With an item buffer
// (--surfaces / --seams ITEMS --scene SCENE): the figure per surface, at edges and inside
// surfaces (§10.3), the structured error (§10.4) and the seams' steps (§10.5).
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
#include "formats/provenance.h"
#include "libcommon/reference/sequence_difference.h"
#include "tools/common/tool_main.h"
#include "tools/rad-diff/geometry_report.h"
#include "tools/rad-diff/item_surfaces.h"

namespace {

constexpr const char* kTool = "rad-diff";
namespace fs = std::filesystem;
using namespace rad::diff;  // this tool's report and item buffers

struct Options {
  std::string test, reference, reference2, emitterMask, surfaces, seams, scene, smoothedError;
  bool json = false;
  std::string channels = "R,G,B";
  double staticTolerance = 0.0;
  long long seamMinPairs = rad::kSeamMinPairs;
  rad::EmitterRule emitters;
  int argc = 0;  // the command line, for the provenance of --smoothed-error
  const char* const* argv = nullptr;
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

nlohmann::json surfacesJson(const rad::ErrorFigures& e, const std::vector<std::string>& names) {
  nlohmann::json a = nlohmann::json::array();
  for (size_t g = 0; g < e.groups.size(); ++g) {
    const rad::PixelSetStats& s = e.groups[g];
    if (s.pixels == 0) continue;
    a.push_back({{"surface", names[g]},
                 {"pixels", s.pixels},
                 {"mean_reference", s.meanReference()},
                 {"bias", number(s.bias())},
                 {"rmse_over_mean", number(s.rmseOverMean())}});
  }
  return a;
}

std::string surfacesText(const rad::ErrorFigures& e, const std::vector<std::string>& names) {
  std::ostringstream os;
  os << "  per surface (node and material; non-emitter pixels): pixels, mean(ref), bias, "
        "rmse/mean\n";
  for (size_t g = 0; g < e.groups.size(); ++g) {
    const rad::PixelSetStats& s = e.groups[g];
    if (s.pixels == 0) continue;
    os << "    " << std::left << std::setw(28) << names[g] << std::right << std::setw(8) << s.pixels
       << "  " << std::setw(10) << text(s.meanReference()) << "  " << std::setw(10)
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

// One frame's "difference" object: statsJson, then its regions and structured error when it
// had an item buffer (else why the structured error is missing).
nlohmann::json frameJson(const rad::FrameDifference& fd) {
  nlohmann::json j = statsJson(fd.stats, fd.error, true);
  if (!fd.error.regions.empty()) j["regions"] = regionsJson(fd.error);
  if (fd.structured) {
    j["structured_error"] = structuredJson(*fd.structured);
  } else {
    j["structured_error"] = nullptr;
    j["structured_error_unavailable"] = kStructuredUnavailable;
  }
  return j;
}

// The lines of one frame's geometry figures (regions, structured error), each indented.
std::string frameGeometryText(const rad::FrameDifference& fd, const std::string& indent) {
  std::string out;
  if (!fd.error.regions.empty()) out += indent + regionsText(fd.error) + "\n";
  if (fd.structured)
    out += indent + structuredText(*fd.structured) + "\n";
  else
    out += indent + "structured error: " + kStructuredUnavailable + "\n";
  return out;
}

// The item buffer of --surfaces or --seams (the same one when both are given).
const std::string& itemsPath(const Options& o) {
  return o.surfaces.empty() ? o.seams : o.surfaces;
}

// Writes a frame's smoothed difference image (--smoothed-error) with its provenance
// (docs/conventions.md §1): this command line, the options and the frame's input files.
std::function<void(const rad::FloatImage&)> smoothedWriter(const Options& o,
                                                           const std::string& path,
                                                           std::vector<std::string> inputs) {
  return [&o, path, inputs](const rad::FloatImage& image) {
    rad::Provenance p = rad::makeProvenance(kTool, o.argc, o.argv,
                                            {{"channels", o.channels},
                                             {"emitter-rule", emitterRuleText(o)},
                                             {"box", rad::kStructuredBox},
                                             {"edge-clearance", rad::kStructuredEdgeClearance}});
    for (const std::string& input : inputs)
      if (!input.empty()) p.inputs.push_back({input, rad::hashFile(input), nullptr});
    rad::writeExrImage(path, image,
                       {{"rad.provenance", p.toJson().dump()},
                        {"rad.description",
                         "structured error (docs/design.md §10.4): 7x7-smoothed luminance "
                         "error / mean reference luminance, 0 off the measured pixels"}});
  };
}

// Two single files.
void compareFiles(const Options& o, const std::vector<std::string>& channels, nlohmann::json& j,
                  std::ostream& out) {
  std::optional<ItemSurfaces> items;
  if (!itemsPath(o).empty()) items.emplace(o.scene);
  int width = 0, height = 0;
  const rad::SequenceDifference seq = rad::compareSequence(
      {0},
      [&](int) {
        rad::FrameImages im;
        im.test = rad::readExrImage(o.test, channels);
        im.reference = rad::readExrImage(o.reference, channels);
        if (!o.reference2.empty()) im.reference2 = rad::readExrImage(o.reference2, channels);
        if (!o.emitterMask.empty()) im.emitterMask = readEmitterMask(o.emitterMask);
        width = im.test.width;
        height = im.test.height;
        im.testWhere = o.test;
        im.reference2Where = o.reference2;
        im.maskWhere = o.emitterMask;
        if (items) {
          ItemSurfaces::Frame f = items->load(itemsPath(o), im.reference);
          if (!o.surfaces.empty()) im.groups = std::move(f.groups);
          im.surfaces = std::move(f.surfaces);
          if (!o.smoothedError.empty())
            im.smoothedSink = smoothedWriter(
                o, o.smoothedError, {o.test, o.reference, o.reference2, itemsPath(o), o.scene});
        }
        return im;
      },
      0.0, o.emitters);
  const rad::FrameDifference& fd = seq.frames[0];
  const rad::ErrorFigures& e = fd.error;
  j["size"] = {width, height};
  j["difference"] = frameJson(fd);
  if (!o.surfaces.empty()) j["per_surface"] = surfacesJson(e, items->names());
  auto patchName = [&](int p) { return items->patchName(p); };
  if (!o.seams.empty()) j["seams"] = seamsJson(seq.seams, o.seamMinPairs, patchName, false);
  out << o.test << " vs " << o.reference;
  if (!o.reference2.empty()) out << " and " << o.reference2;
  out << " (" << width << "x" << height << ", " << o.channels << "):\n"
      << legend(o) << "  " << errorText(e);
  if (o.emitterMask.empty()) out << " (emitter threshold " << text(e.emitterThreshold) << ")";
  out << "\n" << frameGeometryText(fd, "  ");
  out << "  every pixel: " << statsText(fd.stats, kLongRelative) << "\n";
  if (!o.surfaces.empty()) out << surfacesText(e, items->names());
  if (!o.seams.empty()) out << seamsText(seq.seams, o.seamMinPairs, patchName, false);
}
// The temporal error of docs/design.md §10.6, over all non-emitting pixels and, with an item
// buffer, over edge and interior pixels apart.
nlohmann::json temporalJson(const rad::TemporalError& t) {
  auto sums = [](const rad::TemporalSums& s) {
    return nlohmann::json{{"rmse_over_mean", s.rmseOverMean()},
                          {"raw_rmse_over_mean", s.rawRmseOverMean()},
                          {"samples", s.samples}};
  };
  nlohmann::json j = {{"frame_pairs", t.framePairs}, {"all", sums(t.all)}};
  if (t.haveEdges) {
    j["edge"] = sums(t.edge);
    j["interior"] = sums(t.interior);
  }
  return j;
}
std::string temporalText(const rad::TemporalError& t) {
  std::ostringstream s;
  s << "  temporal error (change n -> n+1 against the reference's, rmse/mean): "
    << text(t.all.rmseOverMean());
  if (t.haveEdges)
    s << "; edge " << text(t.edge.rmseOverMean()) << ", interior "
      << text(t.interior.rmseOverMean());
  s << " over " << t.framePairs << " frame pair(s)\n";
  return s.str();
}

// The JSON and text of a sequence's figures (compareDirectories); `items` null without an
// item buffer.
void reportSequence(const Options& o, const rad::SequenceDifference& seq, int onlyTest,
                    int onlyReference, const ItemSurfaces* items, nlohmann::json& j,
                    std::ostream& out) {
  j["frames_compared"] = seq.frames.size();
  j["frames_only_in_test"] = onlyTest;
  j["frames_only_in_reference"] = onlyReference;
  j["difference"] = statsJson(seq.total, seq.totalError, false);
  if (items) {
    j["difference"]["regions"] = regionsJson(seq.totalError);
    j["difference"]["structured_error"] = structuredSequenceJson(seq.frames);
  } else {
    j["difference"]["structured_error"] = nullptr;
    j["difference"]["structured_error_unavailable"] = kStructuredUnavailable;
  }
  if (!o.surfaces.empty()) j["per_surface"] = surfacesJson(seq.totalError, items->names());
  auto patchName = [&](int p) { return items->patchName(p); };
  if (!o.seams.empty()) j["seams"] = seamsJson(seq.seams, o.seamMinPairs, patchName, true);
  j["flicker"] = {{"mean_abs", seq.flicker.mean()},
                  {"max_abs", seq.flicker.maxAbsChange},
                  {"static_pixels", seq.flicker.staticPixels},
                  {"frame_pairs", seq.flicker.framePairs},
                  {"static_tolerance", o.staticTolerance}};
  j["temporal"] = temporalJson(seq.temporal);
  nlohmann::json per = nlohmann::json::array();
  out << o.test << " vs " << o.reference;
  if (!o.reference2.empty()) out << " and " << o.reference2;
  out << ": " << seq.frames.size() << " frame(s) compared";
  if (onlyTest + onlyReference > 0)
    out << " (" << onlyTest << " only in test, " << onlyReference << " only in reference)";
  out << "\n" << legend(o);
  for (const rad::FrameDifference& fd : seq.frames) {
    nlohmann::json fj = frameJson(fd);
    fj["frame"] = fd.frame;
    per.push_back(fj);
    out << "  frame " << std::setw(4) << std::setfill('0') << fd.frame << std::setfill(' ') << ": "
        << errorText(fd.error) << "  |  " << statsText(fd.stats, "relative_l2") << "\n";
    if (items) out << frameGeometryText(fd, "    ");
  }
  j["per_frame"] = per;
  out << "  all frames (pooled): " << errorText(seq.totalError)
      << "\n  all frames, every pixel: " << statsText(seq.total, kLongRelative) << "\n";
  if (items)
    out << "  all frames, " << regionsText(seq.totalError) << "\n  "
        << structuredSequenceText(seq.frames) << "\n";
  else
    out << "  structured error: " << kStructuredUnavailable << "\n";
  out << "  flicker: mean |test(n+1)-test(n)| " << text(seq.flicker.mean()) << " (max "
      << text(seq.flicker.maxAbsChange) << ") over " << seq.flicker.staticPixels
      << " static pixel(s) in " << seq.flicker.framePairs << " frame pair(s)\n"
      << temporalText(seq.temporal);
  if (!o.surfaces.empty()) out << surfacesText(seq.totalError, items->names());
  if (!o.seams.empty()) out << seamsText(seq.seams, o.seamMinPairs, patchName, true);
}

// Two (or three, with --ref2) frame directories, matched by frame number.
void compareDirectories(const Options& o, const std::vector<std::string>& channels,
                        nlohmann::json& j, std::ostream& out) {
  std::map<int, std::string> tests = frameFiles(o.test), refs = frameFiles(o.reference);
  std::map<int, std::string> refs2, masks, itemFiles;
  if (!o.reference2.empty()) refs2 = frameFiles(o.reference2);
  if (!o.emitterMask.empty()) masks = frameFiles(o.emitterMask);
  std::optional<ItemSurfaces> items;
  if (!itemsPath(o).empty()) {
    itemFiles = frameFiles(itemsPath(o));
    items.emplace(o.scene);
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
          std::pair(&itemsPath(o), &itemFiles)})
      if (!dir->empty() && !files->count(f))
        throw rad::inputError(*dir, "no frame " + std::to_string(f) + " (" +
                                        fs::path(refs[f]).filename().string() +
                                        " is in the reference)");
  if (!o.smoothedError.empty()) fs::create_directories(o.smoothedError);
  rad::SequenceDifference seq = rad::compareSequence(
      frames,
      [&](int f) {
        rad::FrameImages im;
        im.test = rad::readExrImage(tests[f], channels);
        im.reference = rad::readExrImage(refs[f], channels);
        rad::requireSameShape(im.test, im.reference, tests[f]);
        if (!o.reference2.empty()) {
          im.reference2 = rad::readExrImage(refs2[f], channels);
          rad::requireSameShape(im.reference2, im.reference, refs2[f]);
        }
        if (!o.emitterMask.empty()) im.emitterMask = readEmitterMask(masks[f]);
        if (items) {
          ItemSurfaces::Frame frame = items->load(itemFiles[f], im.reference);
          if (!o.surfaces.empty()) im.groups = std::move(frame.groups);
          im.surfaces = std::move(frame.surfaces);
          if (!o.smoothedError.empty())
            im.smoothedSink = smoothedWriter(
                o, (fs::path(o.smoothedError) / fs::path(refs[f]).filename()).string(),
                {tests[f], refs[f], refs2[f], itemFiles[f], o.scene});
        }
        return im;
      },
      o.staticTolerance, o.emitters);
  reportSequence(o, seq, onlyTest, onlyReference, items ? &*items : nullptr, j, out);
}

int run(const Options& o) {
  const std::vector<std::string> channels = splitChannels(o.channels);
  if (o.emitters.threshold && !(*o.emitters.threshold >= 0.0))
    throw rad::Error(rad::ExitCode::kUsage, "--emitter-threshold", "must be >= 0");
  std::vector<std::string> inputs = {o.test, o.reference};
  if (!o.surfaces.empty() && !o.seams.empty() && o.surfaces != o.seams)
    throw rad::Error(rad::ExitCode::kUsage, "--seams",
                     "--surfaces and --seams name one item buffer; given two");
  if (itemsPath(o).empty() != o.scene.empty())
    throw rad::Error(
        rad::ExitCode::kUsage,
        o.scene.empty() ? (o.surfaces.empty() ? "--seams" : "--surfaces") : "--scene",
        o.seams.empty() ? "--surfaces and --scene go together" : "--seams and --scene go together");
  if (!o.smoothedError.empty() && itemsPath(o).empty())
    throw rad::Error(rad::ExitCode::kUsage, "--smoothed-error",
                     "needs an item buffer (--surfaces or --seams, with --scene)");
  for (const std::string& p : {o.reference2, o.emitterMask, itemsPath(o), o.scene})
    if (!p.empty()) inputs.push_back(p);
  for (const std::string& p : inputs)
    if (!fs::exists(p)) throw rad::inputError(p, "cannot open (missing)");
  const bool testDir = fs::is_directory(o.test), refDir = fs::is_directory(o.reference);
  if (testDir != refDir)
    throw rad::Error(rad::ExitCode::kUsage, o.test,
                     "TEST and REFERENCE must both be .exr files or both directories");
  for (const auto& [path, flag] :
       {std::pair(o.reference2, "--ref2"), std::pair(o.emitterMask, "--emitter-mask"),
        std::pair(o.surfaces, "--surfaces"), std::pair(o.seams, "--seams")})
    if (!path.empty() && fs::is_directory(path) != refDir)
      throw rad::Error(rad::ExitCode::kUsage, path,
                       std::string(flag) +
                           " must be of the reference's kind (.exr file or "
                           "directory)");
  if (!o.smoothedError.empty() && !refDir && fs::is_directory(o.smoothedError))
    throw rad::Error(rad::ExitCode::kUsage, o.smoothedError,
                     "--smoothed-error must be of the reference's kind (.exr file or directory)");
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
      "pool the sums of every frame. A sequence also gets the temporal error (§10.6): the RMS of\n"
      "(t(n+1) - t(n)) - (r(n+1) - r(n)) over non-emitters, over the mean reference (with --ref2\n"
      "the references' change noise removed), at edge and interior pixels apart with an item\n"
      "buffer: an aliased edge that crawls under a moving camera reads high at edges.\n"
      "\n"
      "With an item buffer (--surfaces or --seams ITEMS, --scene SCENE; rad-intervals\n"
      "--item-buffers writes them), patches that are coplanar and of one material count as one\n"
      "surface, and (docs/design.md §10.3-§10.5):\n"
      "  regions: the figure over edge pixels (one of the 8 neighbours shows another surface or\n"
      "    the background, or the pixel is background beside a surface), interior pixels and\n"
      "    background pixels apart;\n"
      "  structured error: Y = luminance, e = Y(test) - Y(ref), averaged over the 7x7 box of\n"
      "    its pixels that are not edges, emitters or background; p95 of |e_box| / mean Y(ref)\n"
      "    over the pixels >= 3 px from every edge pixel. With --ref2, ref = (ref + ref2) / 2,\n"
      "    and reference_floor_p95 is the same of e = (Y(ref) - Y(ref2)) / 2: what a perfect\n"
      "    test would read. Without an item buffer it is not computed (and says so);\n"
      "  seams (--seams): pixel pairs side by side on two coplanar patches a < b of one\n"
      "    material, no edge or emitter; per patch pair, step = sum(Y_a - Y_b) / sum((Y_a +\n"
      "    Y_b) / 2) of the reference, for the test and the reference; over the seams of >=\n"
      "    --seam-min-pairs pairs, the mean and largest |step| and |excess| = |step(test) -\n"
      "    step(ref)|, and with --ref2 the references' floor (half their steps' difference)."};
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
  app.add_option("--seams", o.seams,
                 "item buffer (as --surfaces; the same one when both are given): adds the "
                 "luminance steps across seams of coplanar patches of one material; needs "
                 "--scene");
  app.add_option("--scene", o.scene,
                 "the scene of --surfaces / --seams (its patches, planes and materials)");
  app.add_option("--seam-min-pairs", o.seamMinPairs,
                 "seams with fewer pixel pairs are left out of the seam summary (their step is "
                 "mostly the references' noise)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--smoothed-error", o.smoothedError,
                 "writes the structured error's smoothed difference image (an .exr, or a "
                 "directory of NNNN.exr like REFERENCE): 7x7-smoothed luminance error / mean, 0 "
                 "off the measured pixels; needs an item buffer");
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
  o.argc = argc;
  o.argv = argv;
  return rad::runTool(kTool, [&]() { return run(o); });
}
