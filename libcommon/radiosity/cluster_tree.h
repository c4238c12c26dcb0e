// The cluster hierarchy above the top-level patches (Smits, Arvo, Greenberg 1994, "A clustering
// algorithm for radiosity in complex environments"; Sillion 1995, "A unified hierarchical
// algorithm for global illumination with scattering volumes and object clusters"), which lets
// rad-global's linking start from one self-link of the root instead of pairing every top-level
// patch with every other (paper §6.1 names that pairing as the first pass's main cost).
//
// A bounding volume hierarchy over the top-level patches, built once for the whole animation.
// A cluster never mixes static and moving geometry: the static patches form one sub-tree and
// each moving mesh node its own, built from its patches in the node's local frame, so that the
// sub-tree moves with the node (rigidly or affinely) and keeps its cluster indices and therefore
// its links' seeds from key to key. The root joins the sub-trees. A cluster's bounds at a key
// time come from its patches' world polygons then (ClusterBounds).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/scene/geometry.h"
#include "libcommon/scene/patch_hierarchy.h"

namespace rad {

// An end of a cluster link: a top-level patch (its dense node index, >= 0) or cluster c,
// encoded as ~c (< 0).
using ClusterRef = int;
inline bool isCluster(ClusterRef r) {
  return r < 0;
}
inline int clusterIndex(ClusterRef r) {
  return ~r;
}
inline ClusterRef clusterRef(int c) {
  return ~c;
}

struct ClusterNode {
  std::vector<ClusterRef> children;  // two or more; sub-clusters have higher indices
  int parent = -1;                   // cluster index, -1 for the root
  uint32_t first = 0, count = 0;     // member tops: ClusterTree::members()[first, first + count)
};

class ClusterTree {
 public:
  ClusterTree() = default;
  // `moving`: per top-level patch, whether its mesh node moves during the animation; the
  // sub-trees are built from the tops' local polygons (static nodes' local frame is fixed, so
  // their world placement is a fixed transform that does not change the split choices much;
  // `world` gives the static tops' placement at the first key time).
  ClusterTree(const PatchHierarchy& hierarchy, const std::vector<Polygon>& staticWorld,
              const std::vector<char>& moving);

  bool empty() const { return nodes_.empty(); }
  int size() const { return int(nodes_.size()); }
  int root() const { return 0; }
  const ClusterNode& node(int c) const { return nodes_[size_t(c)]; }
  // The tops in tree order: every cluster's members are a contiguous range.
  const std::vector<uint32_t>& members() const { return members_; }
  // The cluster whose children include top t (-1 when there is no tree).
  int parentOfTop(int t) const { return topParent_.empty() ? -1 : topParent_[size_t(t)]; }

 private:
  ClusterRef build(std::vector<uint32_t>& tops, size_t lo, size_t hi,
                   const std::vector<glm::dvec3>& centre, int parent);
  std::vector<ClusterNode> nodes_;
  std::vector<uint32_t> members_;
  std::vector<int> topParent_;
};

// A cluster's (or top's) extent at one key time: its bounding sphere (the centre and half
// diagonal of its world bounding box) and its one-sided surface area.
struct ClusterBounds {
  glm::dvec3 lo{0.0}, hi{0.0};
  double area = 0;
  glm::dvec3 centre() const { return 0.5 * (lo + hi); }
  double radius() const { return 0.5 * glm::length(hi - lo); }
};

// Per cluster, its bounds from the tops' world polygons `world` (indexed by top).
std::vector<ClusterBounds> clusterBoundsOf(const ClusterTree& tree,
                                           const std::vector<Polygon>& world);
ClusterBounds polygonBounds(const Polygon& p);

}  // namespace rad
