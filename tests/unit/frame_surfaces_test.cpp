// libcommon/reference/frame_surfaces: item ids to top-level patches, and which patches are one
// surface (coplanar, one material), placed at the item buffer's time.
#include "libcommon/reference/frame_surfaces.h"

#include <cmath>

#include <gtest/gtest.h>

#include "libcommon/core/error.h"
#include "libcommon/scene/scene.h"

namespace rad {
namespace {

// A unit quad in the z = 0 plane at x offset `x0`, facing +z, tilted by `tiltDegrees` about the
// line through its centre along x (so its centroid stays in the plane) and lifted by `lift`.
Mesh quadMesh(double x0, int material, double tiltDegrees = 0.0, double lift = 0.0) {
  const double t = tiltDegrees * M_PI / 180.0;
  auto at = [&](double x, double y) {
    return glm::dvec3(x0 + x, 0.5 + (y - 0.5) * std::cos(t), lift + (y - 0.5) * std::sin(t));
  };
  Mesh m;
  m.triangles.resize(2);
  m.triangles[0].p = {at(0, 0), at(1, 0), at(1, 1)};
  m.triangles[1].p = {at(0, 0), at(1, 1), at(0, 1)};
  for (MeshTriangle& tr : m.triangles) tr.material = material;
  return m;
}

// Node k carries meshes[k]; node 1 moves from z = 0.5 at t = 0 to z = 0 at t = 1 when `moving`.
Scene quads(std::vector<Mesh> meshes, bool moving = false) {
  Scene s;
  s.path = "test";
  s.materials = {Material(), Material()};
  s.meshes = std::move(meshes);
  s.nodes.resize(s.meshes.size());
  for (size_t k = 0; k < s.nodes.size(); ++k) s.nodes[k].mesh = int(k);
  if (moving) {
    AnimationChannel ch;
    ch.node = 1;
    ch.path = AnimationPath::kTranslation;
    ch.interpolation = Interpolation::kLinear;
    ch.times = {0.0, 1.0};
    ch.values = {0, 0, 0.5, 0, 0, 0};
    s.channels.push_back(ch);
  }
  return s;
}

// Two 1 x 1 item buffers' worth of pixels: one pixel per top-level patch.
ItemBuffer itemsOf(const std::vector<uint32_t>& ids) {
  ItemBuffer b;
  b.width = int(ids.size());
  b.height = 1;
  b.id = ids;
  b.depth.assign(ids.size(), 1.0f);
  return b;
}

TEST(FrameSurfaces, ItemIdsMapToTheirTopLevelPatch) {
  // T = 3: ids 1..3 are the tops, 4..15 their children (4 each), 16.. the grandchildren.
  EXPECT_EQ(topPatchOfItem(kNoItem, 3), -1);
  EXPECT_EQ(topPatchOfItem(1, 3), 0);
  EXPECT_EQ(topPatchOfItem(3, 3), 2);
  EXPECT_EQ(topPatchOfItem(4, 3), 0);   // node 3: first child of top 0
  EXPECT_EQ(topPatchOfItem(8, 3), 1);   // node 7: first child of top 1
  EXPECT_EQ(topPatchOfItem(15, 3), 2);  // node 14: last child of top 2
  EXPECT_EQ(topPatchOfItem(16, 3), 0);  // node 15: first grandchild, of node 3
  EXPECT_EQ(topPatchOfItem(63, 3), 2);  // node 62: last grandchild, of node 14
}

TEST(FrameSurfaces, CoplanarPatchesOfOneMaterialAreOneSurface) {
  const Scene s = quads({quadMesh(0, 0), quadMesh(1, 0), quadMesh(2, 1), quadMesh(3, 0, 2.0),
                         quadMesh(4, 0, 0.0, 0.01), quadMesh(5, 0, 0.5)});
  const std::vector<InputPolygon> tops = s.inputPolygons();
  ASSERT_EQ(tops.size(), 6u);  // each quad's two triangles merged
  const FrameSurfaces f = frameSurfaces(itemsOf({1, 2, 0, 6}), s, tops, 0.0, 4, 1, "items.exr");
  EXPECT_EQ(f.patchAt(0, 0), 0);
  EXPECT_EQ(f.patchAt(2, 0), -1);
  EXPECT_EQ(f.patchAt(3, 0), 5);
  EXPECT_TRUE(f.sameSurface(0, 0));
  EXPECT_TRUE(f.sameSurface(0, 1));   // side by side in one plane
  EXPECT_FALSE(f.sameSurface(1, 2));  // another material
  EXPECT_FALSE(f.sameSurface(1, 3));  // tilted by 2 degrees
  EXPECT_FALSE(f.sameSurface(0, 4));  // parallel, 1 cm off
  EXPECT_TRUE(f.sameSurface(0, 5));   // tilted by 0.5 degree: within kCoplanarDegrees
  EXPECT_FALSE(f.emits(0));
  EXPECT_EQ(f.nameOf(2), "node 2 (material 1)");
  EXPECT_THROW(frameSurfaces(itemsOf({1, 2}), s, tops, 0.0, 4, 1, "items.exr"), Error);
}

TEST(FrameSurfaces, MovingPatchesArePlacedAtTheItemBuffersTime) {
  const Scene s = quads({quadMesh(0, 0), quadMesh(1, 0)}, true);
  const std::vector<InputPolygon> tops = s.inputPolygons();
  EXPECT_FALSE(frameSurfaces(itemsOf({1, 2}), s, tops, 0.0, 2, 1, "i").sameSurface(0, 1));
  EXPECT_FALSE(frameSurfaces(itemsOf({1, 2}), s, tops, 0.5, 2, 1, "i").sameSurface(0, 1));
  EXPECT_TRUE(frameSurfaces(itemsOf({1, 2}), s, tops, 1.0, 2, 1, "i").sameSurface(0, 1));
}

}  // namespace
}  // namespace rad
