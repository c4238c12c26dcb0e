// Runs a tool as a user would and captures exit code, stdout and stderr.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace rad::test {

struct CommandResult {
  int exitCode = -1;  // -1: killed by a signal
  std::string out, err;
};

inline std::string readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// `command` is passed to /bin/sh; stdout and stderr go to temporary files.
inline CommandResult runCommand(const std::string& command) {
  namespace fs = std::filesystem;
  static int counter = 0;
  fs::path dir = fs::temp_directory_path();
  std::string tag = std::to_string(::getpid()) + "_" + std::to_string(counter++);
  fs::path out = dir / ("rad_cli_out_" + tag), err = dir / ("rad_cli_err_" + tag);
  std::string full = command + " >" + out.string() + " 2>" + err.string();
  int status = std::system(full.c_str());
  CommandResult r;
  if (WIFEXITED(status)) r.exitCode = WEXITSTATUS(status);
  r.out = readWholeFile(out.string());
  r.err = readWholeFile(err.string());
  fs::remove(out);
  fs::remove(err);
  return r;
}

inline std::string tool(const std::string& name) {
  return std::string(RAD_BIN_DIR) + "/" + name;
}

// Every rad-* executable that was built.
inline std::vector<std::string> builtTools() {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(RAD_BIN_DIR)) {
    std::string n = e.path().filename().string();
    if (n.rfind("rad-", 0) == 0) names.push_back(n);
  }
  std::sort(names.begin(), names.end());
  return names;
}

inline int countLines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

}  // namespace rad::test
