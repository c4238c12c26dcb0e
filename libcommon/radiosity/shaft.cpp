// Shaft culling (Haines & Wallace 1994); see shaft.h.
// The figures behind the reasons given here: docs/results.md, "Figures moved out of the radiosity
// code's comments (issue 55)".
#include "libcommon/radiosity/shaft.h"

#include <algorithm>

namespace rad {

namespace {

// 2D convex hull (Andrew's monotone chain), counter-clockwise, collinear points dropped.
std::vector<glm::dvec2> convexHull2d(std::vector<glm::dvec2> p) {
  std::sort(p.begin(), p.end(), [](const glm::dvec2& a, const glm::dvec2& b) {
    return a.x < b.x || (a.x == b.x && a.y < b.y);
  });
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return p;
  auto cross = [](const glm::dvec2& o, const glm::dvec2& a, const glm::dvec2& b) {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
  };
  std::vector<glm::dvec2> h(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (size_t i = p.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(h[k - 2], h[k - 1], p[i - 1]) <= 0) --k;
    h[k++] = p[i - 1];
  }
  h.resize(k - 1);
  return h;
}

}  // namespace

bool shaftMeetsBox(const Polygon& a, const Polygon& b, const glm::dvec3& lo, const glm::dvec3& hi) {
  // Shaft::meets' first test, on the same exact min/max, before building the shaft's hulls: nearly
  // every link of a coherent key misses the swept boxes here, and so needs no Shaft built.
  glm::dvec3 sLo = a.v[0], sHi = a.v[0];
  for (int i = 0; i < a.count; ++i) sLo = glm::min(sLo, a.v[i]), sHi = glm::max(sHi, a.v[i]);
  for (int i = 0; i < b.count; ++i) sLo = glm::min(sLo, b.v[i]), sHi = glm::max(sHi, b.v[i]);
  for (int k = 0; k < 3; ++k)
    if (hi[k] < sLo[k] || lo[k] > sHi[k]) return false;
  return Shaft(a, b).meets(lo, hi);
}

Shaft::Shaft(const Polygon& a, const Polygon& b) {
  std::vector<glm::dvec3> pts;
  for (int i = 0; i < a.count; ++i) pts.push_back(a.v[i]);
  for (int i = 0; i < b.count; ++i) pts.push_back(b.v[i]);
  lo_ = hi_ = pts[0];
  for (const glm::dvec3& p : pts) lo_ = glm::min(lo_, p), hi_ = glm::max(hi_, p);
  scale_ = glm::length(hi_ - lo_);
  for (int k = 0; k < 3; ++k) {
    int i = (k + 1) % 3, j = (k + 2) % 3;
    std::vector<glm::dvec2> p2;
    for (const glm::dvec3& p : pts) p2.push_back({p[i], p[j]});
    std::vector<glm::dvec2> hull = convexHull2d(p2);
    if (hull.size() < 2) continue;
    for (size_t e = 0; e < hull.size(); ++e) {
      glm::dvec2 p0 = hull[e], p1 = hull[(e + 1) % hull.size()];
      glm::dvec2 d = p1 - p0;
      glm::dvec2 outward(d.y, -d.x);  // right of a CCW edge
      double len = glm::length(outward);
      if (len == 0) continue;
      edges_.push_back({k, p0, outward / len});
    }
  }
}

bool Shaft::meets(const glm::dvec3& lo, const glm::dvec3& hi) const {
  for (int k = 0; k < 3; ++k)
    if (hi[k] < lo_[k] || lo[k] > hi_[k]) return false;
  const double tol = 1e-12 * (scale_ + glm::length(hi - lo));
  for (const Edge& e : edges_) {
    const int i = (e.axis + 1) % 3, j = (e.axis + 2) % 3;
    const glm::dvec2 corners[4] = {{lo[i], lo[j]}, {hi[i], lo[j]}, {hi[i], hi[j]}, {lo[i], hi[j]}};
    bool allOutside = true;
    for (const glm::dvec2& c : corners)
      if (glm::dot(e.out, c - e.p0) <= tol) {
        allOutside = false;
        break;
      }
    if (allOutside) return false;
  }
  return true;
}

}  // namespace rad
