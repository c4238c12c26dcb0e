// rad-diff: the report of docs/design.md §10.3–§10.5.
#include "tools/rad-diff/geometry_report.h"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "libcommon/reference/edge_pixels.h"

namespace rad::diff {

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

const char* const kStructuredUnavailable =
    "not computed: needs an item buffer (--surfaces or --seams ITEMS, with --scene SCENE) to "
    "find the geometric edges";

nlohmann::json regionsJson(const ErrorFigures& e) {
  nlohmann::json j = nlohmann::json::object();
  for (size_t r = 0; r < e.regions.size(); ++r) {
    const PixelSetStats& s = e.regions[r];
    nlohmann::json o = {{"pixels", s.pixels},
                        {"mean_reference", s.meanReference()},
                        {"rmse_over_mean", number(s.rmseOverMean())},
                        {"bias", number(s.bias())}};
    if (s.twoReferences) {
      o["noise_over_mean"] = number(s.noiseOverMean());
      o["raw_rmse_over_mean"] = number(s.rawRmseOverMean());
    }
    j[pixelRegionName(int(r))] = o;
  }
  return j;
}

std::string regionsText(const ErrorFigures& e) {
  std::ostringstream os;
  os << "by region (item buffer; docs/design.md §10.3):";
  for (size_t r = 0; r < e.regions.size(); ++r) {
    const PixelSetStats& s = e.regions[r];
    if (r == kBackgroundRegion && s.pixels == 0) continue;
    os << (r ? ";" : "") << "  " << pixelRegionName(int(r)) << " " << s.pixels << " px";
    if (s.pixels > 0) os << " rmse/mean " << text(s.rmseOverMean()) << " bias " << text(s.bias());
  }
  return os.str();
}

nlohmann::json structuredJson(const StructuredError& s) {
  nlohmann::json j = {{"p95", number(s.p95)},
                      {"pixels", s.pixels},
                      {"mean_reference_luminance", s.meanReference},
                      {"box", kStructuredBox},
                      {"edge_clearance", kStructuredEdgeClearance}};
  if (s.hasFloor) j["reference_floor_p95"] = number(s.floorP95);
  return j;
}

std::string structuredText(const StructuredError& s) {
  std::ostringstream os;
  os << "structured error (docs/design.md §10.4: p95 of |7x7 smoothed Y error| / mean Y, >= 3 "
        "px from edges) "
     << text(s.p95);
  if (s.hasFloor) os << "  (references' floor " << text(s.floorP95) << ")";
  os << " over " << s.pixels << " px";
  return os.str();
}

nlohmann::json structuredSequenceJson(const std::vector<FrameDifference>& frames) {
  double maxP95 = 0.0, sumP95 = 0.0, maxFloor = 0.0, sumFloor = 0.0;
  int count = 0, worstFrame = -1;
  bool floors = false;
  for (const FrameDifference& f : frames) {
    if (!f.structured || f.structured->pixels == 0) continue;  // no figure in that frame
    const StructuredError& s = *f.structured;
    if (count == 0 || s.p95 > maxP95) {
      maxP95 = s.p95;
      worstFrame = f.frame;
    }
    ++count;
    sumP95 += s.p95;
    floors = floors || s.hasFloor;
    maxFloor = std::max(maxFloor, s.floorP95);
    sumFloor += s.floorP95;
  }
  if (count == 0) return nullptr;
  nlohmann::json j = {{"frames", count},
                      {"max_p95", number(maxP95)},
                      {"max_p95_frame", worstFrame},
                      {"mean_p95", number(sumP95 / count)}};
  if (floors) {
    j["max_reference_floor_p95"] = number(maxFloor);
    j["mean_reference_floor_p95"] = number(sumFloor / count);
  }
  return j;
}

std::string structuredSequenceText(const std::vector<FrameDifference>& frames) {
  const nlohmann::json j = structuredSequenceJson(frames);
  if (j.is_null()) return "";
  std::ostringstream os;
  auto value = [&](const char* key) {
    return j[key].is_null() ? std::string("inf") : text(j[key].get<double>());
  };
  os << "structured error over " << j["frames"].get<int>() << " frame(s): largest p95 "
     << value("max_p95") << " (frame " << j["max_p95_frame"].get<int>() << "), mean "
     << value("mean_p95");
  if (j.contains("max_reference_floor_p95"))
    os << "  (references' floor: largest " << value("max_reference_floor_p95") << ", mean "
       << value("mean_reference_floor_p95") << ")";
  return os.str();
}

namespace {

nlohmann::json seamJson(const std::pair<int, int>& key, const SeamSums& s, bool floor,
                        const std::function<std::string(int)>& patchName, bool sequence) {
  nlohmann::json j = {{"patches", {key.first, key.second}},
                      {"surface", patchName(key.first)},
                      {"pairs", s.pairs},
                      {"pixel", {s.x, s.y}},
                      {"local_mean", s.localMean()},
                      {"step_test", number(s.testStep())},
                      {"step_reference", number(s.referenceStep())},
                      {"excess", number(s.excess())}};
  if (floor) j["floor"] = number(s.floor());
  if (sequence) j["frame"] = s.frame;
  return j;
}

}  // namespace

nlohmann::json seamsJson(const SeamSteps& steps, long long minPairs,
                         const std::function<std::string(int)>& patchName, bool sequence) {
  const SeamSummary s = summariseSeams(steps, minPairs);
  nlohmann::json j = {
      {"min_pairs", s.minPairs},
      {"seams_found", s.seamsFound},
      {"seams_measured", s.seamsMeasured},
      {"pairs", s.pairs},
      {"test",
       {{"mean_abs_step", number(s.meanAbsTestStep)}, {"max_abs_step", number(s.maxAbsTestStep)}}},
      {"reference",
       {{"mean_abs_step", number(s.meanAbsReferenceStep)},
        {"max_abs_step", number(s.maxAbsReferenceStep)}}},
      {"excess", {{"mean_abs", number(s.meanAbsExcess)}, {"max_abs", number(s.maxAbsExcess)}}}};
  if (steps.twoReferences) j["reference_floor_max_abs"] = number(s.maxFloor);
  nlohmann::json list = nlohmann::json::array();
  for (const auto& key : s.byExcess)
    list.push_back(seamJson(key, steps.seams.at(key), steps.twoReferences, patchName, sequence));
  j["seams"] = list;
  return j;
}

std::string seamsText(const SeamSteps& steps, long long minPairs,
                      const std::function<std::string(int)>& patchName, bool sequence, int worst) {
  const SeamSummary s = summariseSeams(steps, minPairs);
  std::ostringstream os;
  os << "  seams (docs/design.md §10.5: coplanar patches of one material; step = mean Y(a) - "
        "Y(b) / local mean): "
     << s.seamsMeasured << " of " << s.seamsFound << " seam(s) with >= " << s.minPairs
     << " pixel pairs, " << s.pairs << " pairs\n";
  if (s.seamsMeasured == 0) return os.str();
  os << "    |step| test: mean " << text(s.meanAbsTestStep) << " max " << text(s.maxAbsTestStep)
     << ";  reference: mean " << text(s.meanAbsReferenceStep) << " max "
     << text(s.maxAbsReferenceStep) << ";  |excess|: mean " << text(s.meanAbsExcess) << " max "
     << text(s.maxAbsExcess);
  if (steps.twoReferences) os << ";  references' floor: max " << text(s.maxFloor);
  os << "\n";
  for (size_t k = 0; k < s.byExcess.size() && int(k) < worst; ++k) {
    const auto& key = s.byExcess[k];
    const SeamSums& seam = steps.seams.at(key);
    os << "    patches " << key.first << "|" << key.second << " " << patchName(key.first) << " at ("
       << seam.x << ", " << seam.y << ")";
    if (sequence) os << " of frame " << seam.frame;
    os << ": " << seam.pairs << " pairs, step test " << text(seam.testStep()) << " reference "
       << text(seam.referenceStep()) << " excess " << text(seam.excess());
    if (steps.twoReferences) os << " floor " << text(seam.floor());
    os << "\n";
  }
  return os.str();
}

}  // namespace rad::diff
