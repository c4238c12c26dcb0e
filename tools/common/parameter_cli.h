// A stage's parameter table (libcommon/core/parameter_table.h) on the command line: every entry
// becomes a CLI11 option of its name, help, check and help group, bound to the options struct,
// with the struct's value (after --preset) as the default that --help and --print-defaults show.
// The quality presets: --preset NAME sets a stage's quality knobs before the command line is
// parsed, so an explicit flag overrides it and --print-defaults prints what the preset sets.
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "libcommon/core/parameter_table.h"

namespace rad {

// The CLI11 check of `check` for an option of type `typeName` (INT or FLOAT or TEXT), with the
// messages of tool_main.h's finiteRange, integerRange, parseFrameRange and parseImageSize.
CLI::Validator validatorOf(const ParameterCheck& check, const std::string& typeName);

// Adds every entry of `table`, bound to `options`, to `app`: Common first, then Quality,
// Advanced, Baselines (CLI11 lists groups in the order their first option was added).
template <class O>
void bindParameters(CLI::App& app, const ParameterTable<O>& table, O& options) {
  std::vector<const Parameter<O>*> ordered;
  for (const Parameter<O>& p : table.entries()) ordered.push_back(&p);
  std::stable_sort(ordered.begin(), ordered.end(),
                   [](const auto* a, const auto* b) { return a->group < b->group; });
  for (const Parameter<O>* p : ordered) {
    const std::string flag = "--" + p->name;
    const std::string group = parameterGroupTitle(p->group);
    if (p->kind == Parameter<O>::Kind::kFlag) {
      app.add_flag_callback(
             flag, [p, &options] { p->set(options, "true"); }, p->help)
          ->group(group);
      continue;
    }
    CLI::Option* opt =
        app.add_option_function<std::string>(
               flag, [p, &options](const std::string& s) { p->set(options, s); }, p->help)
            ->default_str(p->text(options))
            ->type_name(p->typeName)
            ->group(group);
    if (!p->choices.empty())
      opt->check(CLI::IsMember(p->choices));
    else if (p->check.kind != ParameterCheck::Kind::kNone)
      opt->check(validatorOf(p->check, p->typeName));
  }
}

// --preset NAME (draft, default, final), in the Common group. It is read from argv here, before
// CLI11 parses (`--preset NAME` or `--preset=NAME`; the last wins).
// A name that is not a preset is left to CLI11's check (one line, exit 2) and counts as
// "default" until then. Returns the preset in effect, for the caller to apply before it binds
// the other options, so the preset's values become the defaults that explicit flags override.
std::string addPresetOption(CLI::App& app, std::string& preset, int argc, char** argv);

// The warning a deprecated spelling prints once on stderr: `tool: warning: --old is deprecated;
// use --new`.
void warnDeprecated(const std::string& tool, const std::string& oldFlag,
                    const std::string& newFlag);

}  // namespace rad
