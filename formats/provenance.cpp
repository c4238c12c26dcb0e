#include "formats/provenance.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <memory>
#include <set>
#include <sstream>

#include "formats/build_info.h"
#include "formats/checksum.h"
#include "libcommon/core/error.h"

namespace rad {

namespace {

const nlohmann::json& field(const nlohmann::json& obj, const char* key) {
  static const nlohmann::json kNull;
  const auto it = obj.find(key);
  return it == obj.end() ? kNull : *it;
}

std::string stringField(const nlohmann::json& obj, const char* key, const std::string& where) {
  const auto& v = field(obj, key);
  if (v.is_null()) return "";  // absent: older writers, or a hand-made test file
  if (!v.is_string()) throw inputError(where, std::string("\"") + key + "\" is not a string");
  return v.get<std::string>();
}

// Value as a user would type it after the option: strings bare, everything else as JSON.
std::string optionValue(const nlohmann::json& v) {
  return v.is_string() ? v.get<std::string>() : v.dump();
}

std::string optionName(const std::string& key) {
  return key.rfind("--", 0) == 0 ? key : "--" + key;
}

void appendText(const Provenance& p, std::set<std::string>& printed, std::ostringstream& out,
                int depth) {
  // Histories are trees (rad-movies reads global.rlh and intervals.rti, both made from the same
  // scene); print each distinct one once. Depth bounds malicious nesting.
  if (depth > 64) return;
  for (const auto& in : p.inputs) {
    if (!in.history.is_object()) continue;
    const std::string key = in.history.dump();
    if (!printed.insert(key).second) continue;
    try {
      appendText(Provenance::fromJson(in.history, in.path), printed, out, depth + 1);
    } catch (const Error&) {
      out << "(unreadable history of " << in.path << ")\n";
    }
  }
  out << (p.tool.empty() ? "(unknown tool)" : p.tool);
  if (!p.version.empty()) out << " " << p.version;
  if (!p.gitRevision.empty()) out << " (git " << p.gitRevision << ")";
  out << ": " << p.commandLine << "\n";
  if (!p.parameters.empty()) out << "    parameters " << p.parameters.dump() << "\n";
  for (const auto& in : p.inputs) out << "    input " << in.path << " " << in.hash << "\n";
}

// Length of the well-formed UTF-8 sequence at text[i], or 0 if it is ill-formed (RFC 3629).
size_t utf8SequenceAt(const std::string& text, size_t i) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char b0 = byte(i);
  if (b0 < 0x80) return 1;
  size_t n;
  unsigned char lo = 0x80, hi = 0xbf;  // allowed range of the second byte
  if (b0 >= 0xc2 && b0 <= 0xdf) {
    n = 2;
  } else if (b0 >= 0xe0 && b0 <= 0xef) {
    n = 3;
    if (b0 == 0xe0) lo = 0xa0;  // overlong
    if (b0 == 0xed) hi = 0x9f;  // surrogates
  } else if (b0 >= 0xf0 && b0 <= 0xf4) {
    n = 4;
    if (b0 == 0xf0) lo = 0x90;  // overlong
    if (b0 == 0xf4) hi = 0x8f;  // above U+10FFFF
  } else {
    return 0;
  }
  if (i + n > text.size() || byte(i + 1) < lo || byte(i + 1) > hi) return 0;
  for (size_t k = 2; k < n; ++k)
    if (byte(i + k) < 0x80 || byte(i + k) > 0xbf) return 0;
  return n;
}

// `j` with every string (keys included) made valid UTF-8.
nlohmann::json validUtf8Json(const nlohmann::json& j) {
  if (j.is_string()) return toValidUtf8(j.get<std::string>());
  if (j.is_array()) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& v : j) out.push_back(validUtf8Json(v));
    return out;
  }
  if (j.is_object()) {
    nlohmann::json out = nlohmann::json::object();
    for (const auto& [k, v] : j.items()) out[toValidUtf8(k)] = validUtf8Json(v);
    return out;
  }
  return j;
}

}  // namespace

size_t firstInvalidUtf8(const std::string& text) {
  for (size_t i = 0; i < text.size();) {
    const size_t n = utf8SequenceAt(text, i);
    if (n == 0) return i;
    i += n;
  }
  return std::string::npos;
}

std::string toValidUtf8(const std::string& text) {
  if (firstInvalidUtf8(text) == std::string::npos) return text;
  std::string out;
  for (size_t i = 0; i < text.size();) {
    const size_t n = utf8SequenceAt(text, i);
    if (n == 0) {
      out += "\xEF\xBF\xBD";  // U+FFFD REPLACEMENT CHARACTER
      ++i;
    } else {
      out.append(text, i, n);
      i += n;
    }
  }
  return out;
}

nlohmann::json parseProvenanceJson(const std::string& text, const std::string& where) {
  const size_t bad = firstInvalidUtf8(text);
  if (bad != std::string::npos)
    throw inputError(where, "provenance is not valid UTF-8 (byte " + std::to_string(bad) +
                                "): the file is damaged");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw inputError(where, "provenance is not valid JSON (byte " + std::to_string(e.byte) +
                                "): the file is damaged");
  }
  Provenance::fromJson(j, where);
  return j;
}

