// The part of a sample's cell a projected polygon covers. Contract in cell_coverage.h.
#include "libcommon/compose/cell_coverage.h"

#include <algorithm>
#include <cmath>

namespace rad {
namespace {

// At most the polygon's vertices plus one per clip side.
constexpr int kMaxVertices = 16;

// Keeps the part of in[0..n) where sign * (p[axis] - bound) <= 0, into out; returns its count.
int clipSide(const glm::dvec2* in, int n, int axis, double bound, double sign, glm::dvec2* out) {
  int m = 0;
  for (int k = 0; k < n; ++k) {
    const glm::dvec2& a = in[k];
    const glm::dvec2& b = in[(k + 1) % n];
    const double da = sign * (a[axis] - bound), db = sign * (b[axis] - bound);
    if (da <= 0.0) out[m++] = a;
    if ((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) {
      const double t = da / (da - db);
      glm::dvec2 p = a + t * (b - a);
      p[axis] = bound;  // on the side exactly
      out[m++] = p;
    }
  }
  return m;
}

}  // namespace

CellCoverage polygonCellCoverage(const glm::dvec2* poly, int count, glm::dvec2 centre,
                                 double half) {
  CellCoverage c;
  if (count < 3 || count > kMaxVertices - 4 || !(half > 0.0)) return c;
  glm::dvec2 a[kMaxVertices], b[kMaxVertices];
  // Relative to the centre, so the shoelace sums small numbers.
  for (int k = 0; k < count; ++k) a[k] = poly[k] - centre;
  int n = clipSide(a, count, 0, half, 1.0, b);
  n = clipSide(b, n, 0, -half, -1.0, a);
  n = clipSide(a, n, 1, half, 1.0, b);
  n = clipSide(b, n, 1, -half, -1.0, a);
  if (n < 3) return c;
  double area2 = 0.0;  // twice the signed area
  glm::dvec2 moment(0.0);
  for (int k = 0; k < n; ++k) {
    const glm::dvec2& p = a[k];
    const glm::dvec2& q = a[(k + 1) % n];
    const double cross = p.x * q.y - q.x * p.y;
    area2 += cross;
    moment += cross * (p + q);
  }
  if (area2 == 0.0 || !std::isfinite(area2)) return c;
  c.fraction = std::min(1.0, std::abs(area2) / (8.0 * half * half));
  c.centroid = moment / (3.0 * area2);
  return c;
}

}  // namespace rad
