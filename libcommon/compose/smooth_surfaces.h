// Which top-level patches rad-compose's pixel filter may treat as one smooth surface
// (docs/design.md §6.4 "Smooth surfaces"; footprint_filter.h). The filter's shortcuts (a uniform
// footprint's 3 x 3 kernel of pixel centres, a sample interpolated from the centres around it) hold
// where the radiance is a smooth field over the footprint. Across an edge shared by coplanar
// patches of one untextured material on one rigid body the radiance is continuous (rad-movies'
// texels carry the irradiance to the border to first order, §6.4; issue 56's seams), so such an
// edge is a seam of the mesh, not of the image: the patches are one surface to the filter, and only
// true edges (silhouettes, creases, another material) make a footprint fully sampled. Shading is
// unchanged: each sample is still shaded on its own patch.
#pragma once

#include <cstdint>
#include <vector>

#include "libcommon/scene/geometry.h"

namespace rad {

struct SmoothSurfaces {
  // Per item id (top-level index + 1; 0 the background, which stays 0): its surface, from 1.
  std::vector<uint32_t> surfaceOf;
  // Per surface: 1 where full sampling is required (a textured material: a surface of its own).
  std::vector<char> fullSurface;
};

// The surfaces of the tops placed in the world (`world`, `normals`: count 0 where not seen; those
// tops are a surface each). Two tops are one surface when their materials and objects are the
// same, neither needs full sampling (`fullItem`, per item id) and their planes agree to 1e-5 of
// the scene's extent (the normal and the offset rounded to that step: a pair across a rounding
// boundary stays two surfaces, as before). Deterministic, O(n log n) in the tops.
SmoothSurfaces smoothSurfaces(const std::vector<Polygon>& world,
                              const std::vector<glm::dvec3>& normals,
                              const std::vector<int>& material, const std::vector<size_t>& object,
                              const std::vector<char>& fullItem);

}  // namespace rad
