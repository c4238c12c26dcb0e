// Write-to-temporary-then-rename, so an interrupted or failing stage never leaves a half file
// that Make would take as up to date (docs/design.md §5).
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
// still work. While it may exist it is registered (formats/temp_file_registry.h): SIGINT,
// SIGTERM and SIGHUP remove it before the process dies of the signal. A process killed with
// SIGKILL can leave one behind; it is never mistaken for output. Not thread-safe per object;
// distinct objects may be used from distinct threads.
class AtomicFile {
 public:
  // How commit() makes the file durable (survive a power loss, not only a crash of the process;
  // either way no reader ever sees a half file under `path`).
  enum class Durability {
    kEachFile,  // fsync the temporary before the rename and the directory after it
    // Rename only. For a stage writing thousands of small files (rad-movies), where one fsync
    // per file was most of the write time: the stage calls syncFileSystemOf() once before it
    // reports success, and Make's completion stamp is written after that, so after a power
    // loss either the stamp is missing (the stage is re-run) or every file is on disk.
    kDeferred,
  };
  explicit AtomicFile(std::string path, Durability durability = Durability::kEachFile);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::string& path() const { return path_; }
  const std::string& tempPath() const { return tempPath_; }

  // fsyncs the temporary (kEachFile), renames it onto path() and fsyncs the directory. Throws
  // rad::outputError(path, ...) on failure (the temporary is then removed by the destructor).
  void commit();
  bool committed() const { return committed_; }

 private:
  std::string path_;
  std::string tempPath_;
  Durability durability_;
  bool committed_ = false;
  int registrySlot_ = -1;  // registerTempFile's slot for tempPath_
};

// Flushes the whole file system holding `path` (syncfs(2)): the one sync that makes files
// committed with AtomicFile::Durability::kDeferred durable. Throws rad::outputError(path, ...).
void syncFileSystemOf(const std::string& path);

// The whole of `text` into `path`, atomically (a stage's JSON report, ...). Throws
// rad::outputError(path, ...).
void writeTextFile(const std::string& path, const std::string& text);

// Writes `size` bytes to `fd`, retrying on EINTR and short writes. Returns false with errno set
// on failure. Shared by the writers that use POSIX descriptors.
bool writeAll(int fd, const void* data, std::size_t size);

}  // namespace rad
