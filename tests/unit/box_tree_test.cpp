// BoxTree (libcommon/scene/box_tree.h) against a scan of every box.
#include "libcommon/scene/box_tree.h"

#include <gtest/gtest.h>

namespace rad {
namespace {

TEST(BoxTree, QueryReturnsExactlyTheBoxesAScanFinds) {
  uint32_t state = 99;
  auto next = [&state] {
    state = state * 1664525u + 1013904223u;
    return double(state >> 8) / double(1u << 24);
  };
  std::vector<AxisBox> boxes;
  for (int i = 0; i < 2000; ++i) {
    glm::dvec3 lo(10 * next(), 10 * next(), 3 * next());
    boxes.push_back({lo, lo + glm::dvec3(next(), 0.3 * next(), 0.0)});  // flat ones too
  }
  boxes[17] = {glm::dvec3(1.0), glm::dvec3(-1.0)};  // empty: never returned
  const BoxTree tree(boxes);
  EXPECT_EQ(tree.size(), boxes.size() - 1);
  size_t found = 0;
  for (int q = 0; q < 200; ++q) {
    glm::dvec3 lo(10 * next(), 10 * next(), 3 * next());
    glm::dvec3 hi = lo + glm::dvec3(2 * next(), 2 * next(), next());
    if (q == 0) lo = hi = boxes[5][0];  // a point on a box's corner touches it
    std::vector<int> expected, got{-7};
    for (size_t i = 0; i < boxes.size(); ++i) {
      const AxisBox& b = boxes[i];
      if (i != 17 && b[0].x <= hi.x && lo.x <= b[1].x && b[0].y <= hi.y && lo.y <= b[1].y &&
          b[0].z <= hi.z && lo.z <= b[1].z)
        expected.push_back(int(i));
    }
    tree.query(lo, hi, got);
    ASSERT_EQ(got.front(), -7) << "query appends";
    got.erase(got.begin());
    EXPECT_EQ(got, expected) << "query " << q;
    if (q == 0) {
      EXPECT_FALSE(expected.empty());
    }
    found += expected.size();
  }
  EXPECT_GT(found, 200u) << "the queries must meet boxes to mean anything";
}

}  // namespace
}  // namespace rad
