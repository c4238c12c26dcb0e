// BoxTree (box_tree.h): median splits on the widest axis of the centres, four items a leaf.
#include "libcommon/scene/box_tree.h"

#include <algorithm>
#include <limits>

namespace rad {
namespace {

constexpr int kLeafItems = 4;

bool meets(const AxisBox& a, const glm::dvec3& lo, const glm::dvec3& hi) {
  return a[0].x <= hi.x && lo.x <= a[1].x && a[0].y <= hi.y && lo.y <= a[1].y && a[0].z <= hi.z &&
         lo.z <= a[1].z;
}

}  // namespace

BoxTree::BoxTree(const std::vector<AxisBox>& boxes) : boxes_(boxes) {
  std::vector<glm::dvec3> centre(boxes.size());
  for (size_t i = 0; i < boxes.size(); ++i) {
    const AxisBox& b = boxes[i];
    if (b[0].x > b[1].x || b[0].y > b[1].y || b[0].z > b[1].z) continue;
    items_.push_back(int(i));
    centre[i] = 0.5 * (b[0] + b[1]);
  }
  if (!items_.empty()) build(0, int(items_.size()), centre);
}

int BoxTree::build(int lo, int hi, const std::vector<glm::dvec3>& centre) {
  const int index = int(nodes_.size());
  nodes_.emplace_back();
  AxisBox box{glm::dvec3(std::numeric_limits<double>::infinity()),
              glm::dvec3(-std::numeric_limits<double>::infinity())};
  glm::dvec3 clo = box[0], chi = box[1];
  for (int i = lo; i < hi; ++i) {
    const int item = items_[size_t(i)];
    box[0] = glm::min(box[0], boxes_[size_t(item)][0]);
    box[1] = glm::max(box[1], boxes_[size_t(item)][1]);
    clo = glm::min(clo, centre[size_t(item)]);
    chi = glm::max(chi, centre[size_t(item)]);
  }
  nodes_[size_t(index)].box = box;
  if (hi - lo <= kLeafItems) {
    nodes_[size_t(index)].first = lo;
    nodes_[size_t(index)].count = hi - lo;
    return index;
  }
  const glm::dvec3 extent = chi - clo;
  const int axis =
      extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
  const int mid = lo + (hi - lo) / 2;
  // Ties broken by item index: the tree, and so nothing downstream, depends on sort stability.
  std::nth_element(items_.begin() + lo, items_.begin() + mid, items_.begin() + hi,
                   [&](int a, int b) {
                     const double ca = centre[size_t(a)][axis], cb = centre[size_t(b)][axis];
                     return ca < cb || (ca == cb && a < b);
                   });
  const int left = build(lo, mid, centre);
  const int right = build(mid, hi, centre);
  nodes_[size_t(index)].left = left;
  nodes_[size_t(index)].right = right;
  return index;
}

void BoxTree::query(const glm::dvec3& lo, const glm::dvec3& hi, std::vector<int>& out) const {
  if (nodes_.empty()) return;
  const size_t start = out.size();
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[size_t(stack[--top])];
    if (!meets(n.box, lo, hi)) continue;
    if (n.left < 0) {
      for (int i = n.first; i < n.first + n.count; ++i) {
        const int item = items_[size_t(i)];
        if (meets(boxes_[size_t(item)], lo, hi)) out.push_back(item);
      }
    } else {
      stack[top++] = n.right;
      stack[top++] = n.left;
    }
  }
  std::sort(out.begin() + long(start), out.end());
}

}  // namespace rad
