// Planar convex polygons (triangles and quads), the unit every patch is made of.
#pragma once

#include <array>
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

}  // namespace rad
