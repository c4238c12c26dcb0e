// What values a parameter takes (libcommon/core/parameter_table.h): one description that the
// command line turns into its CLI11 check (tools/common/parameter_cli.h, with the messages of
// tool_main.h's finiteRange and integerRange) and ParameterTable::validate applies to a struct.
#pragma once

#include <limits>
#include <string>

namespace rad {

struct ParameterCheck {
  enum class Kind {
    kNone,        // any value of the type
    kFinite,      // a finite number
    kRange,       // lo <= x <= hi (finite); an integer parameter: an integer in [lo, hi]
    kPositive,    // x > 0 (finite); an integer parameter: n >= 1
    kFrameRange,  // FIRST-LAST[xSTEP] (oiiotool), checked by the command line
    kImageSize,   // WIDTHxHEIGHT, checked by the command line
  };
  Kind kind = Kind::kNone;
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();

  static ParameterCheck finite() { return {Kind::kFinite}; }
  static ParameterCheck positive() { return {Kind::kPositive}; }
  static ParameterCheck nonNegative() {
    return {Kind::kRange, 0.0, std::numeric_limits<double>::infinity()};
  }
  static ParameterCheck range(double lo, double hi) { return {Kind::kRange, lo, hi}; }
  static ParameterCheck frameRange() { return {Kind::kFrameRange}; }
  static ParameterCheck imageSize() { return {Kind::kImageSize}; }

  // "" when `text` passes, else `TEXT is not WHAT` (tool_main.h's wording). `integer`: the
  // parameter is an integer. kFrameRange and kImageSize pass here (their parsers check them).
  std::string problem(const std::string& text, bool integer) const;
};

}  // namespace rad
