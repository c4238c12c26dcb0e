// The scene's top-level patches for issue 56's seams: the planar surfaces their samples are
// seeded by (planar_surfaces.h), and the corner a triangle's (u,v) map starts at (scene.h).
#include "libcommon/scene/planar_surfaces.h"

#include <gtest/gtest.h>

namespace rad {
namespace {

// Texture coordinates uvScale (x, y): triangles of different scales do not merge into a quad.
int addTriangles(Scene& s, const std::vector<std::array<glm::dvec3, 3>>& tris, int material,
                 const std::vector<double>& uvScale = {}) {
  Mesh m;
  for (size_t i = 0; i < tris.size(); ++i) {
    const auto& p = tris[i];
    const double k = i < uvScale.size() ? uvScale[i] : 1.0;
    MeshTriangle t;
    t.p = p;
    t.material = material;
    t.uv = {k * glm::dvec2(p[0]), k * glm::dvec2(p[1]), k * glm::dvec2(p[2])};
    m.triangles.push_back(t);
  }
  s.meshes.push_back(m);
  Node n;
  n.mesh = int(s.meshes.size()) - 1;
  s.nodes.push_back(n);
  return int(s.nodes.size()) - 1;
}

// A fan of three triangles from (0,0) over a wall at z = 0 (the middle one a sliver; the first
// textured at another scale, so that it does not merge with the sliver into a quad), another
// wall's triangle in the same plane but of another material, one in a parallel plane.
Scene fanScene() {
  Scene s;
  s.materials.resize(2);
  const glm::dvec3 o(0, 0, 0), a(4, 0, 0), b(4, 2, 0), c(3.99, 2, 0), d(0, 2, 0);
  addTriangles(s, {{o, a, b}, {o, b, c}, {o, c, d}}, 0, {2.0, 1.0, 1.0});
  addTriangles(s, {{glm::dvec3(5, 0, 0), glm::dvec3(6, 0, 0), glm::dvec3(5, 1, 0)}}, 1);
  addTriangles(s, {{glm::dvec3(0, 0, 1), glm::dvec3(1, 0, 1), glm::dvec3(0, 1, 1)}}, 0);
  return s;
}

TEST(PlanarSurfaces, CoplanarTopsOfOneNodeAndMaterialAreOneSurface) {
  const std::vector<InputPolygon> tops = fanScene().inputPolygons();
  ASSERT_EQ(tops.size(), 5u) << "no two of the fan's triangles make a convex quad";
  EXPECT_EQ(planarSurfaceOfTops(tops), (std::vector<uint32_t>{0, 0, 0, 3, 4}));
}

// A triangle's (u,v) map starts at the corner opposite its longest edge (scene.cpp
// rootAtWidestCorner): a fan's sliver, written from the fan's apex, starts at a corner of its
// short edge, so its texture's axes run across and along it; the winding is kept.
TEST(InputPolygons, ATrianglesMapStartsOppositeItsLongestEdge) {
  const std::vector<InputPolygon> tops = fanScene().inputPolygons();
  for (const InputPolygon& t : tops) {
    const Polygon& p = t.local;
    const double opposite = glm::length(p.v[2] - p.v[1]);
    EXPECT_GE(opposite, glm::length(p.v[1] - p.v[0]));
    EXPECT_GE(opposite, glm::length(p.v[2] - p.v[0]));
    EXPECT_GT(p.normal().z, 0.0) << "the winding is kept";
    // The glTF texture coordinates went round with the corners.
    const double scale = &t == &tops[0] ? 2.0 : 1.0;
    for (int k = 0; k < 3; ++k) EXPECT_EQ(t.uv[size_t(k)], scale * glm::dvec2(p.v[size_t(k)]));
  }
  // The sliver (o, b, c): v0 at c or b, not at the apex o.
  EXPECT_NE(tops[1].local.v[0], glm::dvec3(0.0));
  // A triangle already rooted there keeps its order.
  EXPECT_EQ(tops[3].local.v[0], glm::dvec3(5, 0, 0));
}

// Two triangles merge into a quad only when it is a parallelogram (to 5 %): a trapezoid's
// bilinear (u,v) map is not the plane homography the shadow masks are rendered with
// (transmittance.h), and a fan's merged trapezoid had its shadows displaced over the whole quad.
TEST(InputPolygons, OnlyParallelogramsMerge) {
  Scene s;
  s.materials.resize(1);
  const glm::dvec3 a(0, 0, 0), b(4, 0, 0), c(4, 2, 0), d(0, 2, 0), e(3, 2, 0);
  addTriangles(s, {{a, b, c}, {a, c, d}}, 0);  // a rectangle
  addTriangles(s, {{a, b, e}, {a, e, d}}, 0);  // a trapezoid
  // A measured rectangle, one corner 3 mm off (the Cornell box's floor).
  addTriangles(s, {{a, b, c + glm::dvec3(0.003, 0, 0)}, {a, c + glm::dvec3(0.003, 0, 0), d}}, 0);
  const std::vector<InputPolygon> tops = s.inputPolygons();
  ASSERT_EQ(tops.size(), 4u);
  EXPECT_EQ(tops[0].local.count, 4);
  EXPECT_EQ(tops[1].local.count, 3);
  EXPECT_EQ(tops[2].local.count, 3);
  EXPECT_EQ(tops[3].local.count, 4);
}

}  // namespace
}  // namespace rad
