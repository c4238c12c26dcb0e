// Whether a point of a surface lies under a touching solid (a box's foot on the floor, a lamp
// panel against the ceiling), decided by rays as rad-global's exposure decides it
// (exposureOf): a point is inside when the first surfaces its rays meet are the backs of
// one-sided patches. rad-movies uses it twice: the fill of covered texels
// (texture_movie_baker.cpp) and the gather's covered tiles and near-shooter cells
// (good_link_gather.h). Both functions are read-only on `blockers` and may run on several
// threads at once.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "libcommon/radiosity/visibility.h"
#include "libcommon/scene/patch_hierarchy.h"
#include "libcommon/scene/scene.h"

namespace rad {

// Where the ray from point p of top-level patch `top` (direction d, whose length bounds the
// search) starts at time t: inside a touching solid (the first surface it meets is the back
// of a one-sided patch), outside, or undecided (a front and such a back at one distance;
// rayStart). A double-sided material's patch is a back only when its mesh is a closed solid
// with faces out (InputPolygon::closedSolid), as in rad-global's exposure (closed_solid.h).
RayStart coveredBySolid(const VisibilityScene& blockers, const Scene& scene,
                        const PatchHierarchy& h, uint32_t top, const glm::dvec3& p,
                        const glm::dvec3& d, double t);

// Whether point p of top-level patch `top` (unit normal n) lies inside a touching solid at
// time t: the four rays 88 degrees from the normal, `size` long, all start inside or
// undecided (coveredBySolid), one at least inside. Nearly along the surface, so that a gap
// between the solid and the surface lets the rays out; the normal ray is not asked, because
// under an open tube closed by a top it meets the top's underside, a front.
bool insideSolid(const VisibilityScene& blockers, const Scene& scene, const PatchHierarchy& h,
                 uint32_t top, const glm::dvec3& p, const glm::dvec3& n, double size, double t);

}  // namespace rad
