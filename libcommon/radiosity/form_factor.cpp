// Baum, Rushmeier, Winget 1989, "Improving radiosity solutions through the use of analytically
// determined form-factors"; Gauss-Legendre area quadrature as in Cohen & Wallace ch. 4.
// The figures behind the reasons given here: docs/results.md, "Figures moved out of the radiosity
// code's comments (issue 55)".
#include "libcommon/radiosity/form_factor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <queue>

namespace rad {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr std::size_t kStackVertices = 16;

// A vertex list that lives on the stack for the usual small polygons.
class VertexBuffer {
 public:
  explicit VertexBuffer(std::size_t capacity) {
    if (capacity > kStackVertices) heap_.reserve(capacity);
    data_ = capacity > kStackVertices ? nullptr : stack_.data();
  }
  void push(const glm::dvec3& x) {
    if (data_) {
      stack_[size_++] = x;
    } else {
      heap_.push_back(x);
      ++size_;
    }
  }
  const glm::dvec3* data() const { return data_ ? data_ : heap_.data(); }
  std::size_t size() const { return size_; }

 private:
  std::array<glm::dvec3, kStackVertices> stack_;
  std::vector<glm::dvec3> heap_;
  glm::dvec3* data_ = nullptr;
  std::size_t size_ = 0;
};

}  // namespace

// Reduced to |t| <= tan(pi/8) with one division (atan y/x = pi/2 - atan x/y = pi/4 + atan
// (y - x)/(y + x)), then atan t = t g(t^2) with g a degree-10 polynomial fitted to atan(sqrt z) /
// sqrt z on [0, tan^2(pi/8)] at Chebyshev nodes (mpmath.chebyfit, 40 digits: relative error
// 3.5e-17, below half an ulp).
double edgeAngle(double crossLength, double dot) {
  constexpr double kTanPi8 = 0.41421356237309504880, kTan3Pi8 = 2.41421356237309504880;
  constexpr double kCoefficients[] = {1.0,
                                      -0.333333333333284385718,
                                      0.199999999988551101336,
                                      -0.142857141809764668302,
                                      0.111111061804559452198,
                                      -0.0909077307480841378967,
                                      0.0768995349630685775628,
                                      -0.0664023393042940858874,
                                      0.0568834922680901047935,
                                      -0.043480522157164624777,
                                      0.0211353731576932452057};
  const double y = crossLength, ax = std::abs(dot);
  if (!(y > 0.0)) return dot < 0.0 ? kPi : 0.0;  // a, b parallel (or y NaN)
  double t, base;
  if (y <= kTanPi8 * ax) {
    t = y / ax, base = 0.0;
  } else if (y >= kTan3Pi8 * ax) {
    t = -ax / y, base = 0.5 * kPi;
  } else {
    t = (y - ax) / (y + ax), base = 0.25 * kPi;
  }
  const double z = t * t;
  double g = kCoefficients[10];
  for (int i = 9; i >= 0; --i) g = g * z + kCoefficients[i];
  const double a = base + t * g;
  return dot < 0.0 ? kPi - a : a;
}

