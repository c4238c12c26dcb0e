// rad-intervals' patch nodes made for the tops a frame shows. Contract in seen_subdivision.h.
#include "libcommon/intervals/seen_subdivision.h"

#include <algorithm>
#include <functional>
#include <limits>
#include <string>

#include "libcommon/core/error.h"

namespace rad {
namespace {

// 4^l.
uint64_t pow4(int l) {
  return uint64_t(1) << (2 * l);
}

// Nodes above level l in a subdivision of `tops` tops made level by level: T (4^l - 1) / 3.
uint64_t nodesAbove(uint64_t tops, int l) {
  return tops * ((pow4(l) - 1) / 3);
}

}  // namespace

SeenSubdivision::SeenSubdivision(std::vector<InputPolygon> tops, int maxLevel, uint64_t maxNodes)
    : hierarchy_(std::move(tops)), maxLevel_(maxLevel) {
  const uint64_t t = uint64_t(hierarchy_.topCount());
  // Level bounds come from TextureIntervalsOptions::validate ([0, 8]), so 4^(L+1) fits.
  fullNodes_ = nodesAbove(t, maxLevel + 1);
  firstLeaf_ = nodesAbove(t, maxLevel);
  // Item ids are number + 1 in 32 bits (0 is kNoItem); dense indices are ints.
  const uint64_t limit =
      std::min<uint64_t>(maxNodes, uint64_t(std::numeric_limits<int32_t>::max()));
  if (fullNodes_ > limit)
    throw Error(ExitCode::kUsage, "",
                "--max-level " + std::to_string(maxLevel) + ": " + std::to_string(t) +
                    " top-level patches would make " + std::to_string(fullNodes_) +
                    " patch nodes (at most " + std::to_string(limit) +
                    "); use a smaller --max-level");
  subtree_.assign(size_t(t), -1);
}

void SeenSubdivision::make(std::vector<int> tops) {
  std::sort(tops.begin(), tops.end());
  tops.erase(std::unique(tops.begin(), tops.end()), tops.end());
  for (int top : tops) {
    if (subtree_[size_t(top)] >= 0) continue;
    ++topsMade_;
    if (maxLevel_ == 0) {
      subtree_[size_t(top)] = top;
      continue;
    }
    // Level by level, so that each level's dense indices follow its numbers (header).
    std::vector<int> level{top};
    int firstChild = -1;
    for (int l = 0; l < maxLevel_; ++l) {
      std::vector<int> next;
      next.reserve(level.size() * 4);
      for (int i : level) {
        const int c = hierarchy_.subdivide(i);
        if (firstChild < 0) firstChild = c;
        for (int k = 0; k < 4; ++k) next.push_back(c + k);
      }
      level.swap(next);
    }
    subtree_[size_t(top)] = firstChild;
  }
}

int SeenSubdivision::nodeOfLeafNumber(uint64_t number) const {
  const int top = topOfLeafNumber(number);
  const int first = subtree_[size_t(top)];
  if (first < 0) return -1;
  if (maxLevel_ == 0) return top;
  const uint64_t path = (number - firstLeaf_) & (pow4(maxLevel_) - 1);
  // Levels 1 .. L-1 of the subtree come first: 4 + 16 + ... + 4^(L-1) = (4^L - 4) / 3 nodes.
  return first + int((pow4(maxLevel_) - 4) / 3 + path);
}

uint64_t SeenSubdivision::numberOf(int node) const {
  const PatchId id = hierarchy_.node(node).id;
  const int l = id.level();
  const uint64_t path = uint64_t(id.path) - pow4(l);  // the leading 1 bit dropped
  return nodesAbove(uint64_t(topCount()), l) + uint64_t(id.top) * pow4(l) + path;
}

std::vector<Polygon> SeenSubdivision::leafPolygons(int top) const {
  std::vector<Polygon> leaves;
  leaves.reserve(size_t(pow4(maxLevel_)));
  // Depth first in child order: the leaves' paths ascending. subdividePolygon is what
  // PatchHierarchy::subdivide splits with, so the same polygons as a made subtree's.
  std::function<void(const Polygon&, int)> descend = [&](const Polygon& p, int level) {
    if (level == maxLevel_) {
      leaves.push_back(p);
      return;
    }
    for (const Polygon& child : subdividePolygon(p)) descend(child, level + 1);
  };
  descend(hierarchy_.top(top).local, 0);
  return leaves;
}

}  // namespace rad
