// Emissive polygons as emitters (contract in emissive_polygon_emitter.h). The irradiance is
// Lambert's contour formula (Lambert 1760; Baum, Rushmeier, Winget 1989, "Improving radiosity
// solutions through the use of analytically determined form-factors").
#include "libcommon/scene/emissive_polygon_emitter.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

namespace rad {

namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

PlacedEmissivePolygon::PlacedEmissivePolygon(const Polygon& world, const glm::dvec3& radiance)
    : world_(world), normal_(world.normal()), radiance_(radiance), area_(world.area()) {}

glm::dvec3 PlacedEmissivePolygon::power() const {
  return kPi * radiance_ * area_;
}

double PlacedEmissivePolygon::samplingWeight() const {
  return area_ * (radiance_.x + radiance_.y + radiance_.z);
}

glm::dvec3 PlacedEmissivePolygon::emittedRadiance(const glm::dvec3&, const glm::dvec3&) const {
  return radiance_;
}

glm::dvec3 PlacedEmissivePolygon::radianceToward(const glm::dvec3& y, const glm::dvec3& x) const {
  return glm::dot(normal_, x - y) > 0.0 ? radiance_ : glm::dvec3(0.0);
}

// $E = \frac{L_e}{2} \sum_k \gamma_k \, \hat n \cdot \frac{R_{k+1} \times R_k}{|R_{k+1} \times
// R_k|}$, $R_k = v_k - x$, over the polygon clipped to the receiver's front half-space.
glm::dvec3 PlacedEmissivePolygon::irradiance(const glm::dvec3& x, const glm::dvec3& n) const {
  if (!(glm::dot(normal_, x - world_.v[0]) > 0.0)) return glm::dvec3(0.0);  // behind the light
  std::vector<glm::dvec3> clipped;
  clipped.reserve(8);
  clipToFront(world_.v.data(), std::size_t(world_.count), n, x, 0.0,
              [&](const glm::dvec3& p) { clipped.push_back(p); });
  if (clipped.size() < 3) return glm::dvec3(0.0);
  double sum = 0.0;
  for (std::size_t k = 0; k < clipped.size(); ++k) {
    const glm::dvec3 a = clipped[k] - x, b = clipped[(k + 1) % clipped.size()] - x;
    const glm::dvec3 c = glm::cross(b, a);
    const double len = glm::length(c);
    if (!(len > 0.0)) continue;
    sum += std::atan2(len, glm::dot(a, b)) * glm::dot(n, c) / len;
  }
  return radiance_ * (0.5 * std::max(sum, 0.0));
}

EmitterSample PlacedEmissivePolygon::sample(const glm::dvec2& u) const {
  EmitterSample s;
  s.point = pointOnPolygon(world_, u.x, u.y);
  s.normal = normal_;
  s.pdfArea = area_ > 0.0 ? 1.0 / area_ : 0.0;
  return s;
}

EmissivePolygonEmitter::EmissivePolygonEmitter(const Scene& scene, const InputPolygon& polygon,
                                               int topIndex, const glm::dvec3& radiance)
    : scene_(scene), polygon_(polygon), top_(topIndex), radiance_(radiance) {}

bool EmissivePolygonEmitter::moves(double t0, double t1) const {
  return polygon_.node >= 0 && scene_.isDynamic(polygon_.node, t0, t1);
}

Polygon EmissivePolygonEmitter::worldAt(double t) const {
  return polygon_.local.transformed(scene_.worldTransform(polygon_.node, t));
}

// A polygon's image under an affine map is the hull of its vertices' images, so the vertices
// at the sample times bound it at those times; between samples the box is padded by the
// largest step a vertex makes, as Scene::sweptBounds pads (the same sampling argument).
std::array<glm::dvec3, 2> EmissivePolygonEmitter::bounds(double t0, double t1) const {
  const double inf = std::numeric_limits<double>::infinity();
  std::array<glm::dvec3, 2> box{glm::dvec3(inf), glm::dvec3(-inf)};
  const bool dynamic = moves(t0, t1);
  const std::vector<double> ts =
      dynamic ? scene_.sampleTimes(polygon_.node, t0, t1, 32) : std::vector<double>{t0};
  std::array<glm::dvec3, 4> prev{};
  double pad = 0.0;
  for (std::size_t i = 0; i < ts.size(); ++i) {
    const Polygon p = worldAt(ts[i]);
    for (int k = 0; k < p.count; ++k) {
      box[0] = glm::min(box[0], p.v[size_t(k)]);
      box[1] = glm::max(box[1], p.v[size_t(k)]);
      if (i > 0) pad = std::max(pad, glm::length(p.v[size_t(k)] - prev[size_t(k)]));
      prev[size_t(k)] = p.v[size_t(k)];
    }
  }
  box[0] -= glm::dvec3(pad);
  box[1] += glm::dvec3(pad);
  return box;
}

glm::dvec3 EmissivePolygonEmitter::power(double t) const {
  return kPi * radiance_ * worldAt(t).area();
}

std::unique_ptr<PlacedEmitter> EmissivePolygonEmitter::at(double t) const {
  const Polygon world = worldAt(t);
  if (world.normal() == glm::dvec3(0.0)) return nullptr;  // degenerate after a zero scale
  return std::make_unique<PlacedEmissivePolygon>(world, radiance_);
}

std::string EmissivePolygonEmitter::toString() const {
  std::ostringstream os;
  os << "emissive polygon (top " << top_ << ", node " << polygon_.node << ", material "
     << polygon_.material << (polygon_.backFace ? ", back face" : "") << ", L_e " << radiance_.x
     << " " << radiance_.y << " " << radiance_.z << ")";
  return os.str();
}

}  // namespace rad
