// rad-diff's report of the figures that need an item buffer (docs/design.md §10.3 edge and
// interior pixels, §10.4 structured error, §10.5 seams), as JSON and as text.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "libcommon/reference/seam_steps.h"
#include "libcommon/reference/sequence_difference.h"

namespace rad::diff {

// JSON has no infinity: a non-finite figure is written as null; text says "inf" or "n/a".
nlohmann::json number(double x);
std::string text(double x);

// Why the structured error is missing without an item buffer.
extern const char* const kStructuredUnavailable;

// {"edge": {...}, "interior": {...}, "background": {...}}: pixels, mean_reference,
// rmse_over_mean, bias (and noise_over_mean, raw_rmse_over_mean with two references).
nlohmann::json regionsJson(const ErrorFigures& e);
// "edge pixels ...; interior ...; background ...", one line without the newline.
std::string regionsText(const ErrorFigures& e);

nlohmann::json structuredJson(const StructuredError& s);
std::string structuredText(const StructuredError& s);
// Over a sequence's frames: the largest per-frame p95 and its frame, and the mean.
nlohmann::json structuredSequenceJson(const std::vector<FrameDifference>& frames);
std::string structuredSequenceText(const std::vector<FrameDifference>& frames);

// The seam summary and every measured seam, largest |excess| first. `patchName` names a
// top-level patch; `sequence`: name the frame each seam was first seen in.
nlohmann::json seamsJson(const SeamSteps& steps, long long minPairs,
                         const std::function<std::string(int)>& patchName, bool sequence);
// The summary and the `worst` seams of largest |excess|, several lines each ending in "\n".
std::string seamsText(const SeamSteps& steps, long long minPairs,
                      const std::function<std::string(int)>& patchName, bool sequence,
                      int worst = 5);

}  // namespace rad::diff
