// What every libFuzzer harness of a reader shares (README "Reliability", tests/fuzz/README.md).
//
// A reader's contract on hostile input is "rad::Error or success": runReader swallows
// rad::Error and nothing else, so any other exception, a signal or a sanitizer report stops
// the fuzzer with the input that caused it.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "libcommon/core/error.h"

namespace rad::fuzz {

template <class Read>
void runReader(Read&& read) {
  try {
    read();
  } catch (const rad::Error&) {
    // Expected: the reader refused the input with a one-line message.
  }
}

// A private directory for this process (the path readers take their input by). Under
// $TMPDIR, or /dev/shm when it exists so each execution's write stays in memory.
inline const std::string& scratchDir() {
  // Never destroyed: the atexit handler that removes the directory runs after static
  // destructors registered later would have freed it.
  static const std::string* dir = [] {
    const char* base = std::getenv("TMPDIR");
    std::string root = base ? base : (access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp");
    std::string pattern = root + "/rad-fuzz-XXXXXX";
    std::vector<char> buf(pattern.begin(), pattern.end());
    buf.push_back('\0');
    if (!mkdtemp(buf.data())) std::abort();
    std::atexit([] { std::filesystem::remove_all(scratchDir()); });
    return new std::string(buf.data());
  }();
  return *dir;
}

// Writes the fuzzer's bytes to `name` in scratchDir() and returns its path.
inline std::string writeScratch(const std::string& name, const uint8_t* data, size_t size) {
  std::string path = scratchDir() + "/" + name;
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  return path;
}

}  // namespace rad::fuzz
