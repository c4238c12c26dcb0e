// A lock named by a file. Contract in file_lock.h.
#include "tools/stages/file_lock.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "libcommon/core/error.h"

namespace rad {

FileLock::FileLock(const std::string& path) : path_(path) {
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throw outputError(path, std::string("cannot create the lock: ") + std::strerror(errno));
  struct flock whole = {};
  whole.l_type = F_WRLCK;
  whole.l_whence = SEEK_SET;  // from the start, l_len 0: the whole file
  while (::fcntl(fd_, F_SETLKW, &whole) != 0) {
    if (errno == EINTR) continue;
    const int e = errno;
    ::close(fd_);
    throw outputError(path, std::string("cannot lock: ") + std::strerror(e));
  }
}

FileLock::~FileLock() {
  ::unlink(path_.c_str());
  ::close(fd_);  // closing any descriptor of the file releases the process's record locks
}

}  // namespace rad
