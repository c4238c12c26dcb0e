// The links of one key time by kind at the end of its refinement (issue 58): which links fill
// the link bound (RadiosityOptions::maxLinks) where a key reaches it. rad-global's report gives
// it per key ("link_census"); counting takes one pass over the links and changes nothing.
#pragma once

#include <array>
#include <cstddef>

#include <nlohmann/json.hpp>

namespace rad {

struct LinkCensus {
  // A cluster link's size class: the member tops of its larger end, 1 (a top), 2-4, 5-16,
  // 17-64, 65-256, more (sizeClass).
  static constexpr int kSizeClasses = 6;
  using BySize = std::array<size_t, kSizeClasses>;
  static int sizeClass(size_t members);

  // Patch links (HSA'91): the leaves the solve gathers and the refined ones the bound also
  // counts; of the leaves, those whose shooter emits, those with V = 0 (every ray blocked), and
  // those whose top-level patches are near each other by the cluster links' rule (the centres
  // of their bounding spheres closer than the separation times the radii's sum).
  size_t patchLeaves = 0, patchRefined = 0, patchLight = 0, patchBlocked = 0, patchNearTops = 0;
  // Cluster links kept (cluster_links.h), by size class: from a shooter that holds a light;
  // near (kept only where the bound stopped refinement); far (the power bound satisfied).
  BySize clusterLight{}, clusterNear{}, clusterFar{};
  // The near links without a light met in this key's refinement: refined after their blocked
  // test found light, refined untested (more facing member pairs than the test takes), and
  // dropped as blocked; each by size class.
  BySize nearRefined{}, nearUntested{}, nearDropped{};

  // {"patch": {...}, "cluster": {"light": [...], ...}, "near_tests": {...}}, arrays by size class.
  nlohmann::json toJson() const;
};

}  // namespace rad