namespace {

// Contour sum for a polygon entirely in front of the element's tangent plane:
// \frac{1}{2\pi} \sum_k \gamma_k \hat n \cdot \widehat{R_{k+1} \times R_k}.
// R_k \times R_{k+1} is computed as R \times (v_{k+1} - v_k) with R the shorter of R_k, R_{k+1}:
// the same value, with no cancellation when p is far away and R_k, R_{k+1} are nearly parallel, nor
// when p is near one end of a long edge (R_k nearly -(v_{k+1} - v_k): the cross product of two
// 1e10 m vectors leaves noise far above a needle's F, and the adaptive rule chased it to its cell
// bound: issue 18).
double contourSum(const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3* w,
                  std::size_t count) {
  double sum = 0.0;
  for (std::size_t k = 0; k < count; ++k) {
    const glm::dvec3& a = w[k];
    const glm::dvec3& b = w[(k + 1) % count];
    glm::dvec3 rk = a - p;
    glm::dvec3 rk1 = b - p;
    const glm::dvec3& r = glm::dot(rk1, rk1) < glm::dot(rk, rk) ? rk1 : rk;
    glm::dvec3 c = glm::cross(r, b - a);  // = R_k x R_{k+1}
    double cl = glm::length(c);
    if (!(cl > 0.0)) continue;  // p on the edge's line: the term vanishes
    double gamma = edgeAngle(cl, glm::dot(rk, rk1));
    sum -= gamma * glm::dot(n, c) / cl;  // n . (R_{k+1} x R_k) = -n . c
  }
  return sum / (2.0 * kPi);
}

// Gauss-Legendre nodes and weights on [0, 1], orders 1..kMaxQuadratureOrder, built once.
struct GaussRule {
  std::vector<double> x, w;
};

const GaussRule& gaussRule(int n) {
  static const std::vector<GaussRule> rules = [] {
    std::vector<GaussRule> r(kMaxQuadratureOrder + 1);
    for (int order = 1; order <= kMaxQuadratureOrder; ++order) {
      GaussRule& g = r[order];
      g.x.resize(order);
      g.w.resize(order);
      for (int i = 0; i < (order + 1) / 2; ++i) {
        // Newton on P_n from the Chebyshev-like guess; converges to machine precision.
        double z = std::cos(kPi * (i + 0.75) / (order + 0.5));
        double dp = 1.0;
        for (int it = 0; it < 100; ++it) {
          double p0 = 1.0, p1 = 0.0;
          for (int j = 1; j <= order; ++j) {
            double p2 = p1;
            p1 = p0;
            p0 = ((2.0 * j - 1.0) * z * p1 - (j - 1.0) * p2) / j;
          }
          dp = order * (z * p0 - p1) / (z * z - 1.0);
          double dz = p0 / dp;
          z -= dz;
          if (std::abs(dz) < 1e-16) {
            // One more evaluation of the derivative at the converged node.
            p0 = 1.0;
            p1 = 0.0;
            for (int j = 1; j <= order; ++j) {
              double p2 = p1;
              p1 = p0;
              p0 = ((2.0 * j - 1.0) * z * p1 - (j - 1.0) * p2) / j;
            }
            dp = order * (z * p0 - p1) / (z * z - 1.0);
            break;
          }
        }
        double weight = 2.0 / ((1.0 - z * z) * dp * dp);
        // Map [-1, 1] -> [0, 1]; z > 0 here, so node i is near 1 and its mirror near 0.
        g.x[i] = 0.5 * (1.0 - z);
        g.x[order - 1 - i] = 0.5 * (1.0 + z);
        g.w[i] = g.w[order - 1 - i] = 0.5 * weight;
      }
      if (order % 2 == 1) g.x[order / 2] = 0.5;
    }
    return r;
  }();
  return rules[std::clamp(n, 1, kMaxQuadratureOrder)];
}

// An integration cell: bilinear map of four corners, (0,0) (1,0) (1,1) (0,1). A triangle with
// apex a is the collapsed cell (a, b, c, a) (Duffy).
struct Cell {
  std::array<glm::dvec3, 4> q;
  glm::dvec3 at(double u, double v) const {
    return (1.0 - u) * (1.0 - v) * q[0] + u * (1.0 - v) * q[1] + u * v * q[2] +
           (1.0 - u) * v * q[3];
  }
  double jacobian(double u, double v) const {
    glm::dvec3 du = (1.0 - v) * (q[1] - q[0]) + v * (q[2] - q[3]);
    glm::dvec3 dv = (1.0 - u) * (q[3] - q[0]) + u * (q[2] - q[1]);
    return glm::length(glm::cross(du, dv));
  }
  Cell sub(double u0, double u1, double v0, double v1) const {
    return Cell{{at(u0, v0), at(u1, v0), at(u1, v1), at(u0, v1)}};
  }
};

struct Target {
  const glm::dvec3* v;
  std::size_t count;
};

// \int_{cell} F(dA_x -> to) dA_x with an nu x nv tensor Gauss-Legendre rule.
double integrateCell(const Cell& cell, const glm::dvec3& normal, const Target& to, int nu, int nv) {
  const GaussRule& gu = gaussRule(nu);
  const GaussRule& gv = gaussRule(nv);
  double sum = 0.0;
  for (int i = 0; i < nu; ++i) {
    double row = 0.0;
    for (int j = 0; j < nv; ++j) {
      double u = gu.x[i], v = gv.x[j];
      double f = pointToPolygonFormFactor(cell.at(u, v), normal, to.v, to.count);
      row += gv.w[j] * cell.jacobian(u, v) * f;
    }
    sum += gu.w[i] * row;
  }
  return sum;
}

// The cells of the reference's fixed rules: quad -> itself, triangle -> collapsed at v0,
// n-gon -> fan of collapsed triangles from the vertex centroid.
std::vector<Cell> initialCells(const std::vector<glm::dvec3>& v) {
  std::vector<Cell> cells;
  if (v.size() == 3) {
    cells.push_back(Cell{{v[0], v[1], v[2], v[0]}});
  } else if (v.size() == 4) {
    cells.push_back(Cell{{v[0], v[1], v[2], v[3]}});
  } else if (v.size() > 4) {
    glm::dvec3 c(0.0);
    for (const auto& x : v) c += x;
    c /= double(v.size());
    for (std::size_t k = 0; k < v.size(); ++k) {
      cells.push_back(Cell{{c, v[k], v[(k + 1) % v.size()], c}});
    }
  }
  return cells;
}

double diameter(const std::vector<glm::dvec3>& v) {
  double d = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    for (std::size_t j = i + 1; j < v.size(); ++j) d = std::max(d, glm::length(v[i] - v[j]));
  }
  return d;
}

