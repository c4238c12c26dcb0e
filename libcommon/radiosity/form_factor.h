// Baum, Rushmeier, Winget 1989, "Improving radiosity solutions through the use of analytically
// determined form-factors" (point-to-polygon contour formula); area quadrature after Cohen &
// Wallace, "Radiosity and Realistic Image Synthesis", ch. 4.
//
// Unoccluded diffuse form factors between planar polygons. Conventions (tests/data/reference):
//  * Every polygon lists its vertices counter-clockwise about its front normal.
//  * Polygons are one-sided: an emitter leaves (and a receiver accepts) energy through its
//    front only. F is 0 when the receiving element lies on or behind the polygon's plane, and
//    only the part of the polygon in front of the element's tangent plane counts (horizon
//    clipping). F is therefore always in [0, 1] and never NaN for finite input.
#pragma once

#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/scene/geometry.h"

namespace rad {

// F(dA -> P): fraction of the energy leaving the differential element at `p` with unit normal
// `n` that arrives at the polygon P (exact Lambert / Nusselt contour formula):
//
//   F = \frac{1}{2\pi} \sum_k \gamma_k \, \hat n \cdot \frac{R_{k+1} \times R_k}{|R_{k+1} \times
//   R_k|}, \gamma_k = \operatorname{atan2}(|R_k \times R_{k+1}|, R_k \cdot R_{k+1}),  R_k = v_k -
//   p,
//
// evaluated after clipping P to the half-space n \cdot (x - p) \ge 0. Returns 0 if p is on or
// behind P's plane (one-sided polygon), if nothing of P is in front of the element, or if P or
// n is degenerate. The result is clamped to [0, 1] (rounding only).
double pointToPolygonFormFactor(const glm::dvec3& p, const glm::dvec3& n, const Polygon& poly);
// Same for a planar convex n-gon (any vertex count >= 3; e.g. the reference 64-gons).
double pointToPolygonFormFactor(const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3* v,
                                std::size_t count);
double pointToPolygonFormFactor(const glm::dvec3& p, const glm::dvec3& n,
                                const std::vector<glm::dvec3>& v);
// The angle in [0, pi] between two vectors a, b from |a x b| (`crossLength`, >= 0) and a . b
// (`dot`): atan2(crossLength, dot) within 4 eps relative for finite input (1.96 eps measured
// over 10^6 angles), the contour formula's gamma_k. glibc's correctly rounded atan2 is a large
// share of rad-global's and rad-movies' time; this is one division and a polynomial.
double edgeAngle(double crossLength, double dot);

// Order used by polygonToPolygonFormFactor when it is given order <= 0 (kAutoOrder).
constexpr int kAutoOrder = 0;
constexpr int kMaxQuadratureOrder = 64;

// F(from -> to) = \frac{1}{A_{from}} \int_{from} F(dA_x \to to) \, dA_x, by a fixed Gauss-Legendre
// rule on `from` with the exact point-to-polygon formula at every node:
//  * quad: order x order tensor rule on the bilinear map of the quad;
//  * triangle: collapsed (Duffy) order x order rule with its apex at the first vertex;
//  * n-gon (> 4 vertices): fan of triangles from the vertex centroid, collapsed rule on each
//    with its apex at the centre.
// These are exactly the rules of the reference's Gauss-Legendre error table, so the error for
// a given order can be read there. order <= 0 picks autoQuadratureOrder(from, to). Orders are
// clamped to [1, kMaxQuadratureOrder]. No sample ever lies on the boundary of `from`.
double polygonToPolygonFormFactor(const Polygon& from, const Polygon& to, int order);
double polygonToPolygonFormFactor(const std::vector<glm::dvec3>& from,
                                  const std::vector<glm::dvec3>& to, int order);

// Order for a relative error of about 1e-6 or better away from contact, from the ratio
// r = d / s, where d is the distance between the centroids and s the larger diameter:
//   r >= 20: 2, r >= 5: 4, r >= 2: 6, r >= 1: 8, r >= 0.5: 12, else 16.
// Near contact (r small: touching or nearly touching patches) no fixed order is accurate (see
// the reference's table: 16x16 is still off by 2e-4 at d/s = 0.01, and edge-sharing thin
// patches converge only algebraically); the hierarchical solver must subdivide there, or use
// polygonToPolygonFormFactorAdaptive.
int autoQuadratureOrder(const std::vector<glm::dvec3>& from, const std::vector<glm::dvec3>& to);
int autoQuadratureOrder(const Polygon& from, const Polygon& to);

struct AdaptiveFormFactor {
  double value = 0.0;          // F(from -> to)
  double errorEstimate = 0.0;  // estimated absolute error of value
  int cells = 0;               // number of integration cells used
  bool converged = false;      // errorEstimate <= max(absTol, relTol * value)
};

// F(from -> to) by globally adaptive, anisotropic cell subdivision of `from` (each cell a
// bilinear quad, triangles as collapsed quads). Every cell is integrated with 8x8, 5x8 and 8x5
// Gauss-Legendre rules; the differences give an error estimate per parametric direction and
// the cell with the largest error is split across the direction(s) that carry it. This copes
// with the log-singular derivative of F(dA_x -> to) along a shared edge (refining only across
// the edge) and with near contact, and reaches ~1e-13 relative on every reference case.
// Stops when errorEstimate <= max(absTol, 1e-18, relTol * value) or after maxCells cells.
// Pairs that cannot see each other (every vertex of one on or behind the other's plane, to a
// relative 1e-12 of their size; e.g. coplanar patches) return exactly 0 without quadrature;
// polygonToPolygonFormFactor does the same.
AdaptiveFormFactor polygonToPolygonFormFactorAdaptive(const std::vector<glm::dvec3>& from,
                                                      const std::vector<glm::dvec3>& to,
                                                      double relTol = 1e-12, double absTol = 0.0,
                                                      int maxCells = 200000);
AdaptiveFormFactor polygonToPolygonFormFactorAdaptive(const Polygon& from, const Polygon& to,
                                                      double relTol = 1e-12, double absTol = 0.0,
                                                      int maxCells = 200000);

// The absolute error in F that the link form factors (areaAverageFormFactor, rad-global's
// linkFormFactor) are computed to besides their relative tolerance. Below it a link carries
// less than 1e-8 of its shooter's radiosity, far beneath any eps the refinement uses; without
// it, slivers kilometres long seen edge-on (a mutated vertex, issue 18) took the adaptive rule
// to its 4096 cells for each link, chasing 1e-5 of an F of 5e-9.
constexpr double kLinkFormFactorAbsTol = 1e-8;

// F(r -> q) as an area average over r to about relTol, at the cost the pair needs: F(x -> q) is
// smooth over r on the scale of x's distance to q (its plane and its contour), so a fixed
// Gauss rule on r is accurate once that distance is large against r's size, and the adaptive
// rule takes over below adaptiveBelow times it (contact, shared edges). rad-global's closure
// and rad-movies' good-link gather use it, so both see the same F; rad-global's link form factor
// (linkFormFactor) too, adaptive up to a ratio of 1.
double areaAverageFormFactor(const Polygon& r, const Polygon& q, double relTol,
                             double adaptiveBelow = 0.25);

// Size of a polygon (largest vertex distance from the first vertex), for relative tolerances.
double polygonSize(const Polygon& p);
// Distance from point x to the convex planar polygon q (its nearest point).
double distanceToPolygon(const glm::dvec3& x, const Polygon& q);

// Cheap unoccluded estimate for refinement oracles: the exact point-to-polygon factor from the
// centroid of `from` (one Lambert evaluation, the n = 1 column of the reference table). Exact
// in the far field to O((s/d)^2); near contact it may be off by O(1), so an oracle should also
// look at d/s (see autoQuadratureOrder).
double formFactorEstimate(const Polygon& from, const Polygon& to);

// How much the point form factor F(dA -> to) varies over `from`: max - min over its vertices
// and centroid. A link that gathers the shooter's mean radiosity through the mean form factor
// errs by at most (spread over the receiver) x B x A_receiver on the receiving side and
// (spread over the shooter) x (B variation) x A_shooter on the shooting side: the error
// oracle of hierarchical radiosity (Lischinski, Tampieri, Greenberg 1993; Holzschuch and
// Sillion 1998 bound the same quantity). Large near contact, ~0 in the far field.
// `atCentroid` is formFactorEstimate(from, to), which the caller has already computed.
double formFactorSpread(const Polygon& from, const Polygon& to, double atCentroid);

// Helpers shared with the tests.
std::vector<glm::dvec3> polygonVertices(const Polygon& poly);
// Newell normal (unit; zero for a degenerate polygon) and area of a planar polygon.
glm::dvec3 polygonNormal(const glm::dvec3* v, std::size_t count);
double polygonArea(const glm::dvec3* v, std::size_t count);

}  // namespace rad
