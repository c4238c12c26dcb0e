#include "libcommon/intervals/movie_extent.h"

namespace rad {

const char* movieEndName(MovieEnd e) {
  switch (e) {
    case MovieEnd::kLeftFrustum:
      return "left_frustum";
    case MovieEnd::kHidden:
      return "hidden";
    case MovieEnd::kLevelChange:
      return "level_change";
    case MovieEnd::kResize:
      return "resize";
    case MovieEnd::kMaxLength:
      return "max_length";
    case MovieEnd::kWindow:
      return "window";
  }
  return "unknown";
}

}  // namespace rad
