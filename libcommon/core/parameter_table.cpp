// The parts of parameter_table.h and parameter_check.h that are not templates.
#include "libcommon/core/parameter_table.h"

#include <cerrno>
#include <cstdlib>

namespace rad {

const char* parameterGroupTitle(ParameterGroup group) {
  switch (group) {
    case ParameterGroup::kCommon:
      return "Common";
    case ParameterGroup::kQuality:
      return "Quality (set by --preset)";
    case ParameterGroup::kAdvanced:
      return "Advanced";
    case ParameterGroup::kBaseline:
      return "Baselines for comparison";
  }
  return "Advanced";
}

const Preset& findPreset(const std::vector<Preset>& presets, const std::string& name) {
  static const Preset kNothing{};
  for (const Preset& p : presets)
    if (p.name == name) return p;
  for (const std::string& known : presetNames())
    if (known == name) return kNothing;
  throw Error(ExitCode::kUsage, "", "--preset " + name + ": expected draft, default or final");
}

std::string ParameterCheck::problem(const std::string& text, bool integer) const {
  if (kind == Kind::kNone || kind == Kind::kFrameRange || kind == Kind::kImageSize) return "";
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const double x = integer ? double(std::strtoll(begin, &end, 10)) : std::strtod(begin, &end);
  const bool number = end != begin && *end == '\0' && errno != ERANGE && std::isfinite(x);
  std::string want = integer ? "an integer" : "a finite number";
  bool ok = number;
  if (kind == Kind::kPositive) {
    want += integer ? " >= 1" : " > 0";
    ok = ok && x > 0.0;
  } else if (kind == Kind::kRange) {
    const bool open = std::isinf(hi);
    want += open ? " >= " + numberText(lo) : " in [" + numberText(lo) + ", " + numberText(hi) + "]";
    ok = ok && x >= lo && x <= hi;
  }
  return ok ? "" : text + " is not " + want;
}

}  // namespace rad
