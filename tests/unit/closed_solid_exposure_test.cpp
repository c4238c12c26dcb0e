// rad-global's covered test on doubleSided closed solids (issue 57; closed_solid.h): the unit
// room of six touching slabs 0.1 m thick with a 1 cd point lamp at its centre
// (pipelines/scenes/make_lamp_slab_box.py), as Blender exports it (every material doubleSided)
// and one-sided. Before, the doubleSided room had no covered node (a doubleSided polygon is two
// patches back to back, so no ray met the inside of a slab): the leaves at a wall's foot
// averaged their lit part with the part under the wall and shot that diluted radiosity, light
// lost at every bounce (docs/results.md, "Lamps: leaks, fallback pixels, ...", finding 5).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>

#include "formats/gltf_scene.h"
#include "libcommon/radiosity/hierarchical_radiosity.h"
#include "libcommon/radiosity/key_solve_inputs.h"
#include "libcommon/radiosity/lamp_coherence.h"
#include "libcommon/radiosity/scene_visibility.h"
#include "libcommon/scene/closed_solid.h"
#include "libcommon/scene/scene_emitters.h"
#include "tests/unit/key_time_solve_fixture.h"

namespace rad {
namespace {

// The slab room, "double" or "single".
Scene slabRoom(const std::string& sides) {
  return generatedScene("make_lamp_slab_box.py", sides + " {out}");
}

// A key-time solve at time 0 with clusters, visibility and the lamp, as rad-global makes one
// (space_time_radiosity.cpp), reduced to what the test reads.
struct SlabRoomSolve {
  size_t coveredLeaves = 0;  // leaves of exposure < 1
  size_t leaves = 0;
  // B over the exposed area of the leaves that face into the room (the camera's view of it).
  double roomB = 0.0;

  SlabRoomSolve(const Scene& scene, const RadiosityOptions& options) {
    const KeyTimeSolve solve(scene, options);
    const PatchHierarchy& hierarchy = solve.hierarchy;
    const KeySolution& k = solve.solution;
    double sumB = 0.0, sumA = 0.0;
    for (int i = 0; i < hierarchy.size(); ++i) {
      if (!k.inTree(i, hierarchy) || k.split[size_t(i)]) continue;
      ++leaves;
      coveredLeaves += k.exposure[size_t(i)] < 1.0 ? 1 : 0;
      // Facing into the room, within the slabs' outer bounds [-0.1, 1.1]^3: the room's faces,
      // the parts under the walls included (their exposure weighs them out).
      const Polygon& P = k.world[size_t(i)];
      const glm::dvec3 c = P.centroid();
      if (glm::any(glm::lessThanEqual(c, glm::dvec3(-0.1 + 1e-9))) ||
          glm::any(glm::greaterThanEqual(c, glm::dvec3(1.1 - 1e-9))) ||
          glm::dot(P.normal(), glm::dvec3(0.5) - c) <= 0.0)
        continue;
      const double w = k.exposure[size_t(i)] * k.area[size_t(i)];
      sumB += w * k.radiosity[size_t(i)].x;
      sumA += w;
    }
    roomB = sumB / sumA;
  }
};

RadiosityOptions withoutClosedRooms() {
  RadiosityOptions o;
  o.closedRooms = false;
  return o;
}

TEST(ClosedSolid, AWatertightOutwardWoundMeshIsASolidAndNothingElseIs) {
  const Scene scene = slabRoom("double");
  ASSERT_FALSE(scene.meshes.empty());
  std::vector<MeshTriangle> box = scene.meshes[0].triangles;
  EXPECT_TRUE(isClosedSolid(box));
  std::vector<MeshTriangle> inward = box;  // wound inwards: a room modelled from inside
  for (MeshTriangle& t : inward) std::swap(t.p[1], t.p[2]);
  EXPECT_FALSE(isClosedSolid(inward));
  std::vector<MeshTriangle> open(box.begin() + 1, box.end());  // a face's triangle missing
  EXPECT_FALSE(isClosedSolid(open));
  std::vector<MeshTriangle> mixed = box;  // one triangle flipped: not consistently wound
  std::swap(mixed[0].p[1], mixed[0].p[2]);
  EXPECT_FALSE(isClosedSolid(mixed));
}

// The doubleSided room finds the parts under the walls covered, as the one-sided room does, and
// its walls come out as bright as the one-sided room's. Before: no covered leaf, and the room's B
// far below the one-sided room's (the parts under the walls averaged in, light lost at each
// bounce; figures in docs/results.md). The closed-room fill (key_time_closure.cpp) leaves the
// doubleSided room darker than the one-sided one at the defaults; without it the two are closer
// (docs/results.md, issue 57's covered test).
TEST(ClosedSolid, DoubleSidedSlabRoomIsCoveredAndLitAsTheOneSidedRoom) {
  const Scene twoSidedScene = slabRoom("double"), oneSidedScene = slabRoom("single");
  const SlabRoomSolve twoSided(twoSidedScene, RadiosityOptions()),
      oneSided(oneSidedScene, RadiosityOptions());
  const SlabRoomSolve twoSidedOpen(twoSidedScene, withoutClosedRooms()),
      oneSidedOpen(oneSidedScene, withoutClosedRooms());
  // The closed form: the room's power balance, rho 4 pi I / (A (1 - rho)), A = 6 m^2.
  const double closedForm = 0.5 * 4.0 * M_PI / (6.0 * 0.5);
  std::cout << "doubleSided: " << twoSided.coveredLeaves << " of " << twoSided.leaves
            << " leaves covered, room B / closed form " << twoSided.roomB / closedForm
            << " (without closed rooms " << twoSidedOpen.roomB / closedForm
            << "); one-sided: " << oneSided.coveredLeaves << " of " << oneSided.leaves << ", "
            << oneSided.roomB / closedForm << " (" << oneSidedOpen.roomB / closedForm << ")\n";
  EXPECT_GT(oneSided.coveredLeaves, 0u);
  EXPECT_GT(twoSided.coveredLeaves, oneSided.coveredLeaves / 2);
  EXPECT_GT(twoSided.roomB, 0.975 * oneSided.roomB);
  EXPECT_NEAR(twoSidedOpen.roomB / oneSidedOpen.roomB, 1.0, 0.015);
}

}  // namespace
}  // namespace rad
