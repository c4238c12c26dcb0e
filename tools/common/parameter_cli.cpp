#include "tools/common/parameter_cli.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <limits>

#include "tools/common/tool_main.h"

namespace rad {

namespace {
// A check that runs `parse` (which throws a usage Error) on the value.
CLI::Validator parsedBy(std::function<void(const std::string&)> parse, const std::string& tag) {
  return CLI::Validator(
      [parse](std::string& input) -> std::string {
        try {
          parse(input);
        } catch (const Error& e) {
          std::string message = e.what();  // " VALUE: expected ...": the flag is CLI11's
          return message.substr(message.find_first_not_of(' '));
        }
        return "";
      },
      tag);
}

long long integerBound(double x) {
  if (x >= double(std::numeric_limits<long long>::max()))
    return std::numeric_limits<long long>::max();
  if (x <= double(std::numeric_limits<long long>::min()))
    return std::numeric_limits<long long>::min();
  return (long long)x;
}
}  // namespace

CLI::Validator validatorOf(const ParameterCheck& check, const std::string& typeName) {
  using Kind = ParameterCheck::Kind;
  const bool integer = typeName == "INT";
  switch (check.kind) {
    case Kind::kNone:
      return CLI::Validator();
    case Kind::kFinite:
      return finiteNumber();
    case Kind::kPositive:
      return integer ? positiveInteger() : positiveFinite();
    case Kind::kRange:
      if (integer) return integerRange(integerBound(check.lo), integerBound(check.hi));
      if (check.lo == 0.0 && std::isinf(check.hi)) return nonNegativeFinite();
      return finiteRange(check.lo, check.hi);
    case Kind::kFrameRange:
      return parsedBy([](const std::string& s) { parseFrameRange(s, ""); }, "FIRST-LAST[xSTEP]");
    case Kind::kImageSize:
      return parsedBy([](const std::string& s) { parseImageSize(s, ""); }, "WxH");
  }
  return CLI::Validator();
}

std::string addPresetOption(CLI::App& app, std::string& preset, int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--preset") == 0 && i + 1 < argc)
      preset = argv[++i];
    else if (std::strncmp(argv[i], "--preset=", 9) == 0)
      preset = argv[i] + 9;
  }
  const std::vector<std::string>& names = presetNames();
  if (std::find(names.begin(), names.end(), preset) == names.end()) preset = "default";
  app.add_option("--preset", preset,
                 "quality preset: draft, default or final (the README's recommended settings); "
                 "sets the Quality options below, which explicit flags override")
      ->capture_default_str()
      ->check(CLI::IsMember(presetNames()))
      ->group(parameterGroupTitle(ParameterGroup::kCommon));
  return preset;
}

void warnDeprecated(const std::string& tool, const std::string& oldFlag,
                    const std::string& newFlag) {
  std::cerr << tool << ": warning: " << oldFlag << " is deprecated; use " << newFlag << "\n";
}

}  // namespace rad
