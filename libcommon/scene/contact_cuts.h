// Discontinuity meshing at near contacts: input polygons cut along the outline of a polygon that
// lies flat just in front of them (a lamp 1 mm under a ceiling, a picture's back 1 cm off a
// wall). The D0 discontinuities of Heckbert 1992 / Lischinski, Tampieri, Greenberg 1992,
// for the one case texels cannot resolve: a gap far smaller than a texel.
#pragma once

#include <vector>

namespace rad {

class Scene;
struct InputPolygon;

// A static polygon A parallel to a static polygon B, in front of B with a gap smaller than
// kContactGap times A's size, makes B's radiosity jump along A's outline: under A, B sees almost
// nothing. An element or a movie texel that straddles the outline averages the two sides (the
// bundled scene's lamp, 1 mm under the ceiling: the pixels around it held much of the frame's
// squared error, the gap's ceiling too bright and the ceiling beside the lamp too dark). So B is
// cut into B ∩ A's outline and, per edge k of A, B ∩ outside(edge k) ∩ inside(edge k + 1) (a
// pinwheel: convex pieces that reach B's boundary without slivers along A's edge lines), each piece
// then split into parallelograms and triangles (a quad that is not a parallelogram would take its
// shadow masks at points other than its texels', transmittance.h). B's radiosity falls towards the
// outline over a few gaps on either side, so B is cut the same way along rims kRimGaps gaps wide
// outside and inside the outline too, whose own movies resolve that fall (the outline alone does
// not lower the error). Pieces keep B's node, material, face and uv map; the union of the pieces is
// B. Order and result are deterministic.
inline constexpr double kContactGap = 0.02;
inline constexpr double kRimGaps = 2.0;
std::vector<InputPolygon> cutAtContacts(const Scene& scene, std::vector<InputPolygon> polygons);

}  // namespace rad