// True if no part of `to` can be seen from `from`: every vertex of `from` is on or behind
// `to`'s plane, or every vertex of `to` is on or behind `from`'s plane, up to a relative
// rounding tolerance (kPlaneTolerance times the diameter). Catches coplanar pairs (including a
// polygon with itself), whose point factors are pure rounding noise.
constexpr double kPlaneTolerance = 1e-12;

bool facesAway(const std::vector<glm::dvec3>& from, const glm::dvec3& fromNormal,
               const std::vector<glm::dvec3>& to, const glm::dvec3& toNormal, double scale) {
  double eps = kPlaneTolerance * scale;
  bool fromInFront = false, toInFront = false;
  for (const auto& x : from) fromInFront |= glm::dot(toNormal, x - to[0]) > eps;
  for (const auto& x : to) toInFront |= glm::dot(fromNormal, x - from[0]) > eps;
  return !fromInFront || !toInFront;
}

// A point whose height over a polygon's plane is at most this fraction of the largest coordinate
// involved is on the plane to rounding, and pointToPolygonFormFactor gives it 0.
constexpr double kHeightRounding = 1e-13;

double largestComponent(const glm::dvec3& x) {
  return std::max({std::abs(x.x), std::abs(x.y), std::abs(x.z)});
}

// The polygon's part of the largest coordinate that the rounding rule sees: its first vertex
// and its extent from it (the point's own coordinates are the rest).
double polygonRoundingScale(const glm::dvec3* v, std::size_t count) {
  double scale = largestComponent(v[0]);
  for (std::size_t k = 1; k < count; ++k) scale = std::max(scale, largestComponent(v[k] - v[0]));
  return scale;
}

// A height over `to`'s plane below which pointToPolygonFormFactor(x, ., to) is 0 for every x of
// `from` (kHeightRounding of a bound on the largest coordinate that rule sees).
double roundingHeight(const std::vector<glm::dvec3>& from, const std::vector<glm::dvec3>& to) {
  double scale = polygonRoundingScale(to.data(), to.size());
  for (const auto& x : from) scale = std::max(scale, largestComponent(x));
  return kHeightRounding * scale;
}

// The part of `from` in front of `to`'s plane (normal `m`): `from` itself when no vertex is behind
// it by more than `eps`, else its part above roundingHeight, made in `clipped`. Points behind
// `to`'s plane see none of its front (pointToPolygonFormFactor is 0 there), and where `from` passes
// through `to` the point factor jumps from 0 to as much as 1/2: inside a cell, that line keeps the
// adaptive rule refining along it to its cell bound (interpenetrating triangles, issue 18) and no
// fixed rule resolves it. Over the front part only, the jump lies on the cells' boundary; the
// integral is the same. The part is cut at the height where the point factor's rounding rule starts
// giving nonzero, not at the plane: a strip between the two (a millimetre wide next to a vertex
// 1e10 m away, issue 18) is a jump inside the cells again.
const std::vector<glm::dvec3>& frontPart(const std::vector<glm::dvec3>& from,
                                         const std::vector<glm::dvec3>& to, const glm::dvec3& m,
                                         double eps, std::vector<glm::dvec3>& clipped) {
  bool behind = false;
  for (const auto& x : from) behind |= glm::dot(m, x - to[0]) < -eps;
  if (!behind) return from;
  clipped.clear();
  clipToFront(from.data(), from.size(), m, to[0], roundingHeight(from, to),
              [&](const glm::dvec3& x) { clipped.push_back(x); });
  if (clipped.size() < 3) clipped.clear();
  return clipped;
}

