// The part of a sample's cell a projected polygon covers. Contract in cell_coverage.h.
#include "libcommon/compose/cell_coverage.h"

#include <algorithm>
#include <cmath>

namespace rad {
namespace {

// The square clipped by at most kMaxVertices - 4 half-planes.
constexpr int kMaxVertices = 16;

// Twice the signed area of poly[0..count).
double signedArea2(const glm::dvec2* poly, int count) {
  double a = 0.0;
  for (int k = 0; k < count; ++k) {
    const glm::dvec2& p = poly[k];
    const glm::dvec2& q = poly[(k + 1) % count];
    a += p.x * q.y - q.x * p.y;
  }
  return a;
}

}  // namespace

CellCoverage polygonCellCoverage(const glm::dvec2* poly, int count, glm::dvec2 centre,
                                 double half) {
  CellCoverage c;
  if (count < 3 || count > kMaxVertices - 4 || !(half > 0.0)) return c;
  const double orientation = signedArea2(poly, count);
  if (orientation == 0.0 || !std::isfinite(orientation)) return c;
  const double sign = orientation > 0.0 ? 1.0 : -1.0;
  // The cell, relative to its centre, clipped by each edge's inner half-plane in turn (the
  // polygon is convex): a cell inside the polygon is never clipped, one an edge crosses once.
  glm::dvec2 a[kMaxVertices] = {{-half, -half}, {half, -half}, {half, half}, {-half, half}};
  glm::dvec2 b[kMaxVertices];
  double d[kMaxVertices];
  int n = 4;
  bool clipped = false;
  for (int e = 0; e < count; ++e) {
    const glm::dvec2 p = poly[e] - centre, q = poly[(e + 1) % count] - centre, t = q - p;
    bool anyIn = false, anyOut = false;
    for (int k = 0; k < n; ++k) {
      d[k] = sign * (t.x * (a[k].y - p.y) - t.y * (a[k].x - p.x));  // > 0: inside
      anyIn |= d[k] > 0.0;
      anyOut |= d[k] < 0.0;
    }
    if (!anyOut) continue;
    if (!anyIn) return c;
    int m = 0;
    for (int k = 0; k < n && m + 2 <= kMaxVertices; ++k) {
      const int l = (k + 1) % n;
      if (d[k] >= 0.0) b[m++] = a[k];
      if ((d[k] > 0.0 && d[l] < 0.0) || (d[k] < 0.0 && d[l] > 0.0))
        b[m++] = a[k] + d[k] / (d[k] - d[l]) * (a[l] - a[k]);
    }
    std::copy(b, b + m, a);
    n = m;
    clipped = true;
    if (n < 3) return c;
  }
  if (!clipped) {
    c.fraction = 1.0;
    return c;
  }
  double area2 = 0.0;  // twice the signed area (counter-clockwise in these coordinates)
  glm::dvec2 moment(0.0);
  for (int k = 0; k < n; ++k) {
    const glm::dvec2& p = a[k];
    const glm::dvec2& q = a[(k + 1) % n];
    const double cross = p.x * q.y - q.x * p.y;
    area2 += cross;
    moment += cross * (p + q);
  }
  if (!(std::abs(area2) > 0.0) || !std::isfinite(area2)) return c;
  c.fraction = std::min(1.0, std::abs(area2) / (8.0 * half * half));
  c.centroid = moment / (3.0 * area2);
  return c;
}

}  // namespace rad
