// The texels of a triangle's texture that lie beyond the triangle (docs/design.md §6.3).
//
// A triangle's texture covers its (u,v) square, of which the triangle is the half u + v <= 1.
// The texels whose centres lie on the long edge u + v = 1 or beyond it are not points of the
// patch, yet a pixel inside next to that edge reads them in its bilinear cell. Their own gathers
// are wrong there: points on the edge are half shadowed by whatever touches it, points beyond it
// may lie inside the neighbouring geometry. Filled with the mean of their neighbours inside (the
// solids' fill), they held the value a texel inside, so the pixels along the edge interpolated a
// flat continuation and the irradiance stepped by its gradient times a texel where the triangle
// met its coplanar neighbour (issue 56's seams). They are now the linear continuation of the
// texels inside, which a smooth irradiance continues to first order.
#pragma once

#include <vector>

namespace rad {

// Whether texel (i, j) of a w x h texture of a triangle lies on or beyond the triangle's long
// edge: its centre ((i + .5) / w, (j + .5) / h) has u + v >= 1 (to rounding).
bool texelBeyondTriangle(int i, int j, int w, int h);

// Rewrites every texel beyond the triangle (texelBeyondTriangle) of an RGB float texture
// (w * h * 3, row j at offset j * w * 3) with the linear continuation of the texels before it, in
// order of u + v: the plane through its left, lower and lower-left neighbours, v(i-1, j) +
// v(i, j-1) - v(i-1, j-1), where they exist; else the line through the two before it in its
// column or row; else the one before it. Values are kept non-negative (irradiance). Texels inside
// are not changed. Deterministic; linear in w h.
void extendBeyondTriangle(std::vector<float>& rgb, int w, int h);

}  // namespace rad