glm::dvec3 vertexCentroid(const std::vector<glm::dvec3>& v) {
  glm::dvec3 c(0.0);
  for (const auto& x : v) c += x;
  return v.empty() ? c : c / double(v.size());
}

}  // namespace

glm::dvec3 polygonNormal(const glm::dvec3* v, std::size_t count) {
  glm::dvec3 a(0.0);
  for (std::size_t i = 1; i + 1 < count; ++i) a += glm::cross(v[i] - v[0], v[i + 1] - v[0]);
  double len = glm::length(a);
  return len > 0.0 && std::isfinite(len) ? a / len : glm::dvec3(0.0);
}

double polygonArea(const glm::dvec3* v, std::size_t count) {
  glm::dvec3 a(0.0);
  for (std::size_t i = 1; i + 1 < count; ++i) a += glm::cross(v[i] - v[0], v[i + 1] - v[0]);
  return 0.5 * glm::length(a);
}

std::vector<glm::dvec3> polygonVertices(const Polygon& poly) {
  return std::vector<glm::dvec3>(poly.v.begin(), poly.v.begin() + std::clamp(poly.count, 0, 4));
}

double pointToPolygonFormFactor(const glm::dvec3& p, const glm::dvec3& nIn, const glm::dvec3* v,
                                std::size_t count) {
  if (count < 3) return 0.0;
  double nl = glm::length(nIn);
  if (!(nl > 0.0) || !std::isfinite(nl)) return 0.0;
  glm::dvec3 n = nIn / nl;
  glm::dvec3 m = polygonNormal(v, count);
  if (m == glm::dvec3(0.0)) return 0.0;
  // One-sided: only an element strictly in front of the polygon's plane sees its front. A point
  // on the plane to rounding (a vertex on a shared edge, computed by a cut: contact_cuts.h) is
  // not in front; otherwise its form factor is singular at whichever side rounding puts it
  // (the error oracle then refined a ceiling at 1e-3 scale and not at 1).
  // Rounding is relative to the coordinates as well as to the polygon's size (largest
  // component: no square root on this path, which every texel's every link takes).
  const double height = glm::dot(m, p - v[0]);
  if (!(height > 0.0)) return 0.0;
  const double scale = std::max(largestComponent(p), polygonRoundingScale(v, count));
  if (!(height > kHeightRounding * scale)) return 0.0;

  // Horizon clipping to n . (x - p) >= 0 (Sutherland-Hodgman against one plane).
  bool anyIn = false, anyOut = false;
  for (std::size_t k = 0; k < count; ++k) {
    double d = glm::dot(n, v[k] - p);
    anyIn |= d > 0.0;
    anyOut |= d < 0.0;
  }
  if (!anyIn) return 0.0;
  double f;
  if (!anyOut) {
    f = contourSum(p, n, v, count);
  } else {
    VertexBuffer w(count + 2);
    clipToFront(v, count, n, p, 0.0, [&](const glm::dvec3& x) { w.push(x); });
    if (w.size() < 3) return 0.0;
    f = contourSum(p, n, w.data(), w.size());
  }
  if (!(f > 0.0)) return 0.0;  // also maps a NaN from non-finite input to 0
  return std::min(f, 1.0);
}

double pointToPolygonFormFactor(const glm::dvec3& p, const glm::dvec3& n,
                                const std::vector<glm::dvec3>& v) {
  return pointToPolygonFormFactor(p, n, v.data(), v.size());
}

double pointToPolygonFormFactor(const glm::dvec3& p, const glm::dvec3& n, const Polygon& poly) {
  return pointToPolygonFormFactor(p, n, poly.v.data(),
                                  static_cast<std::size_t>(std::clamp(poly.count, 0, 4)));
}

int autoQuadratureOrder(const std::vector<glm::dvec3>& from, const std::vector<glm::dvec3>& to) {
  double s = std::max(diameter(from), diameter(to));
  double d = glm::length(vertexCentroid(from) - vertexCentroid(to));
  if (!(s > 0.0)) return 1;
  double r = d / s;
  if (r >= 20.0) return 2;
  if (r >= 5.0) return 4;
  if (r >= 2.0) return 6;
  if (r >= 1.0) return 8;
  if (r >= 0.5) return 12;
  return 16;
}

int autoQuadratureOrder(const Polygon& from, const Polygon& to) {
  return autoQuadratureOrder(polygonVertices(from), polygonVertices(to));
}

