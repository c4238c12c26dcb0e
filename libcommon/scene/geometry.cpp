#include "libcommon/scene/geometry.h"
#include <algorithm>

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

glm::dvec3 pointOnPolygon(const Polygon& p, double u1, double u2) {
  auto onTriangle = [](const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, double u,
                       double v) {
    const double su = std::sqrt(u);
    return (1.0 - su) * a + su * (1.0 - v) * b + su * v * c;
  };
  if (p.count == 3) return onTriangle(p.v[0], p.v[1], p.v[2], u1, u2);
  const double a0 = glm::length(glm::cross(p.v[1] - p.v[0], p.v[2] - p.v[0]));
  const double a1 = glm::length(glm::cross(p.v[2] - p.v[0], p.v[3] - p.v[0]));
  const double w = a0 + a1 > 0.0 ? a0 / (a0 + a1) : 0.5;
  if (u1 < w) return onTriangle(p.v[0], p.v[1], p.v[2], u1 / w, u2);
  return onTriangle(p.v[0], p.v[2], p.v[3], std::min((u1 - w) / (1.0 - w), 1.0), u2);
}

}  // namespace rad
