// rad-movies' contact test on doubleSided closed solids (solid_contact.h, closed_solid.h): the
// unit room of six touching slabs 0.1 m thick (pipelines/scenes/make_lamp_slab_box.py), as
// Blender exports it (every material doubleSided) and one-sided. The floor slab runs under the
// walls, so a floor point under a wall slab is inside that solid. rad-global's exposure has said
// so for closed doubleSided solids since issue 57; rad-movies' fill of covered texels and the
// gather's covered tiles used the old rule, by which a doubleSided patch is never a back, and
// found no point covered.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "libcommon/movies/solid_contact.h"
#include "libcommon/radiosity/scene_visibility.h"
#include "tests/unit/key_time_solve_fixture.h"

namespace rad {
namespace {

// The top patch of the floor slab's upper face (world normal +y at y = 0), front copy.
uint32_t floorTop(const Scene& scene, const PatchHierarchy& h) {
  for (int t = 0; t < h.topCount(); ++t) {
    const InputPolygon& p = h.top(t);
    const Polygon w = p.local.transformed(scene.worldTransform(p.node, 0.0));
    if (!p.backFace && w.normal().y > 0.999 && std::abs(w.centroid().y) < 1e-9) return uint32_t(t);
  }
  ADD_FAILURE() << "no floor top";
  return 0;
}

struct SlabRoomContact {
  Scene scene;
  PatchHierarchy h;
  SceneVisibility visibility;
  uint32_t floor;
  explicit SlabRoomContact(const std::string& sides)
      : scene(generatedScene("make_lamp_slab_box.py", sides + " {out}")),
        h(scene.inputPolygons()),
        visibility(scene, h, 0.0, 0.0),
        floor(floorTop(scene, h)) {}
  bool inside(const glm::dvec3& p) const {
    return insideSolid(visibility.visibility(), scene, h, floor, p, glm::dvec3(0, 1, 0), 1.0, 0.0);
  }
};

TEST(SolidContact, AFloorPointUnderAWallSlabIsInsideWhateverTheMaterialsSides) {
  for (const std::string sides : {"single", "double"}) {
    const SlabRoomContact room(sides);
    for (const InputPolygon& p : room.h.tops())
      EXPECT_TRUE(p.closedSolid) << sides << ": every slab is a closed solid with faces out";
    EXPECT_TRUE(room.inside(glm::dvec3(-0.05, 0.0, 0.5))) << sides << ": under the left wall";
    EXPECT_TRUE(room.inside(glm::dvec3(0.5, 0.0, 1.05))) << sides << ": under the far wall";
    EXPECT_FALSE(room.inside(glm::dvec3(0.5, 0.0, 0.5))) << sides << ": the room's floor";
    EXPECT_FALSE(room.inside(glm::dvec3(0.02, 0.0, 0.5))) << sides << ": beside the wall";
  }
}

}  // namespace
}  // namespace rad
