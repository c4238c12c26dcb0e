// What the pipeline tests share: the stage names, a fresh folder, the Makefile's command line at
// small settings and which stages `make -n` would run.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "tests/cli/cli_util.h"

namespace rad::test {

inline const std::vector<std::string> kStages = {"rad-global", "rad-intervals", "rad-movies",
                                                 "rad-compose"};

// The stages that are not built: the pipeline tests fail on them, they do not skip.
inline std::vector<std::string> missingStages() {
  std::vector<std::string> missing;
  for (const std::string& s : kStages)
    if (!std::filesystem::exists(tool(s))) missing.push_back(s);
  return missing;
}

// Small, fast settings; the Makefile is the one the README runs.
inline std::string makeCommand(const std::filesystem::path& out,
                               const std::string& bin = RAD_BIN_DIR,
                               const std::string& extra = "") {
  return "make --no-print-directory -C " RAD_SOURCE_DIR " -f pipelines/animation.mk BIN=" + bin +
         " OUT=" + out.string() + " FRAMES=0-7 SIZE=88x60 " + extra;
}

inline std::filesystem::path freshDir(const std::string& name) {
  namespace fs = std::filesystem;
  fs::path d =
      fs::temp_directory_path() / ("rad_pipeline_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// Which stages `make -n` would run.
inline std::vector<std::string> stagesMakeWouldRun(const std::string& command) {
  CommandResult r = runCommand(command + " -n");
  std::vector<std::string> run;
  for (const std::string& s : kStages)
    if (r.out.find("/" + s + " ") != std::string::npos) run.push_back(s);
  return run;
}

}  // namespace rad::test
