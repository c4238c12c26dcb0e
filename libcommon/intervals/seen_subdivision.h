// rad-intervals' patch nodes: the regular subdivision of every top-level patch down to
// --max-level (paper §4.3: a patch is shown at its own level or by its children), numbered as if
// made in full, but made only for the tops some frame has shown (issue 58; docs/design.md §6.2).
//
// Numbers. Node (top t, level l, quadtree path p, the l child indices read as a base-4 number,
// level 1 most significant) has number T (4^l - 1) / 3 + t 4^l + p, T = top count: the order of a
// subdivision made level by level, each level top-major. That is what rad-intervals' item ids
// (number + 1) and visible samples files (formats/visible_samples.md) name, so they do not depend
// on which tops were made, or in which order.
//
// Made lazily. A top's subtree (4 + 16 + ... + 4^L nodes) is added to the hierarchy the first time
// a frame shows one of its leaves. A top no frame shows has no visible sample, so no movie and no
// level to choose: its subtree would only hold memory (most tops of a floor of furnished rooms are
// never in view). The hierarchy's dense indices then follow the order tops were made in; every
// rule of the builder reads nodes through their ids and numbers, so the movies do not depend on it.
// Within a subtree, dense indices grow with depth (children after parents), each level in number
// order.
#pragma once

#include <cstdint>
#include <vector>

#include "libcommon/scene/patch_hierarchy.h"

namespace rad {

class SeenSubdivision {
 public:
  SeenSubdivision() = default;
  // Throws rad::Error(kUsage) naming --max-level when the full subdivision's numbers would not fit
  // an item id (32 bits) or `maxNodes`.
  SeenSubdivision(std::vector<InputPolygon> tops, int maxLevel, uint64_t maxNodes);

  const PatchHierarchy& hierarchy() const { return hierarchy_; }
  int topCount() const { return hierarchy_.topCount(); }
  int maxLevel() const { return maxLevel_; }
  // Nodes of the full subdivision: T (4^(L+1) - 1) / 3.
  uint64_t fullNodeCount() const { return fullNodes_; }
  // Whether `number` names a leaf of the full subdivision (level maxLevel).
  bool isLeafNumber(uint64_t number) const { return number >= firstLeaf_ && number < fullNodes_; }
  int topOfLeafNumber(uint64_t number) const {
    return int((number - firstLeaf_) >> (2 * maxLevel_));
  }
  // Whether top t was given to make(): its subtree is in the hierarchy.
  bool made(int top) const { return subtree_[size_t(top)] >= 0; }
  int topsMade() const { return topsMade_; }
  // Makes the subtrees of `tops` (any order, repeats allowed) that are not made yet, in ascending
  // top order, so that the dense indices depend only on the tops each call was given. For
  // maxLevel 0 there is nothing to add: the tops are only marked made.
  void make(std::vector<int> tops);
  // Dense index of a leaf number (isLeafNumber); -1 when its top is not made.
  int nodeOfLeafNumber(uint64_t number) const;
  // Number of dense node i.
  uint64_t numberOf(int node) const;
  // The 4^maxLevel leaf polygons of top t in number order (made or not), in its node's frame.
  std::vector<Polygon> leafPolygons(int top) const;

 private:
  PatchHierarchy hierarchy_;
  int maxLevel_ = 0;
  uint64_t fullNodes_ = 0, firstLeaf_ = 0;
  // Per top: -1 = not made; else the dense index of its first child (maxLevel > 0) or the top's
  // own.
  std::vector<int> subtree_;
  int topsMade_ = 0;
};

}  // namespace rad
