// Closed solids: meshes whose winding tells their inside from their outside (issue 57).
//
// rad-global's exposure (key_time_exposure.cpp) calls a ray start point covered when its short
// ray first meets the inside of a solid. A one-sided polygon's back is that inside. A doubleSided
// polygon is two patches back to back (docs/design.md §4), so it has no back, and Blender's glTF
// exporter makes every material doubleSided: the floor under a wall standing on it was never found
// covered (docs/results.md, "Lamps: leaks, fallback pixels, ..."). A mesh that is watertight and
// wound consistently with its faces out still bounds a volume whatever its material says, and its
// winding gives the outside: a ray that meets one of its faces from behind that face's geometric
// normal starts inside it. Open meshes (a plane, a leaf) and closed ones wound inwards (a room
// modelled from inside, or an object whose normals were flipped, which a doubleSided material
// hides in Blender) are not solids here.
#pragma once

#include <vector>

#include "libcommon/scene/scene.h"

namespace rad {

// Whether the triangles bound a solid with their faces out: every edge, by exact vertex
// positions, is used once in each direction (watertight and consistently wound, so no edge is
// shared by more than two triangles), and the enclosed signed volume is positive (the
// counter-clockwise fronts face out). Deterministic; O(n log n) in the triangles.
bool isClosedSolid(const std::vector<MeshTriangle>& triangles);

}  // namespace rad
