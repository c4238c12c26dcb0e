// The conforming vertex mesh over the leaves of the union patch hierarchy, on which the
// space-time merge interpolates the good-link irradiance (Gouraud) that rad-movies reads
// (GlobalSolution's leaf vertices). A pure function of the hierarchy and the leaves:
// deterministic, the same whatever the thread count.
#pragma once

#include <array>
#include <vector>

#include "libcommon/scene/patch_hierarchy.h"

namespace rad {

// The union leaves' shared vertices (a conforming Gouraud mesh, so that indirect light has no
// step across a leaf or patch boundary): per leaf and corner, the index of its vertex, and per
// vertex the number of leaf corners at it. A vertex is a distinct exact dyadic top-level (u,v)
// of a top-level patch (a triangle's fourth corner repeats its first), merged with the
// vertices of the other top-level patches of the same mesh node that lie at the same point of
// the same plane (a quad split into two triangles, a floor made of tiles). A vertex inside an
// edge of a larger leaf of its top-level patch (a T-vertex) takes the interpolation along that
// edge (`constraints`, coarse leaves first), so the smaller leaves meet the larger one's edge.
struct LeafVertices {
  std::vector<std::array<int, 4>> leafVertex;
  std::vector<int> vertexCount;
  struct Constraint {
    int vertex, a, b;  // value(vertex) = (1 - t) value(a) + t value(b)
    double t;
  };
  std::vector<Constraint> constraints;
};

// The shared vertices of `leaves` (dense node indices of `h`), in the order given.
LeafVertices leafVerticesOf(const PatchHierarchy& h, const std::vector<int>& leaves);

}  // namespace rad