nlohmann::json Provenance::toJson() const {
  // Everything here may come from argv or from paths, which are bytes, not necessarily UTF-8.
  nlohmann::json inputsJson = nlohmann::json::array();
  for (const auto& in : inputs) {
    inputsJson.push_back({{"path", toValidUtf8(in.path)},
                          {"hash", toValidUtf8(in.hash)},
                          {"history", validUtf8Json(in.history)}});
  }
  return {
      {"tool", toValidUtf8(tool)},
      {"version", toValidUtf8(version)},
      {"git_revision", toValidUtf8(gitRevision)},
      {"command_line", toValidUtf8(commandLine)},
      {"parameters", parameters.is_null() ? nlohmann::json::object() : validUtf8Json(parameters)},
      {"inputs", inputsJson}};
}

Provenance Provenance::fromJson(const nlohmann::json& j, const std::string& where) {
  if (!j.is_object()) throw inputError(where, "not a JSON object");
  Provenance p;
  p.tool = stringField(j, "tool", where);
  p.version = stringField(j, "version", where);
  p.gitRevision = stringField(j, "git_revision", where);
  p.commandLine = stringField(j, "command_line", where);
  const auto& params = field(j, "parameters");
  if (!params.is_null() && !params.is_object()) {
    throw inputError(where, "\"parameters\" is not an object");
  }
  if (params.is_object()) p.parameters = params;
  const auto& inputs = field(j, "inputs");
  if (!inputs.is_null() && !inputs.is_array()) throw inputError(where, "\"inputs\" is not a list");
  if (inputs.is_array()) {
    for (const auto& in : inputs) {
      if (!in.is_object()) throw inputError(where, "an input is not an object");
      InputRecord r;
      r.path = stringField(in, "path", where);
      r.hash = stringField(in, "hash", where);
      r.history = field(in, "history");
      if (!r.history.is_null() && !r.history.is_object()) {
        throw inputError(where, "history of input " + r.path + " is not an object");
      }
      p.inputs.push_back(std::move(r));
    }
  }
  return p;
}

std::string Provenance::toText() const {
  std::set<std::string> printed;
  std::ostringstream out;
  appendText(*this, printed, out, 0);
  return out.str();
}

std::string shellQuote(const std::string& word) {
  if (word.empty()) return "''";
  const bool safe = word.find_first_not_of(
                        "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                        "@%+=:,./_-") == std::string::npos;
  if (safe) return word;
  std::string out = "'";
  for (char c : word) {
    if (c == '\'')
      out += "'\\''";
    else
      out += c;
  }
  return out + "'";
}

Provenance makeProvenance(const std::string& tool, int argc, const char* const* argv,
                          const nlohmann::json& parameters) {
  Provenance p;
  p.tool = tool;
#ifdef RAD_VERSION
  p.version = RAD_VERSION;
#else
  p.version = "unknown";
#endif
  p.gitRevision = gitRevision();
  for (int i = 0; i < argc; ++i) {
    if (i) p.commandLine += ' ';
    p.commandLine += shellQuote(argv[i] ? argv[i] : "");
  }
  if (parameters.is_object())
    p.parameters = parameters;
  else if (!parameters.is_null())
    p.parameters = {{"value", parameters}};
  return p;
}

std::string hashFile(const std::string& path) {
  // O_NONBLOCK: opening a FIFO must not wait for a writer (it is refused below); reads of a
  // regular file ignore the flag.
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) throw inputError(path, std::string("cannot open: ") + std::strerror(errno));
  struct stat st;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw inputError(path, "not a regular file");
  }
  // 64 KiB, not zero-filled: rad-compose hashes every movie it reads (tens of thousands in a
  // from-scratch run), and a fresh zeroed 1 MiB buffer per file cost a memset and 256 page faults
  // each.
  constexpr size_t kChunk = size_t(1) << 16;
  std::unique_ptr<unsigned char[]> buf(new unsigned char[kChunk]);
  uint64_t h = kFnv1a64Offset;
  for (;;) {
    const ssize_t n = ::read(fd, buf.get(), kChunk);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      ::close(fd);
      throw inputError(path, std::string("cannot read: ") + std::strerror(err));
    }
    if (n == 0) break;
    h = fnv1a64(buf.get(), static_cast<std::size_t>(n), h);
  }
  ::close(fd);
  return formatFnv1a64(h);
}

std::vector<std::string> parameterMismatch(const nlohmann::json& built,
                                           const nlohmann::json& expected,
                                           const std::vector<std::string>& keys) {
  std::vector<std::string> out;
  auto lookup = [](const nlohmann::json& obj, const std::string& key) -> const nlohmann::json* {
    if (!obj.is_object()) return nullptr;
    const auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  };
  for (const auto& key : keys) {
    const nlohmann::json* b = lookup(built, key);
    const nlohmann::json* e = lookup(expected, key);
    const bool hasB = b != nullptr, hasE = e != nullptr;
    if (!hasB && !hasE) continue;
    if (hasB && hasE && *b == *e) continue;
    const std::string name = optionName(key);
    std::string msg = hasB ? "built with " + name + " " + optionValue(*b) : "built without " + name;
    msg += hasE ? "; this run expects " + optionValue(*e) : "; this run does not set it";
    out.push_back(msg);
  }
  return out;
}

}  // namespace rad
