#include "formats/checksum.h"

#include <cstdio>

namespace rad {

std::string formatFnv1a64(uint64_t h) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "fnv1a64:%016llx", static_cast<unsigned long long>(h));
  return buf;
}

}  // namespace rad
