#include "formats/form_factor_scratch_file.h"

#include <cerrno>

#include <unistd.h>

namespace rad {

FormFactorScratchFile::~FormFactorScratchFile() {
  if (file_) std::fclose(file_);
}

long long FormFactorScratchFile::put(const std::vector<double>& f) {
  if (failed_) return -1;
  if (!file_ && !(file_ = std::tmpfile())) {
    failed_ = true;
    return -1;
  }
  const char* p = reinterpret_cast<const char*>(f.data());
  size_t left = f.size() * sizeof(double);
  long long at = size_;
  off_t offset = off_t(size_);
  while (left > 0) {
    ssize_t n = ::pwrite(fileno(file_), p, left, offset);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      failed_ = true;
      return -1;
    }
    p += n;
    left -= size_t(n);
    offset += n;
  }
  size_ += (long long)(f.size() * sizeof(double));
  return at;
}

bool FormFactorScratchFile::get(long long at, std::vector<double>& f) const {
  if (!file_ || at < 0) return false;
  char* p = reinterpret_cast<char*>(f.data());
  size_t left = f.size() * sizeof(double);
  off_t offset = off_t(at);
  while (left > 0) {
    ssize_t n = ::pread(fileno(file_), p, left, offset);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    left -= size_t(n);
    offset += n;
  }
  return true;
}

FormFactorSpillFactory formFactorScratchFiles() {
  return [] { return std::make_unique<FormFactorScratchFile>(); };
}

}  // namespace rad
