// rad-diff: how far a rendered image or frame sequence is from a reference (DESIGN.md §8,
// "error vs converged reference" and "temporal flicker"): RMSE, relative L2, max abs
// difference, PSNR and the flicker of the test sequence where the reference is static.
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <regex>
#include <sstream>

#include <nlohmann/json.hpp>

#include "formats/exr_image.h"
#include "libcommon/reference/image_difference.h"
#include "tools/common/tool_main.h"

namespace {

constexpr const char* kTool = "rad-diff";
namespace fs = std::filesystem;

struct Options {
  std::string test, reference;
  bool json = false;
  std::string channels = "R,G,B";
  double staticTolerance = 0.0;
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

nlohmann::json statsJson(const rad::DifferenceStats& s) {
  return {{"samples", s.samples},
          {"non_finite", s.nonFinite},
          {"rmse", number(s.rmse())},
          {"relative_l2", number(s.relativeL2())},
          {"max_abs", s.maxAbsDifference},
          {"psnr_db", number(s.psnr())},
          {"reference_peak", number(s.referencePeak)}};
}

std::string statsText(const rad::DifferenceStats& s) {
  std::ostringstream os;
  os << "rmse " << text(s.rmse()) << "  relative_l2 " << text(s.relativeL2()) << "  max_abs "
     << text(s.maxAbsDifference) << "  psnr " << text(s.psnr()) << " dB (peak "
     << text(s.referencePeak) << ")";
  if (s.nonFinite > 0) os << "  non_finite " << s.nonFinite;
  return os.str();
}

int run(const Options& o) {
  const std::vector<std::string> channels = splitChannels(o.channels);
  for (const std::string& p : {o.test, o.reference})
    if (!fs::exists(p)) throw rad::inputError(p, "cannot open (missing)");
  const bool testDir = fs::is_directory(o.test), refDir = fs::is_directory(o.reference);
  if (testDir != refDir)
    throw rad::Error(rad::ExitCode::kUsage, o.test,
                     "TEST and REFERENCE must both be .exr files or both directories");
  nlohmann::json j;
  j["test"] = o.test;
  j["reference"] = o.reference;
  j["channels"] = channels;
  std::ostringstream out;
  if (!testDir) {
    rad::FloatImage test = rad::readExrImage(o.test, channels);
    rad::FloatImage reference = rad::readExrImage(o.reference, channels);
    rad::DifferenceStats s = rad::compareImages(test, reference, o.test);
    j["size"] = {test.width, test.height};
    j["difference"] = statsJson(s);
    out << o.test << " vs " << o.reference << " (" << test.width << "x" << test.height << ", "
        << o.channels << "):\n  " << statsText(s) << "\n";
  } else {
    std::map<int, std::string> tests = frameFiles(o.test), refs = frameFiles(o.reference);
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
    rad::SequenceDifference seq = rad::compareSequence(
        frames,
        [&](int f) {
          rad::FloatImage test = rad::readExrImage(tests[f], channels);
          rad::FloatImage ref = rad::readExrImage(refs[f], channels);
          rad::requireSameShape(test, ref, tests[f]);
          return std::make_pair(std::move(test), std::move(ref));
        },
        o.staticTolerance);
    j["frames_compared"] = frames.size();
    j["frames_only_in_test"] = onlyTest;
    j["frames_only_in_reference"] = onlyReference;
    j["difference"] = statsJson(seq.total);
    j["flicker"] = {{"mean_abs", seq.flicker.mean()},
                    {"max_abs", seq.flicker.maxAbsChange},
                    {"static_pixels", seq.flicker.staticPixels},
                    {"frame_pairs", seq.flicker.framePairs},
                    {"static_tolerance", o.staticTolerance}};
    nlohmann::json per = nlohmann::json::array();
    out << o.test << " vs " << o.reference << ": " << frames.size() << " frame(s) compared";
    if (onlyTest + onlyReference > 0)
      out << " (" << onlyTest << " only in test, " << onlyReference << " only in reference)";
    out << "\n";
    for (const rad::FrameDifference& fd : seq.frames) {
      nlohmann::json fj = statsJson(fd.stats);
      fj["frame"] = fd.frame;
      per.push_back(fj);
      out << "  frame " << std::setw(4) << std::setfill('0') << fd.frame << std::setfill(' ')
          << ": " << statsText(fd.stats) << "\n";
    }
    j["per_frame"] = per;
    out << "  all frames: " << statsText(seq.total) << "\n";
    out << "  flicker: mean |test(n+1)-test(n)| " << text(seq.flicker.mean()) << " (max "
        << text(seq.flicker.maxAbsChange) << ") over " << seq.flicker.staticPixels
        << " static pixel(s) in " << seq.flicker.framePairs << " frame pair(s)\n";
  }
  if (o.json)
    std::cout << j.dump(1) << "\n";
  else
    std::cout << out.str();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Compares a test image or frame directory (NNNN.exr) with a reference: RMSE, relative L2, "
      "max abs difference, PSNR (peak = max of the reference) and, for sequences, the temporal "
      "flicker of the test where the reference does not change."};
  Options o;
  rad::setUpApp(app, kTool, "rad-diff out/frames ref/frames --json");
  app.add_option("TEST", o.test, "test .exr file or directory of NNNN.exr")->required();
  app.add_option("REFERENCE", o.reference, "reference .exr file or directory of NNNN.exr")
      ->required();
  app.add_flag("--json", o.json, "print JSON on stdout instead of text");
  app.add_option("--channels", o.channels, "comma-separated channels to compare")
      ->capture_default_str();
  app.add_option("--static-tolerance", o.staticTolerance,
                 "flicker: a reference pixel is static when no channel changes by more")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  if (int rc = rad::parseCommandLine(app, kTool, argc, argv); rc >= 0) return rc;
  return rad::runTool(kTool, [&]() { return run(o); });
}
