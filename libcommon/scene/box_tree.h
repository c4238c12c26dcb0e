// A bounding-volume hierarchy over axis-aligned boxes, for "which of these boxes meet that box"
// (rad-movies' blocker candidates of a shaft). Built once; queries are read-only and may run on
// several threads at once.
#pragma once

#include <array>
#include <limits>
#include <vector>

#include <glm/glm.hpp>

namespace rad {

using AxisBox = std::array<glm::dvec3, 2>;  // {lo, hi}

// The empty box (lo +inf, hi -inf): growBox makes it the box of the first point it is given.
inline AxisBox emptyAxisBox() {
  return {glm::dvec3(std::numeric_limits<double>::infinity()),
          glm::dvec3(-std::numeric_limits<double>::infinity())};
}
// Grows b to hold point p.
inline void growBox(AxisBox& b, const glm::dvec3& p) {
  b[0] = glm::min(b[0], p);
  b[1] = glm::max(b[1], p);
}
// Whether two boxes meet (touching counts; an empty box meets nothing).
inline bool boxesMeet(const AxisBox& a, const AxisBox& b) {
  return a[0].x <= b[1].x && b[0].x <= a[1].x && a[0].y <= b[1].y && b[0].y <= a[1].y &&
         a[0].z <= b[1].z && b[0].z <= a[1].z;
}
// Whether b holds point p (its faces included).
inline bool boxHolds(const AxisBox& b, const glm::dvec3& p) {
  return boxesMeet(b, AxisBox{p, p});
}

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
