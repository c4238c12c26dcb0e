// An exclusive lock named by a file, for tasks of a render farm that share a folder (issue 58:
// the piece tasks that merge a movie, tools/stages/movie_pieces.h). POSIX record locks (fcntl
// F_SETLKW) on PATH, created if missing: the system releases them when the holder dies (a
// killed task leaves no lock held), and NFS clients forward them to the server's lock manager,
// so tasks on different nodes exclude each other. The holder removes PATH before it lets go;
// a task that opened the old file then gets a lock on a file no one else can open, so whatever
// a holder checks must be checked again under the lock (the lock orders, the files tell).
#pragma once

#include <string>

namespace rad {

class FileLock {
 public:
  // Blocks until this process holds the lock of `path`. Throws rad::outputError(path, ...) when
  // the file cannot be created or locked.
  explicit FileLock(const std::string& path);
  // Removes the file, then lets go.
  ~FileLock();
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

 private:
  std::string path_;
  int fd_ = -1;
};

}  // namespace rad
