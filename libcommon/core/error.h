// Errors and exit codes shared by every tool (docs/conventions.md §3 "Small tools", §4 "Errors").
//
// Library code throws rad::Error; only a tool's main catches it and prints
// `rad-tool: path: what is wrong` on one line, then exits with the error's code.
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>

namespace rad {

// Exit codes, listed in every tool's --help and in the README.
enum class ExitCode : int {
  kOk = 0,
  kBadInput = 1,     // bad or incompatible input file
  kUsage = 2,        // bad command line
  kOutput = 3,       // could not write output
  kEnvironment = 4,  // no GL context, out of memory, ...
  kInternal = 5,     // a bug
};

class Error : public std::runtime_error {
 public:
  // `where` is usually a path, optionally followed by a place inside it
  // ("scene.gltf", "global.rlh: array links"); it may be empty.
  Error(ExitCode code, const std::string& where, const std::string& what)
      : std::runtime_error(where.empty() ? what : where + ": " + what), code_(code) {}
  ExitCode code() const { return code_; }

 private:
  ExitCode code_;
};

// A number for a message, %g style: 1.79769e+308 and 1e-07, where std::to_string(double)
// prints 309 digits and 0.000000.
inline std::string numberText(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", x);
  return text;
}

// Shorthands for the common cases.
inline Error inputError(const std::string& where, const std::string& what) {
  return Error(ExitCode::kBadInput, where, what);
}
inline Error outputError(const std::string& where, const std::string& what) {
  return Error(ExitCode::kOutput, where, what);
}

}  // namespace rad
