#include "libcommon/scene/patch_hierarchy.h"

#include <random>

#include <gtest/gtest.h>

namespace rad {
namespace {

InputPolygon quad(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d) {
  InputPolygon p;
  p.local = {4, {a, b, c, d}};
  return p;
}
InputPolygon tri(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  InputPolygon p;
  p.local = {3, {a, b, c, {}}};
  return p;
}

PatchHierarchy sample() {
  return PatchHierarchy({quad({0, 0, 0}, {2, 0, 0}, {2.5, 1, 0}, {0.3, 1.2, 0}),
                         tri({0, 0, 1}, {1, 0, 1}, {0.2, 3, 1.5})});
}

TEST(PatchId, PathEncodesLevelAndChildren) {
  PatchId root{7, 1};
  EXPECT_EQ(root.level(), 0);
  PatchId c = root.child(2).child(3).child(0);
  EXPECT_EQ(c.level(), 3);
  EXPECT_EQ(c.childIndex(), 0);
  EXPECT_EQ(c.parent().childIndex(), 3);
  EXPECT_EQ(c.parent().parent().parent(), root);
  EXPECT_EQ(c.toString(), "7/2.3.0");
  EXPECT_EQ(PatchId::fromPacked(c.packed()), c);
}

TEST(PatchHierarchy, ChildrenAreasSumToParentAndNormalsAgree) {
  PatchHierarchy h = sample();
  for (int t = 0; t < h.topCount(); ++t) {
    std::vector<int> stack{t};
    while (!stack.empty()) {
      int i = stack.back();
      stack.pop_back();
      if (h.node(i).id.level() >= 4) continue;
      int first = h.subdivide(i);
      double sum = 0.0;
      for (int k = 0; k < 4; ++k) {
        const PatchNode& c = h.node(first + k);
        sum += c.local.area();
        EXPECT_GT(glm::dot(c.local.normal(), h.node(i).local.normal()), 1.0 - 1e-12);
        EXPECT_EQ(c.parent, i);
        stack.push_back(first + k);
      }
      EXPECT_NEAR(sum, h.node(i).local.area(), 1e-12 * h.node(i).local.area());
    }
  }
}

TEST(PatchHierarchy, TriangleChildrenHaveEqualAreas) {
  PatchHierarchy h = sample();
  int first = h.subdivide(1);
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(h.node(first + k).local.area(), h.node(1).local.area() / 4, 1e-12);
  }
}

TEST(PatchHierarchy, IdsAreIndependentOfRefinementOrder) {
  PatchHierarchy a = sample(), b = sample();
  // a refines breadth first, b creates deep nodes directly in another order.
  int a0 = a.subdivide(0);
  int a02 = a.subdivide(a0 + 2);
  a.subdivide(1);
  int target = a.subdivide(a02 + 1) + 3;
  PatchId id = a.node(target).id;
  b.subdivide(1);
  int bt = b.findOrCreate(id);
  EXPECT_EQ(b.node(bt).id, id);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(a.node(target).local.v[k], b.node(bt).local.v[k]);
  }
  EXPECT_NE(a.find(id), -1);
  EXPECT_EQ(b.find(PatchId{0, 1}.child(0).child(0)), -1);
}

TEST(PatchHierarchy, UvMapRoundTripsAndMatchesChildren) {
  PatchHierarchy h = sample();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int i = 0; i < h.topCount(); ++i) {
    for (int s = 0; s < 100; ++s) {
      glm::dvec2 uv(U(rng), U(rng));
      if (h.node(i).local.count == 3 && uv.x + uv.y > 1) uv = glm::dvec2(1.0) - uv;
      glm::dvec2 back = h.uvAt(i, h.pointAt(i, uv));
      EXPECT_NEAR(back.x, uv.x, 1e-10);
      EXPECT_NEAR(back.y, uv.y, 1e-10);
    }
  }
  // Quad child k's (u,v) square is the parent's quarter square: child 2 covers [.5,1]^2.
  int first = h.subdivide(0);
  glm::dvec3 p = h.pointAt(first + 2, {0.5, 0.5});
  glm::dvec3 q = h.pointAt(0, {0.75, 0.75});
  EXPECT_NEAR(glm::length(p - q), 0.0, 1e-12);
  // Corners: a quad maps (1,1) to v2, a triangle maps (0,1) to v2.
  EXPECT_EQ(h.pointAt(0, {1, 1}), h.node(0).local.v[2]);
  EXPECT_EQ(h.pointAt(1, {0, 1}), h.node(1).local.v[2]);
}

// PolygonUvMap takes the affine inverse for triangles and parallelograms (no Newton) and
// Newton's method for other quads: all must invert polygonPointAt.
TEST(PatchHierarchy, PolygonUvMapInvertsPointAtForEveryShape) {
  std::vector<Polygon> shapes = {
      {4, {glm::dvec3(0, 0, 0), {2, 0, 0}, {2.5, 1, 0}, {0.3, 1.2, 0}}},        // general quad
      {4, {glm::dvec3(1, 1, 1), {3, 1.5, 1}, {3.5, 2.5, 2}, {1.5, 2, 2}}},      // parallelogram
      {4, {glm::dvec3(0, 0, 5), {1e-3, 0, 5}, {1e-3, 2e-3, 5}, {0, 2e-3, 5}}},  // mm rectangle
      {3, {glm::dvec3(0, 0, 1), {1, 0, 1}, {0.2, 3, 1.5}, {}}}};
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (const Polygon& p : shapes) {
    const PolygonUvMap map(p);
    for (int s = 0; s < 200; ++s) {
      glm::dvec2 uv(U(rng), U(rng));
      if (p.count == 3 && uv.x + uv.y > 1) uv = glm::dvec2(1.0) - uv;
      glm::dvec3 x = polygonPointAt(p, uv);
      glm::dvec2 back = map.uvAt(x);
      EXPECT_NEAR(back.x, uv.x, 1e-10) << p.count;
      EXPECT_NEAR(back.y, uv.y, 1e-10) << p.count;
      EXPECT_EQ(back, polygonUvAt(p, x));
    }
  }
  // A degenerate polygon gives (0,0), as polygonUvAt always did.
  Polygon line{4, {glm::dvec3(0), {1, 0, 0}, {2, 0, 0}, {3, 0, 0}}};
  EXPECT_EQ(PolygonUvMap(line).uvAt(glm::dvec3(1, 0, 0)), glm::dvec2(0.0));
}

TEST(PatchHierarchy, CentroidOfChildrenIsParentCentroid) {
  PatchHierarchy h = sample();
  for (int t = 0; t < 2; ++t) {
    int first = h.subdivide(t);
    glm::dvec3 c(0.0);
    double a = 0.0;
    for (int k = 0; k < 4; ++k) {
      c += h.node(first + k).local.area() * h.node(first + k).local.centroid();
      a += h.node(first + k).local.area();
    }
    EXPECT_NEAR(glm::length(c / a - h.node(t).local.centroid()), 0.0, 1e-12);
  }
}

}  // namespace
}  // namespace rad