double polygonToPolygonFormFactor(const std::vector<glm::dvec3>& from,
                                  const std::vector<glm::dvec3>& to, int order) {
  if (from.size() < 3 || to.size() < 3) return 0.0;
  double area = polygonArea(from.data(), from.size());
  glm::dvec3 normal = polygonNormal(from.data(), from.size());
  if (!(area > 0.0) || normal == glm::dvec3(0.0)) return 0.0;
  glm::dvec3 toNormal = polygonNormal(to.data(), to.size());
  if (toNormal == glm::dvec3(0.0)) return 0.0;
  const double fromSize = diameter(from);
  if (facesAway(from, normal, to, toNormal, std::max(fromSize, diameter(to)))) return 0.0;
  if (order <= 0) order = autoQuadratureOrder(from, to);
  order = std::clamp(order, 1, kMaxQuadratureOrder);
  Target target{to.data(), to.size()};
  double sum = 0.0;
  std::vector<glm::dvec3> clipped;
  for (const Cell& cell :
       initialCells(frontPart(from, to, toNormal, kPlaneTolerance * fromSize, clipped)))
    sum += integrateCell(cell, normal, target, order, order);
  double f = sum / area;
  return std::isfinite(f) ? std::clamp(f, 0.0, 1.0) : 0.0;
}

double polygonToPolygonFormFactor(const Polygon& from, const Polygon& to, int order) {
  return polygonToPolygonFormFactor(polygonVertices(from), polygonVertices(to), order);
}

AdaptiveFormFactor polygonToPolygonFormFactorAdaptive(const std::vector<glm::dvec3>& from,
                                                      const std::vector<glm::dvec3>& to,
                                                      double relTol, double absTol, int maxCells) {
  AdaptiveFormFactor result;
  if (from.size() < 3 || to.size() < 3) return result;
  double area = polygonArea(from.data(), from.size());
  glm::dvec3 normal = polygonNormal(from.data(), from.size());
  if (!(area > 0.0) || normal == glm::dvec3(0.0)) return result;
  glm::dvec3 toNormal = polygonNormal(to.data(), to.size());
  const double fromSize = diameter(from);
  if (toNormal == glm::dvec3(0.0) ||
      facesAway(from, normal, to, toNormal, std::max(fromSize, diameter(to)))) {
    result.converged = true;
    return result;
  }
  Target target{to.data(), to.size()};
  std::vector<glm::dvec3> clipped;
  const std::vector<glm::dvec3>& front =
      frontPart(from, to, toNormal, kPlaneTolerance * fromSize, clipped);

  constexpr int kHigh = 8, kLow = 5;
  // Absolute error in F below which refining only chases rounding noise.
  constexpr double kAdaptiveNoiseFloor = 1e-18;
  struct Scored {
    Cell cell;
    double value, errU, errV;
    double err() const { return errU + errV; }
    bool operator<(const Scored& o) const { return err() < o.err(); }
  };
  auto score = [&](const Cell& c) {
    double hh = integrateCell(c, normal, target, kHigh, kHigh);
    double lh = integrateCell(c, normal, target, kLow, kHigh);
    double hl = integrateCell(c, normal, target, kHigh, kLow);
    return Scored{c, hh, std::abs(lh - hh), std::abs(hl - hh)};
  };

  // Sums are over \int F dA (not yet divided by the area); tolerances scale accordingly.
  std::priority_queue<Scored> heap;
  double total = 0.0, totalErr = 0.0;
  for (const Cell& c : initialCells(front)) {
    Scored s = score(c);
    total += s.value;
    totalErr += s.err();
    heap.push(s);
  }
  auto done = [&] {
    return totalErr <=
           std::max(std::max(absTol, kAdaptiveNoiseFloor) * area, relTol * std::abs(total));
  };
  int cells = static_cast<int>(heap.size());
  int sinceResum = 0;
  while (!done() && cells < maxCells && !heap.empty()) {
    Scored worst = heap.top();
    heap.pop();
    total -= worst.value;
    totalErr -= worst.err();
    std::array<Cell, 4> children;
    int childCount = 0;
    const Cell& c = worst.cell;
    // Split across the parametric direction(s) that carry the error.
    bool splitU = worst.errU >= 0.25 * worst.errV;
    bool splitV = worst.errV >= 0.25 * worst.errU;
    if (splitU && splitV) {
      children = {c.sub(0, 0.5, 0, 0.5), c.sub(0.5, 1, 0, 0.5), c.sub(0.5, 1, 0.5, 1),
                  c.sub(0, 0.5, 0.5, 1)};
      childCount = 4;
    } else if (splitU) {
      children[0] = c.sub(0, 0.5, 0, 1);
      children[1] = c.sub(0.5, 1, 0, 1);
      childCount = 2;
    } else {
      children[0] = c.sub(0, 1, 0, 0.5);
      children[1] = c.sub(0, 1, 0.5, 1);
      childCount = 2;
    }
    for (int i = 0; i < childCount; ++i) {
      Scored s = score(children[i]);
      total += s.value;
      totalErr += s.err();
      heap.push(s);
    }
    cells += childCount - 1;
    if (++sinceResum == 1024) {
      // Recompute the running sums to stop drift from the repeated add/subtract.
      sinceResum = 0;
      auto copy = heap;
      total = totalErr = 0.0;
      while (!copy.empty()) {
        total += copy.top().value;
        totalErr += copy.top().err();
        copy.pop();
      }
    }
  }
  // Final sum, smallest contributions first.
  std::vector<double> values, errors;
  while (!heap.empty()) {
    values.push_back(heap.top().value);
    errors.push_back(heap.top().err());
    heap.pop();
  }
  std::sort(values.begin(), values.end(),
            [](double a, double b) { return std::abs(a) < std::abs(b); });
  total = totalErr = 0.0;
  for (double x : values) total += x;
  for (double e : errors) totalErr += e;
  result.cells = cells;
  result.converged = done();
  double f = total / area;
  result.value = std::isfinite(f) ? std::clamp(f, 0.0, 1.0) : 0.0;
  result.errorEstimate = totalErr / area;
  return result;
}

