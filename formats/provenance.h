// Provenance: what made a file and from what (docs/design.md §5, docs/conventions.md §1 "Files that
// say what made them"). Every rad file records the tool, its version and git revision, the full
// command line, every parameter in effect (defaults included) and each input's content hash
// followed by that input's own provenance, so the whole chain back to the scene can be printed like
// Radiance's getinfo.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace rad {

// The record of one input (provenance.inputs). The container-aware ways of making one (addInput,
// inputRecordOf) are in formats/container.h: the container stores a provenance, so it builds
// on this file, never the reverse.
struct InputRecord {
  std::string path;  // as given on the command line (not made absolute: files move)
  std::string hash;  // "fnv1a64:<16 hex>" of the whole file's bytes
  // The input's own provenance (a Provenance JSON object) if it is a rad file, else null.
  nlohmann::json history;
};

struct Provenance {
  std::string tool;         // e.g. "rad-global"
  std::string version;      // RAD_VERSION of the build, e.g. "0.1.0"
  std::string gitRevision;  // gitRevision() of the build (formats/build_info.h), or "unknown"
  std::string commandLine;  // argv, shell-quoted so it can be pasted back into a shell
  // Every parameter in effect, defaults included; keys are long option names without "--".
  nlohmann::json parameters = nlohmann::json::object();
  std::vector<InputRecord> inputs;

  nlohmann::json toJson() const;
  // `where` names the file for error messages; throws rad::inputError on a malformed object.
  // Unknown keys are ignored (a newer minor version may add some).
  static Provenance fromJson(const nlohmann::json& j, const std::string& where);
  // Radiance-getinfo-like text: one line per tool of the history chain, oldest first (inputs'
  // histories before the tool that consumed them; a history shared by several inputs is
  // printed once), each followed by its indented parameters and inputs.
  std::string toText() const;
};

// tool, RAD_VERSION, gitRevision(), the quoted command line and `parameters` (must be an
// object; null is taken as {}).
Provenance makeProvenance(const std::string& tool, int argc, const char* const* argv,
                          const nlohmann::json& parameters);

// Provenance JSON read from a file (an OpenEXR rad.provenance attribute): parsed and checked as a
// Provenance. Throws rad::inputError(where, ...) on one line (no bytes of the text in it) if it
// is not valid UTF-8, not JSON or not a provenance object.
nlohmann::json parseProvenanceJson(const std::string& text, const std::string& where);

// Byte offset of the first ill-formed UTF-8 sequence in `text` (overlong forms, surrogates and
// code points above U+10FFFF included), or std::string::npos if there is none.
size_t firstInvalidUtf8(const std::string& text);
// `text` with each ill-formed sequence replaced by U+FFFD. JSON strings must be UTF-8, and
// nlohmann::json throws (type_error 316) when it dumps one that is not: command lines, paths and
// other attributes' bytes go through this before they are put in JSON.
std::string toValidUtf8(const std::string& text);

// POSIX-shell quoting: words made only of safe characters are left bare, others are put in
// single quotes ('it'\''s').
std::string shellQuote(const std::string& word);

// Content hash of a whole file, "fnv1a64:<16 hex>". Streams in 64 KiB chunks. Throws
// rad::inputError(path, ...) if it cannot be read or is not a regular file (a FIFO is refused, not
// waited on).
std::string hashFile(const std::string& path);

// Compares the parameters a file was built with against those this run needs, for each of
// `keys`. Returns one message per difference, e.g. "built with --eps 0.02; this run expects
// 0.01" or "built without --eps; this run expects 0.01"; empty when all agree. Numbers compare
// by value (1 == 1.0).
std::vector<std::string> parameterMismatch(const nlohmann::json& built,
                                           const nlohmann::json& expected,
                                           const std::vector<std::string>& keys);

}  // namespace rad
