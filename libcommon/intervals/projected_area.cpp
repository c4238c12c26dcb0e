// Homogeneous frustum clipping + shoelace area. Sources in projected_area.h.
#include "libcommon/intervals/projected_area.h"

#include <array>
#include <cmath>
#include <string>

#include "libcommon/core/error.h"

namespace rad {
namespace {

// A convex n-gon clipped by 6 planes has at most n + 6 vertices.
constexpr int kMaxVertices = 16;

struct ClipPolygon {
  int count = 0;
  std::array<glm::dvec4, kMaxVertices> v;
};

// Signed distance-like value of a clip-space point to frustum plane `plane`; inside when >= 0.
// Planes: w+x, w-x, w+y, w-y, w+z, w-z (OpenGL clip volume -w <= x, y, z <= w). For the
// infinite-far projection w - z = 2 znear > 0 everywhere, so the far plane never clips.
double planeValue(const glm::dvec4& p, int plane) {
  switch (plane) {
    case 0:
      return p.w + p.x;
    case 1:
      return p.w - p.x;
    case 2:
      return p.w + p.y;
    case 3:
      return p.w - p.y;
    case 4:
      return p.w + p.z;
    default:
      return p.w - p.z;
  }
}

void clipAgainst(const ClipPolygon& in, int plane, ClipPolygon& out) {
  out.count = 0;
  if (in.count == 0) return;
  for (int i = 0; i < in.count; ++i) {
    const glm::dvec4& a = in.v[i];
    const glm::dvec4& b = in.v[(i + 1) % in.count];
    double da = planeValue(a, plane), db = planeValue(b, plane);
    if (da >= 0.0) out.v[out.count++] = a;
    if ((da >= 0.0) != (db >= 0.0)) {
      // Linear interpolation in clip space is exact: clip coordinates are affine in world space.
      double t = da / (da - db);
      out.v[out.count++] = a + t * (b - a);
    }
  }
}

}  // namespace

double projectedAreaPixels(const glm::dmat4& clipFromPolygon, ImageSize size,
                           const glm::dvec3* points, int count) {
  if (count > kMaxVertices - 6)
    throw Error(ExitCode::kInternal, "projected area",
                std::to_string(count) + " vertices; at most " + std::to_string(kMaxVertices - 6));
  if (count < 3) return 0.0;
  ClipPolygon a, b;
  a.count = count;
  for (int i = 0; i < count; ++i) a.v[i] = clipFromPolygon * glm::dvec4(points[i], 1.0);
  ClipPolygon* cur = &a;
  ClipPolygon* next = &b;
  for (int plane = 0; plane < 6; ++plane) {
    clipAgainst(*cur, plane, *next);
    std::swap(cur, next);
    if (cur->count < 3) return 0.0;
  }
  // Every surviving vertex has w >= |x|, |y|, |z| and w >= znear-ish > 0, so division is safe.
  // Fan around the first vertex (relative coordinates keep the shoelace sum well conditioned).
  std::array<glm::dvec2, kMaxVertices> px;
  for (int i = 0; i < cur->count; ++i) {
    const glm::dvec4& c = cur->v[i];
    px[i] = glm::dvec2((c.x / c.w + 1.0) * 0.5 * size.width, (1.0 - c.y / c.w) * 0.5 * size.height);
  }
  double twiceArea = 0.0;
  for (int i = 1; i + 1 < cur->count; ++i) {
    glm::dvec2 e1 = px[i] - px[0], e2 = px[i + 1] - px[0];
    twiceArea += e1.x * e2.y - e2.x * e1.y;
  }
  return 0.5 * std::abs(twiceArea);
}

double projectedAreaPixels(const CameraView& view, ImageSize size, const Polygon& world) {
  return projectedAreaPixels(clipFromWorld(view, size), size, world.v.data(), world.count);
}

}  // namespace rad
