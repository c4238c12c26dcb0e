// What every tool's main shares: exit codes, the one-line error format and CLI11 set-up
// (CONVENTIONS.md "Small tools with thin mains", "Errors").
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "libcommon/core/error.h"

namespace rad {

// The exit-code table every --help ends with.
inline const char* exitCodeHelp() {
  return "Exit codes: 0 ok; 1 bad or incompatible input; 2 usage; 3 could not write output;\n"
         "            4 environment (no GL context, out of memory); 5 internal error.";
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
// documented exit code.
int runTool(const std::string& tool, const std::function<int()>& body);

// Parses "a-b", "a-bxs" or "a" (oiiotool style) into the frames it names; throws a usage
// Error naming `flag` on bad syntax.
std::vector<int> parseFrameRange(const std::string& spec, const std::string& flag = "--frames");

// Parses "352x240".
std::pair<int, int> parseImageSize(const std::string& spec, const std::string& flag = "--size");

// Peak resident memory of this process so far, MiB (getrusage ru_maxrss), for --report.
double peakMemoryMb();
// True when stderr is a terminal (progress bars only then).
bool stderrIsTerminal();

// A progress bar on stderr that draws only on a terminal.
class Progress {
 public:
  Progress(std::string label, long total);
  void advance(long n = 1);
  void done();
  ~Progress();

 private:
  std::string label_;
  long total_, count_ = 0;
  int lastPercent_ = -1;
  bool active_;
};

}  // namespace rad
