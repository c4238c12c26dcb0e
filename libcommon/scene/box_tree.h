// A bounding-volume hierarchy over axis-aligned boxes, for "which of these boxes meet that box"
// (rad-movies' blocker candidates of a shaft). Built once; queries are read-only and may run on
// several threads at once.
#pragma once

#include <array>
#include <vector>

#include <glm/glm.hpp>

namespace rad {

using AxisBox = std::array<glm::dvec3, 2>;  // {lo, hi}

class BoxTree {
 public:
  BoxTree() = default;
  // Item i is boxes[i]; an empty box (lo > hi on an axis) is never returned.
  explicit BoxTree(const std::vector<AxisBox>& boxes);
  // Appends to `out`, in ascending item order, every item whose box meets [lo, hi] (touching
  // counts).
  void query(const glm::dvec3& lo, const glm::dvec3& hi, std::vector<int>& out) const;
  size_t size() const { return items_.size(); }

 private:
  struct Node {
    AxisBox box;
    int first = 0, count = 0;  // leaf: items_[first, first + count); inner: count = 0
    int left = -1, right = -1;
  };
  int build(int lo, int hi, const std::vector<glm::dvec3>& centre);
  std::vector<AxisBox> boxes_;
  std::vector<int> items_;
  std::vector<Node> nodes_;
};

}  // namespace rad
