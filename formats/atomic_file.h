// Write-to-temporary-then-rename, so an interrupted or failing stage never leaves a half file
// that Make would take as up to date (DESIGN.md §5).
#pragma once

#include <string>

namespace rad {

// Usage: AtomicFile f(path); write the whole output to f.tempPath() by any means (POSIX, OIIO,
// OpenEXR); f.commit(). If commit() is never reached (exception, early return), the destructor
// removes the temporary, and `path` is left as it was (absent or the previous version).
//
// The temporary lives in the same directory as `path` (rename is atomic only within one file
// system) and is a hidden file, ".<stem>.tmp.<pid>.<n><ext>": Make's wildcards skip it, no
// rule names it, and it keeps the extension so writers that pick a format by extension (OIIO)
// still work. A process killed with SIGKILL can leave one behind; it is never mistaken for
// output. Not thread-safe per object; distinct objects may be used from distinct threads.
class AtomicFile {
 public:
  explicit AtomicFile(std::string path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::string& path() const { return path_; }
  const std::string& tempPath() const { return tempPath_; }

  // fsyncs the temporary, renames it onto path() and fsyncs the directory. Throws
  // rad::outputError(path, ...) on failure (the temporary is then removed by the destructor).
  void commit();
  bool committed() const { return committed_; }

 private:
  std::string path_;
  std::string tempPath_;
  bool committed_ = false;
};

// The whole of `text` into `path`, atomically (a stage's JSON report, ...). Throws
// rad::outputError(path, ...).
void writeTextFile(const std::string& path, const std::string& text);

// Writes `size` bytes to `fd`, retrying on EINTR and short writes. Returns false with errno set
// on failure. Shared by the writers that use POSIX descriptors.
bool writeAll(int fd, const void* data, std::size_t size);

}  // namespace rad
