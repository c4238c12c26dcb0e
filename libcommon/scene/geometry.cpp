#include "libcommon/scene/geometry.h"

#include <sstream>

namespace rad {

glm::dvec3 Polygon::vectorArea() const {
  glm::dvec3 a(0.0);
  for (int i = 1; i + 1 < count; ++i) a += glm::cross(v[i] - v[0], v[i + 1] - v[0]);
  return 0.5 * a;
}

glm::dvec3 Polygon::normal() const {
  glm::dvec3 a = vectorArea();
  double len = glm::length(a);
  return len > 0.0 ? a / len : glm::dvec3(0.0);
}

double Polygon::area() const {
  return glm::length(vectorArea());
}

glm::dvec3 Polygon::centroid() const {
  // Fan triangulation from v0; each triangle's centroid weighted by its (signed) area.
  glm::dvec3 n = normal();
  glm::dvec3 c(0.0);
  double total = 0.0;
  for (int i = 1; i + 1 < count; ++i) {
    double a = 0.5 * glm::dot(glm::cross(v[i] - v[0], v[i + 1] - v[0]), n);
    c += a * (v[0] + v[i] + v[i + 1]) / 3.0;
    total += a;
  }
  if (total <= 0.0) {
    glm::dvec3 s(0.0);
    for (int i = 0; i < count; ++i) s += v[i];
    return count > 0 ? s / double(count) : s;
  }
  return c / total;
}

Polygon Polygon::transformed(const glm::dmat4& m) const {
  Polygon p = *this;
  for (int i = 0; i < count; ++i) p.v[i] = glm::dvec3(m * glm::dvec4(v[i], 1.0));
  return p;
}

std::string Polygon::toString() const {
  std::ostringstream os;
  os.precision(17);
  os << "[";
  for (int i = 0; i < count; ++i) {
    os << (i ? ", " : "") << "(" << v[i].x << ", " << v[i].y << ", " << v[i].z << ")";
  }
  os << "]";
  return os.str();
}

}  // namespace rad
