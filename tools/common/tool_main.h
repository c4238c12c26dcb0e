// What every tool's main shares: exit codes, the one-line error format and CLI11 set-up
// (docs/conventions.md §3 "Small tools with thin mains", §4 "Errors").
#pragma once

#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "libcommon/core/error.h"

namespace rad {

struct Camera;

// The exit-code table every --help ends with.
inline const char* exitCodeHelp() {
  return "Exit codes: 0 ok; 1 bad or incompatible input; 2 usage; 3 could not write output;\n"
         "            4 environment (no GL context, out of memory, a thread that cannot start);\n"
         "            5 internal error.";
}

// Creates the CLI11 app with --version, --threads, --print-defaults and the exit-code footer.
// `example` is one command line.
void setUpApp(CLI::App& app, const std::string& tool, const std::string& example);

// Parses the command line; returns -1 to go on, otherwise the exit code to return
// (0 after --help / --version / --print-defaults, 2 after a usage error, which is printed as
// one line).
int parseCommandLine(CLI::App& app, const std::string& tool, int argc, char** argv);

// Every option's default as one JSON object, for --print-defaults (Radiance's print_rdefaults):
// keys are the long names without "--" ("eps", "key-step"), values the defaults the options
// were bound with: numbers as JSON numbers, flags false, other values as strings, an option
// with no default (empty string or list, unset std::optional) null. Positionals, --help,
// --version and --print-defaults are left out. Call it before parsing (it reads the bound
// variables).
nlohmann::json optionDefaults(CLI::App& app);

// Runs body, mapping rad::Error and other exceptions to `tool: message` on stderr and the
// documented exit code; then finishStdout.
int runTool(const std::string& tool, const std::function<int()>& body);

// Flushes stdout and returns rc, or, when what the tool printed there was lost (a full disk:
// `rad-inspect --json f > /dev/full`), prints `tool: stdout: write failed: REASON` and returns
// max(rc, 3). Without it the loss shows only at exit, where nothing checks it (exit 0).
int finishStdout(const std::string& tool, int rc);

// Checks for floating-point options, for every tool's float option. CLI11's own
// (PositiveNumber, NonNegativeNumber, Range) let "nan" through, since every comparison with NaN
// is false, accept "inf", and print their bounds with %f (DBL_MAX as 309 digits). These accept
// finite numbers only, and say what they want in %g style.
CLI::Validator finiteNumber();
CLI::Validator positiveFinite();                   // > 0
CLI::Validator nonNegativeFinite();                // >= 0
CLI::Validator finiteRange(double lo, double hi);  // lo <= x <= hi
// The same for integer options (CLI11's PositiveNumber on --key-step 0 printed 309 digits).
CLI::Validator integerRange(long long lo, long long hi);  // lo <= n <= hi
CLI::Validator positiveInteger();                         // >= 1
CLI::Validator nonNegativeInteger();                      // >= 0

// Parses "a-b", "a-bxs" or "a" (oiiotool style) into the frames it names; throws a usage
// Error naming `flag` on bad syntax.
std::vector<int> parseFrameRange(const std::string& spec, const std::string& flag = "--frames");

// Parses "352x240".
std::pair<int, int> parseImageSize(const std::string& spec, const std::string& flag = "--size");

// The warning line (with its newline) for `empty` of `frames` frames in which the camera sees no
// surface, the first of them `firstEmpty`: they come out black, usually because `lens`'s clip
// planes or view miss the whole scene. "" when empty is 0.
std::string emptyFramesWarning(const std::string& tool, size_t empty, int firstEmpty, size_t frames,
                               const Camera& lens);

// Peak resident memory of this process so far, MiB (getrusage ru_maxrss), for --report.
double peakMemoryMb();
// True when stderr is a terminal (progress bars only then).
bool stderrIsTerminal();

// A progress bar on stderr. On a terminal it redraws one line; elsewhere (a log file, a farm
// job's output) it prints a plain line `label: done/total (pct %)` at most every kLogSeconds, none
// in a shorter run: 12,501 key times once made one line each.
class Progress {
 public:
  Progress(std::string label, long total);
  void advance(long n = 1);
  void done();
  ~Progress();

 private:
  static constexpr double kLogSeconds = 10.0;
  void log();

  std::string label_;
  long total_, count_ = 0;
  int lastPercent_ = -1;
  bool active_;
  bool logging_;  // off a terminal
  std::chrono::steady_clock::time_point lastLog_;
};

}  // namespace rad
