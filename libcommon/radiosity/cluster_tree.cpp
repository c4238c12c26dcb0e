// The cluster hierarchy above the top-level patches (see the header).
#include "libcommon/radiosity/cluster_tree.h"

#include <algorithm>
#include <map>

namespace rad {

ClusterBounds polygonBounds(const Polygon& p) {
  ClusterBounds b;
  b.lo = b.hi = p.v[0];
  for (int i = 1; i < p.count; ++i) {
    b.lo = glm::min(b.lo, p.v[size_t(i)]);
    b.hi = glm::max(b.hi, p.v[size_t(i)]);
  }
  b.area = p.area();
  return b;
}

ClusterTree::ClusterTree(const PatchHierarchy& h, const std::vector<Polygon>& staticWorld,
                         const std::vector<char>& moving) {
  const int T = h.topCount();
  if (T < 2) return;
  // The sub-trees: static tops in world space, each moving node's tops in its local frame.
  std::vector<glm::dvec3> centre(static_cast<size_t>(T));
  std::map<int, std::vector<uint32_t>> groups;  // mesh node (or -1: static) -> its tops
  for (int t = 0; t < T; ++t) {
    const bool m = size_t(t) < moving.size() && moving[size_t(t)];
    centre[size_t(t)] = m ? h.top(t).local.centroid() : staticWorld[size_t(t)].centroid();
    groups[m ? h.top(t).node : -1].push_back(uint32_t(t));
  }
  topParent_.assign(size_t(T), -1);
  nodes_.emplace_back();  // the root, index 0
  if (groups.size() == 1) {
    std::vector<uint32_t>& tops = groups.begin()->second;
    nodes_.clear();
    build(tops, 0, tops.size(), centre, -1);
    return;
  }
  nodes_[0].first = 0;
  for (auto& [node, tops] : groups) {
    ClusterRef sub =
        tops.size() == 1 ? ClusterRef(tops[0]) : build(tops, 0, tops.size(), centre, 0);
    nodes_[0].children.push_back(sub);
    if (!isCluster(sub)) {
      topParent_[size_t(sub)] = 0;
      members_.push_back(uint32_t(sub));
    }
  }
  nodes_[0].count = uint32_t(members_.size());
}

// Median split on the longest axis of the centres' bounds (ties by top index, so the tree does
// not depend on the sort's order); a range of one top is that top.
ClusterRef ClusterTree::build(std::vector<uint32_t>& tops, size_t lo, size_t hi,
                              const std::vector<glm::dvec3>& centre, int parent) {
  const int c = int(nodes_.size());
  nodes_.emplace_back();
  nodes_[size_t(c)].parent = parent;
  nodes_[size_t(c)].first = uint32_t(members_.size());
  glm::dvec3 a = centre[tops[lo]], b = a;
  for (size_t i = lo; i < hi; ++i)
    a = glm::min(a, centre[tops[i]]), b = glm::max(b, centre[tops[i]]);
  const glm::dvec3 ext = b - a;
  const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
  const size_t mid = lo + (hi - lo) / 2;
  std::nth_element(tops.begin() + long(lo), tops.begin() + long(mid), tops.begin() + long(hi),
                   [&](uint32_t p, uint32_t q) {
                     const double cp = centre[p][axis], cq = centre[q][axis];
                     return cp < cq || (cp == cq && p < q);
                   });
  for (auto [from, to] : {std::make_pair(lo, mid), std::make_pair(mid, hi)}) {
    ClusterRef child;
    if (to - from == 1) {
      child = ClusterRef(tops[from]);
      topParent_[tops[from]] = c;
      members_.push_back(tops[from]);
    } else {
      child = clusterRef(0);  // placeholder: build() appends nodes_
      child = build(tops, from, to, centre, c);
    }
    nodes_[size_t(c)].children.push_back(child);
  }
  nodes_[size_t(c)].count = uint32_t(members_.size()) - nodes_[size_t(c)].first;
  return clusterRef(c);
}

std::vector<ClusterBounds> clusterBoundsOf(const ClusterTree& tree,
                                           const std::vector<Polygon>& world) {
  std::vector<ClusterBounds> out(size_t(tree.size()));
  for (int c = tree.size(); c-- > 0;) {  // sub-clusters (higher indices) first
    ClusterBounds& b = out[size_t(c)];
    bool firstChild = true;
    for (ClusterRef r : tree.node(c).children) {
      const ClusterBounds cb =
          isCluster(r) ? out[size_t(clusterIndex(r))] : polygonBounds(world[size_t(r)]);
      b.lo = firstChild ? cb.lo : glm::min(b.lo, cb.lo);
      b.hi = firstChild ? cb.hi : glm::max(b.hi, cb.hi);
      b.area += cb.area;
      firstChild = false;
    }
  }
  return out;
}

}  // namespace rad
