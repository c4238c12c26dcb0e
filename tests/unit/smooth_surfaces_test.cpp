// Coplanar patches of one untextured material on one object are one surface to rad-compose's pixel
// filter (libcommon/compose/smooth_surfaces.h): a fan-triangulated wall is one surface; another
// material, another object, another plane, a textured material or an unseen top is not.
#include <vector>

#include <gtest/gtest.h>

#include "libcommon/compose/smooth_surfaces.h"

namespace rad {
namespace {

Polygon triangle(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  Polygon p;
  p.count = 3;
  p.v[0] = a;
  p.v[1] = b;
  p.v[2] = c;
  return p;
}

TEST(SmoothSurfaces, CoplanarPatchesOfOneMaterialAndObjectAreOneSurface) {
  // A wall at z = -5 fanned from (0, 0) (slivers of very different sizes), then the same
  // triangles with another material, on another object, tilted, textured and unseen.
  const glm::dvec3 o(0, 0, -5);
  std::vector<Polygon> world = {
      triangle(o, {4, 0, -5}, {4, 0.01, -5}),   triangle(o, {4, 0.01, -5}, {-3, 3, -5}),
      triangle(o, {-3, 3, -5}, {-3, -1e3, -5}), triangle(o, {4, 0, -5}, {4, 0.01, -5}),
      triangle(o, {4, 0, -5}, {4, 0.01, -5}),   triangle(o, {4, 0, -5.001}, {4, 0.01, -5}),
      triangle(o, {4, 0, -5}, {4, 0.01, -5}),   Polygon{}};
  std::vector<glm::dvec3> normals;
  for (const Polygon& p : world) normals.push_back(p.count ? p.normal() : glm::dvec3(0.0));
  const std::vector<int> material = {0, 0, 0, 1, 0, 0, 0, 0};
  const std::vector<size_t> object = {0, 0, 0, 0, 1, 0, 0, 0};
  std::vector<char> fullItem(world.size() + 1, 0);
  fullItem[7] = 1;  // item 7 = top 6: textured
  const SmoothSurfaces s = smoothSurfaces(world, normals, material, object, fullItem);
  ASSERT_EQ(s.surfaceOf.size(), world.size() + 1);
  EXPECT_EQ(s.surfaceOf[0], 0u);  // the background
  EXPECT_EQ(s.surfaceOf[1], s.surfaceOf[2]);
  EXPECT_EQ(s.surfaceOf[1], s.surfaceOf[3]);
  for (size_t item = 4; item <= world.size(); ++item)
    for (size_t other = 1; other < item; ++other)
      EXPECT_NE(s.surfaceOf[item], s.surfaceOf[other]) << item << " " << other;
  EXPECT_EQ(s.fullSurface[s.surfaceOf[1]], 0);
  EXPECT_EQ(s.fullSurface[s.surfaceOf[7]], 1);
  EXPECT_EQ(s.fullSurface[s.surfaceOf[8]], 0);
}

}  // namespace
}  // namespace rad
