// Planar convex polygons (triangles and quads), the unit every patch is made of.
#pragma once

#include <array>
#include <cstddef>
#include <string>

#include <glm/glm.hpp>

namespace rad {

// A planar convex polygon with 3 or 4 vertices, counter-clockwise about its front normal
// (right-hand rule), in metres. Quads come from merging coplanar triangle pairs and are convex.
struct Polygon {
  int count = 0;  // 3 or 4
  std::array<glm::dvec3, 4> v{};

  // Area-weighted normal direction, unit length; zero for a degenerate polygon.
  glm::dvec3 normal() const;
  // Vector area: 0.5 * sum of cross products; its length is the area.
  glm::dvec3 vectorArea() const;
  double area() const;
  glm::dvec3 centroid() const;  // area centroid
  Polygon transformed(const glm::dmat4& m) const;
  std::string toString() const;
};

// Sutherland-Hodgman against one plane: the vertices of v[0..count) at a height of at least
// `lift` over the plane through `at` with normal `n`, and the points where edges cross that
// height, in order, to push(x).
template <class Push>
void clipToFront(const glm::dvec3* v, std::size_t count, const glm::dvec3& n, const glm::dvec3& at,
                 double lift, Push&& push) {
  for (std::size_t k = 0; k < count; ++k) {
    const glm::dvec3& a = v[k];
    const glm::dvec3& b = v[(k + 1) % count];
    const double da = glm::dot(n, a - at) - lift, db = glm::dot(n, b - at) - lift;
    if (da >= 0.0) push(a);
    if ((da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0)) {
      const double t = da / (da - db);  // in (0, 1)
      push(a + t * (b - a));
    }
  }
}

// Area-uniform point on a triangle or convex quad from two numbers in [0, 1) (the quad split
// along v0-v2, the halves chosen by area).
glm::dvec3 pointOnPolygon(const Polygon& p, double u1, double u2);

}  // namespace rad
