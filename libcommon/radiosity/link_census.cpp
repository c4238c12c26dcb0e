// The link census of a key time (link_census.h).
#include "libcommon/radiosity/link_census.h"

namespace rad {

int LinkCensus::sizeClass(size_t members) {
  int c = 0;
  for (size_t top = 1; members > top && c + 1 < kSizeClasses; top *= 4) ++c;
  return c;
}

nlohmann::json LinkCensus::toJson() const {
  auto total = [](const BySize& s) {
    size_t n = 0;
    for (size_t v : s) n += v;
    return n;
  };
  auto bySize = [&](const BySize& s) {
    return nlohmann::json{{"total", total(s)}, {"by_size", s}};
  };
  return {{"size_classes", {"1", "2-4", "5-16", "17-64", "65-256", ">256"}},
          {"patch",
           {{"leaves", patchLeaves},
            {"refined", patchRefined},
            {"light", patchLight},
            {"blocked", patchBlocked},
            {"near_tops", patchNearTops}}},
          {"cluster",
           {{"light", bySize(clusterLight)},
            {"near", bySize(clusterNear)},
            {"far", bySize(clusterFar)}}},
          {"near_tests",
           {{"refined", bySize(nearRefined)},
            {"untested", bySize(nearUntested)},
            {"dropped", bySize(nearDropped)}}}};
}

}  // namespace rad
