// The planar surfaces of a scene: the top-level patches of one mesh node and material that lie in
// one plane (a wall's triangles, a floor's tiles). Two of them meet at shared edges where the
// radiance must be continuous (issue 56), so the second pass's estimators that sample something
// per receiver (rad-movies' shooter points for shadows and per-texel visibility) seed their
// samples per surface, not per top: the two sides of a shared edge then take the same points and
// their estimates of one shadow meet without a step.
#pragma once

#include <cstdint>
#include <vector>

#include "libcommon/scene/scene.h"

namespace rad {

// Per top-level patch, the lowest index of the top-level patches of its planar surface: the
// tops of its mesh node, material and side (backFace) whose planes, in the node's local frame,
// agree to 1e-6 in the normal and to 1e-9 of the largest patch's size in the offset (exactly
// coplanar input rounds alike; a plane on a rounding boundary may split in two surfaces, which
// costs only the shared samples). A top alone in its plane is its own surface. Deterministic.
std::vector<uint32_t> planarSurfaceOfTops(const std::vector<InputPolygon>& tops);

}  // namespace rad
