// The pieces of a contact cut (contact_cuts.h) are parallelograms and triangles: a quad's shadow
// masks are rendered by the plane homography of its corners (transmittance.h), which places a
// texel where its bilinear (u,v) map does only for a parallelogram.
#include <gtest/gtest.h>

#include <algorithm>

#include "libcommon/movies/transmittance.h"
#include "libcommon/scene/patch_hierarchy.h"
#include "libcommon/scene/scene.h"

namespace rad {
namespace {

// A right triangle (node 0, 1 m legs, uv = local x, y) with a 20 cm square (node 1, facing the
// same way) 1 mm in front of it across its long edge: the cut lines cross the long edge at a
// slant, so the pinwheel's convex pieces there are trapezoids and pentagons (the bathroom
// countertop's triangles under the backsplash).
Scene squareAcrossATrianglesLongEdge() {
  Scene s;
  s.nodes.resize(2);
  s.roots = {0, 1};
  s.nodes[0].mesh = 0;
  s.nodes[1].mesh = 1;
  s.nodes[1].scale = {0.2, 0.2, 1};
  s.nodes[1].translation = {0.35, 0.35, 0.001};
  Mesh triangle, square;
  MeshTriangle t;
  t.p = {glm::dvec3(0, 0, 0), glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0)};
  t.uv = {glm::dvec2(0, 0), glm::dvec2(1, 0), glm::dvec2(0, 1)};
  triangle.triangles = {t};
  MeshTriangle a, b;
  a.p = {glm::dvec3(0, 0, 0), glm::dvec3(1, 0, 0), glm::dvec3(1, 1, 0)};
  b.p = {glm::dvec3(0, 0, 0), glm::dvec3(1, 1, 0), glm::dvec3(0, 1, 0)};
  square.triangles = {a, b};
  s.meshes = {triangle, square};
  return s;
}

double longestEdge(const Polygon& p) {
  double longest = 0.0;
  for (int k = 0; k < p.count; ++k)
    longest = std::max(longest, glm::length(p.v[size_t((k + 1) % p.count)] - p.v[size_t(k)]));
  return longest;
}

TEST(ContactCutPieces, QuadsAreParallelogramsSoTheirMasksFallOnTheirTexels) {
  const std::vector<InputPolygon> polys = squareAcrossATrianglesLongEdge().inputPolygons();
  double area = 0.0;
  int pieces = 0, quads = 0;
  for (const InputPolygon& p : polys) {
    if (p.node != 0) continue;
    ++pieces;
    area += p.local.area();
    const double size = longestEdge(p.local);
    // The uv map is the triangle's own (uv = local x, y).
    for (int k = 0; k < p.local.count; ++k) {
      EXPECT_NEAR(p.uv[size_t(k)].x, p.local.v[size_t(k)].x, 1e-12);
      EXPECT_NEAR(p.uv[size_t(k)].y, p.local.v[size_t(k)].y, 1e-12);
    }
    if (p.local.count == 3) {
      // Rooted at its widest corner (docs/design.md §4): v1-v2 is the longest edge.
      EXPECT_NEAR(glm::length(p.local.v[2] - p.local.v[1]), size, 1e-12) << p.local.toString();
      continue;
    }
    ++quads;
    // Where the shadow masks put texel (u,v) is where the texel is, but for the second-order
    // displacement of a quad within the 5 % rule (a rim 2 mm wide with a slanted end).
    const ReceiverTextureMap map(p.local);
    double worst = 0.0;
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < 8; ++i) {
        const glm::dvec2 uv((i + 0.5) / 8.0, (j + 0.5) / 8.0);
        worst = std::max(worst, glm::length(map.planePoint(uv) - polygonPointAt(p.local, uv)));
      }
    EXPECT_LT(worst, 1e-3 * size) << p.local.toString();
  }
  EXPECT_GT(pieces, 10);  // cut along the outline and both rims
  EXPECT_GT(quads, 0);
  EXPECT_NEAR(area, 0.5, 1e-12);
}

}  // namespace
}  // namespace rad