AdaptiveFormFactor polygonToPolygonFormFactorAdaptive(const Polygon& from, const Polygon& to,
                                                      double relTol, double absTol, int maxCells) {
  return polygonToPolygonFormFactorAdaptive(polygonVertices(from), polygonVertices(to), relTol,
                                            absTol, maxCells);
}

double formFactorEstimate(const Polygon& from, const Polygon& to) {
  return pointToPolygonFormFactor(from.centroid(), from.normal(), to);
}

double formFactorSpread(const Polygon& from, const Polygon& to, double atCentroid) {
  glm::dvec3 n = from.normal();
  double lo = atCentroid, hi = atCentroid;
  for (int i = 0; i < from.count; ++i) {
    double f = pointToPolygonFormFactor(from.v[size_t(i)], n, to);
    lo = std::min(lo, f);
    hi = std::max(hi, f);
  }
  return hi - lo;
}

double polygonSize(const Polygon& p) {
  double s = 0;
  for (int i = 1; i < p.count; ++i) s = std::max(s, glm::length(p.v[i] - p.v[0]));
  return s;
}

double distanceToPolygon(const glm::dvec3& x, const Polygon& q) {
  const glm::dvec3 n = q.normal();
  const glm::dvec3 onPlane = x - glm::dot(x - q.v[0], n) * n;
  bool inside = true;
  double edge = std::numeric_limits<double>::infinity();
  for (int i = 0; i < q.count; ++i) {
    const glm::dvec3 a = q.v[size_t(i)], b = q.v[size_t((i + 1) % q.count)];
    if (glm::dot(glm::cross(b - a, onPlane - a), n) < 0.0) inside = false;
    const glm::dvec3 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double t = len2 > 0.0 ? glm::clamp(glm::dot(x - a, ab) / len2, 0.0, 1.0) : 0.0;
    edge = std::min(edge, glm::length(x - (a + t * ab)));
  }
  return inside ? std::abs(glm::dot(x - q.v[0], n)) : edge;
}

double areaAverageFormFactor(const Polygon& r, const Polygon& q, double relTol,
                             double adaptiveBelow) {
  const double size = polygonSize(r);
  const double ratio = size > 0.0 ? distanceToPolygon(r.centroid(), q) / size : 0.0;
  if (ratio < adaptiveBelow)
    return polygonToPolygonFormFactorAdaptive(r, q, relTol, kLinkFormFactorAbsTol, 4096).value;
  const int order = ratio >= 20 ? 2 : ratio >= 5 ? 4 : ratio >= 2 ? 6 : ratio >= 1 ? 8 : 12;
  return polygonToPolygonFormFactor(r, q, order);
}

}  // namespace rad
