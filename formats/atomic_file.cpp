#include "formats/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <utility>

#include "formats/temp_file_registry.h"
#include "libcommon/core/error.h"

namespace rad {

namespace {

// Distinguishes two AtomicFiles for the same path in one process (e.g. two threads).
std::atomic<unsigned> gTempCounter{0};

std::string directoryOf(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

}  // namespace

AtomicFile::AtomicFile(std::string path, Durability durability)
    : path_(std::move(path)), durability_(durability) {
  const auto slash = path_.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "" : path_.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? path_ : path_.substr(slash + 1);
  // Keep the extension last; a leading-dot name such as ".hidden" has no extension.
  const auto dot = name.find_last_of('.');
  const bool hasExt = dot != std::string::npos && dot > 0;
  const std::string stem = hasExt ? name.substr(0, dot) : name;
  const std::string ext = hasExt ? name.substr(dot) : "";
  tempPath_ = dir + "." + stem + ".tmp." + std::to_string(::getpid()) + "." +
              std::to_string(gTempCounter.fetch_add(1)) + ext;
  registrySlot_ = registerTempFile(tempPath_);
}

AtomicFile::~AtomicFile() {
  if (!committed_) ::unlink(tempPath_.c_str());  // ENOENT is fine: nothing was written
  unregisterTempFile(registrySlot_);
}

void AtomicFile::commit() {
  if (committed_) return;
  if (durability_ == Durability::kDeferred) {
    if (::rename(tempPath_.c_str(), path_.c_str()) != 0) {
      throw outputError(
          path_, std::string("cannot rename temporary file into place: ") + std::strerror(errno));
    }
    committed_ = true;
    unregisterTempFile(std::exchange(registrySlot_, -1));
    return;
  }
  // Flush the data before the rename makes it visible, so a crash cannot leave a complete
  // name with incomplete content.
  int fd = ::open(tempPath_.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    throw outputError(path_,
                      "cannot open temporary file " + tempPath_ + ": " + std::strerror(errno));
  }
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    throw outputError(path_, std::string("cannot sync: ") + std::strerror(err));
  }
  ::close(fd);
  if (::rename(tempPath_.c_str(), path_.c_str()) != 0) {
    throw outputError(
        path_, std::string("cannot rename temporary file into place: ") + std::strerror(errno));
  }
  committed_ = true;
  unregisterTempFile(std::exchange(registrySlot_, -1));
  // Make the rename itself durable; failure here is not worth failing the stage for.
  int dirFd = ::open(directoryOf(path_).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dirFd >= 0) {
    ::fsync(dirFd);
    ::close(dirFd);
  }
}

void syncFileSystemOf(const std::string& path) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw outputError(path, std::string("cannot open to sync: ") + std::strerror(errno));
  const bool ok = ::syncfs(fd) == 0;
  const int err = errno;
  ::close(fd);
  if (!ok) throw outputError(path, std::string("cannot sync: ") + std::strerror(err));
}

void writeTextFile(const std::string& path, const std::string& text) {
  AtomicFile file(path);
  int fd = ::open(file.tempPath().c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw outputError(path, std::string("cannot create: ") + std::strerror(errno));
  bool ok = writeAll(fd, text.data(), text.size());
  const int err = errno;
  ok = ::close(fd) == 0 && ok;
  if (!ok) throw outputError(path, std::string("cannot write: ") + std::strerror(err));
  file.commit();
}

bool writeAll(int fd, const void* data, std::size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, p, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    p += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace rad
