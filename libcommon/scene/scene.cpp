// The scene model: glTF 2.0 animation evaluation, input polygons, cameras (docs/design.md §4).
//
// Animation semantics follow the glTF 2.0 specification, §3.11 "Animations" and
// Appendix C "Animation Sampler Interpolation Modes" (Khronos, glTF 2.0.1).
#include "libcommon/scene/scene.h"

#include "libcommon/core/error.h"
#include "libcommon/scene/closed_solid.h"
#include "libcommon/scene/contact_cuts.h"
#include "libcommon/scene/patch_hierarchy.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <tuple>

namespace rad {

namespace {

int componentCount(AnimationPath path) {
  return path == AnimationPath::kRotation ? 4 : 3;
}

// A channel is usable when it has keys and as many output elements as the sampler needs
// (glTF §3.11: count, or 3 x count for CUBICSPLINE).
bool channelUsable(const AnimationChannel& ch) {
  if (ch.times.empty()) return false;
  size_t per = ch.interpolation == Interpolation::kCubicSpline ? 3 : 1;
  return ch.values.size() >= ch.times.size() * per * size_t(componentCount(ch.path));
}

// Element `e` of key `k`: 0 = value; for CUBICSPLINE -1 = in-tangent, +1 = out-tangent.
const double* keyElement(const AnimationChannel& ch, size_t k, int e = 0) {
  size_t n = size_t(componentCount(ch.path));
  if (ch.interpolation == Interpolation::kCubicSpline) return &ch.values[(3 * k + 1 + e) * n];
  return &ch.values[k * n];
}

// glTF Appendix C: spherical linear interpolation with the shortest-arc sign flip.
glm::dvec4 slerpXyzw(glm::dvec4 a, glm::dvec4 b, double s) {
  double d = glm::dot(a, b);
  if (d < 0.0) {
    b = -b;
    d = -d;
  }
  glm::dvec4 r;
  if (d > 1.0 - 1e-12) {
    r = a + s * (b - a);  // nearly equal: lerp is exact to rounding
  } else {
    double theta = std::acos(std::min(d, 1.0));
    double sinTheta = std::sin(theta);
    r = (std::sin((1.0 - s) * theta) / sinTheta) * a + (std::sin(s * theta) / sinTheta) * b;
  }
  double len = glm::length(r);
  return len > 0.0 ? r / len : glm::dvec4(0, 0, 0, 1);
}

// Value of a channel at time t (3 or 4 doubles in `out`, quaternions x y z w).
void sampleChannel(const AnimationChannel& ch, double t, double out[4]) {
  const int n = componentCount(ch.path);
  const size_t keys = ch.times.size();
  auto copy = [&](const double* v) {
    for (int c = 0; c < n; ++c) out[c] = v[c];
  };
  // glTF §3.11: before the first key the first value holds, after the last key the last.
  if (!(t > ch.times.front())) return copy(keyElement(ch, 0));
  if (t >= ch.times.back()) return copy(keyElement(ch, keys - 1));
  // Segment k with t_k <= t < t_{k+1}.
  size_t k = size_t(std::upper_bound(ch.times.begin(), ch.times.end(), t) - ch.times.begin()) - 1;
  const double t0 = ch.times[k], t1 = ch.times[k + 1];
  const double td = t1 - t0;
  const double s = td > 0.0 ? (t - t0) / td : 0.0;
  switch (ch.interpolation) {
    case Interpolation::kStep:  // Appendix C.1: the left key's value holds.
      return copy(keyElement(ch, k));
    case Interpolation::kLinear: {  // Appendix C.2
      const double* a = keyElement(ch, k);
      const double* b = keyElement(ch, k + 1);
      if (ch.path == AnimationPath::kRotation) {
        glm::dvec4 q = slerpXyzw({a[0], a[1], a[2], a[3]}, {b[0], b[1], b[2], b[3]}, s);
        for (int c = 0; c < 4; ++c) out[c] = q[c];
      } else {
        for (int c = 0; c < n; ++c) out[c] = a[c] + s * (b[c] - a[c]);
      }
      return;
    }
    case Interpolation::kCubicSpline: {  // Appendix C.3, Hermite spline
      // $p(s) = (2s^3-3s^2+1) v_k + t_d (s^3-2s^2+s) b_k + (-2s^3+3s^2) v_{k+1}
      //        + t_d (s^3-s^2) a_{k+1}$ with b_k the out-tangent, a_{k+1} the in-tangent.
      const double s2 = s * s, s3 = s2 * s;
      const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s;
      const double h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
      const double* vk = keyElement(ch, k);
      const double* bk = keyElement(ch, k, +1);
      const double* vk1 = keyElement(ch, k + 1);
      const double* ak1 = keyElement(ch, k + 1, -1);
      for (int c = 0; c < n; ++c) {
        out[c] = h00 * vk[c] + td * h10 * bk[c] + h01 * vk1[c] + td * h11 * ak1[c];
      }
      if (ch.path == AnimationPath::kRotation) {
        double len =
            std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2] + out[3] * out[3]);
        if (len > 0.0) {
          for (int c = 0; c < 4; ++c) out[c] /= len;
        } else {
          out[0] = out[1] = out[2] = 0.0;
          out[3] = 1.0;
        }
      }
      return;
    }
  }
}

glm::dmat4 composeTrs(const glm::dvec3& t, const glm::dquat& r, const glm::dvec3& s) {
  // glTF §3.5.3: M = T * R * S.
  glm::dmat4 m = glm::mat4_cast(glm::normalize(r));
  for (int c = 0; c < 3; ++c) m[c] *= s[c];
  m[3] = glm::dvec4(t, 1.0);
  return m;
}

bool nearlyEqual(const double* a, const double* b, int n) {
  for (int c = 0; c < n; ++c) {
    if (std::abs(a[c] - b[c]) > 1e-12 * std::max({1.0, std::abs(a[c]), std::abs(b[c])}))
      return false;
  }
  return true;
}

bool sameKeyValue(const AnimationChannel& ch, const double* a, const double* b) {
  if (nearlyEqual(a, b, componentCount(ch.path))) return true;
  if (ch.path == AnimationPath::kRotation) {  // q and -q are the same rotation
    double neg[4] = {-b[0], -b[1], -b[2], -b[3]};
    return nearlyEqual(a, neg, 4);
  }
  return false;
}

bool isZero(const double* a, int n) {
  for (int c = 0; c < n; ++c)
    if (a[c] != 0.0) return false;
  return true;
}

// Whether the channel's value changes anywhere in [t0, t1] (t0 < t1).
bool channelChanges(const AnimationChannel& ch, double t0, double t1) {
  const size_t keys = ch.times.size();
  if (keys < 2) return false;
  if (t1 <= ch.times.front() || t0 >= ch.times.back()) return false;  // held value
  // Keys lo..hi determine every value taken on [t0, t1]: lo is the last key at or before t0;
  // hi is the first key at or after t1 (interpolating) or the last key at or before t1 (STEP,
  // which reaches key k's value only at t_k).
  size_t lo = 0, hi = keys - 1;
  while (lo + 1 < keys && ch.times[lo + 1] <= t0) ++lo;
  if (ch.interpolation == Interpolation::kStep) {
    while (hi > 0 && ch.times[hi] > t1) --hi;
  } else {
    while (hi > 0 && ch.times[hi - 1] >= t1) --hi;
  }
  const double* v0 = keyElement(ch, lo);
  const int n = componentCount(ch.path);
  for (size_t k = lo; k <= hi; ++k) {
    if (!sameKeyValue(ch, v0, keyElement(ch, k))) return true;
    if (ch.interpolation == Interpolation::kCubicSpline) {
      if (k > lo && !isZero(keyElement(ch, k, -1), n)) return true;
      if (k < hi && !isZero(keyElement(ch, k, +1), n)) return true;
    }
  }
  // A rotation channel whose keys are q and -q: slerp takes the shortest arc, so constant.
  return false;
}

}  // namespace

glm::dmat4 Scene::localTransform(int node, double t) const {
  if (node < 0 || node >= int(nodes.size())) return glm::dmat4(1.0);
  const Node& n = nodes[size_t(node)];
  glm::dvec3 translation = n.translation, scale = n.scale;
  glm::dquat rotation = n.rotation;
  for (const AnimationChannel& ch : channels) {
    if (ch.node != node || !channelUsable(ch)) continue;
    double v[4];
    sampleChannel(ch, t, v);
    switch (ch.path) {
      case AnimationPath::kTranslation:
        translation = {v[0], v[1], v[2]};
        break;
      case AnimationPath::kScale:
        scale = {v[0], v[1], v[2]};
        break;
      case AnimationPath::kRotation:
        rotation = glm::dquat(v[3], v[0], v[1], v[2]);  // glTF x y z w -> glm (w, x, y, z)
        break;
    }
  }
  return composeTrs(translation, rotation, scale);
}

glm::dmat4 Scene::worldTransform(int node, double t) const {
  glm::dmat4 m(1.0);
  // The depth guard keeps a malformed (cyclic) hand-built hierarchy from looping forever.
  for (size_t depth = 0; node >= 0 && node < int(nodes.size()) && depth <= nodes.size(); ++depth) {
    m = localTransform(node, t) * m;
    node = nodes[size_t(node)].parent;
  }
  return m;
}

double Scene::startTime() const {
  double t = std::numeric_limits<double>::infinity();
  for (const AnimationChannel& ch : channels)
    if (!ch.times.empty()) t = std::min(t, ch.times.front());
  return std::isinf(t) ? 0.0 : t;
}

double Scene::endTime() const {
  double t = -std::numeric_limits<double>::infinity();
  for (const AnimationChannel& ch : channels)
    if (!ch.times.empty()) t = std::max(t, ch.times.back());
  return std::isinf(t) ? 0.0 : t;
}

std::vector<int> Scene::reachableNodes() const {
  std::vector<char> seen(nodes.size(), 0);
  std::vector<int> stack;
  if (roots.empty()) {
    for (size_t i = 0; i < nodes.size(); ++i)
      if (nodes[i].parent < 0) stack.push_back(int(i));
  } else {
    stack = roots;
  }
  while (!stack.empty()) {
    int i = stack.back();
    stack.pop_back();
    if (i < 0 || i >= int(nodes.size()) || seen[size_t(i)]) continue;
    seen[size_t(i)] = 1;
    for (int c : nodes[size_t(i)].children) stack.push_back(c);
  }
  std::vector<int> out;
  for (size_t i = 0; i < nodes.size(); ++i)
    if (seen[i]) out.push_back(int(i));
  return out;
}

std::vector<int> Scene::meshNodes() const {
  std::vector<int> out;
  for (int i : reachableNodes())
    if (nodes[size_t(i)].mesh >= 0 && nodes[size_t(i)].mesh < int(meshes.size())) out.push_back(i);
  return out;
}

bool Scene::isDynamic(int node, double t0, double t1) const {
  if (t1 < t0) std::swap(t0, t1);
  if (!(t1 > t0)) return false;  // a single instant: nothing can change
  for (size_t depth = 0; node >= 0 && node < int(nodes.size()) && depth <= nodes.size(); ++depth) {
    for (const AnimationChannel& ch : channels)
      if (ch.node == node && channelUsable(ch) && channelChanges(ch, t0, t1)) return true;
    node = nodes[size_t(node)].parent;
  }
  return false;
}

std::vector<double> Scene::sampleTimes(int node, double t0, double t1, int perSegment) const {
  if (t1 < t0) std::swap(t0, t1);
  std::vector<double> ts{t0, t1};
  const int uniform = 64;
  for (int i = 1; i < uniform; ++i) ts.push_back(t0 + (t1 - t0) * i / uniform);
  for (size_t depth = 0; node >= 0 && node < int(nodes.size()) && depth <= nodes.size(); ++depth) {
    for (const AnimationChannel& ch : channels) {
      if (ch.node != node || !channelUsable(ch)) continue;
      for (size_t k = 0; k + 1 < ch.times.size(); ++k) {
        double a = ch.times[k], b = ch.times[k + 1];
        if (b < t0 || a > t1) continue;
        for (int i = 0; i <= perSegment; ++i) {
          double t = a + (b - a) * i / perSegment;
          if (t >= t0 && t <= t1) ts.push_back(t);
        }
        // STEP jumps at b: sample just before it too.
        double before = std::nextafter(b, a);
        if (before >= t0 && before <= t1) ts.push_back(before);
      }
    }
    node = nodes[size_t(node)].parent;
  }
  std::sort(ts.begin(), ts.end());
  ts.erase(std::unique(ts.begin(), ts.end()), ts.end());
  return ts;
}

std::array<glm::dvec3, 2> Scene::sweptBounds(int node, double t0, double t1) const {
  const double inf = std::numeric_limits<double>::infinity();
  std::array<glm::dvec3, 2> box{glm::dvec3(inf), glm::dvec3(-inf)};
  if (node < 0 || node >= int(nodes.size())) return {glm::dvec3(0.0), glm::dvec3(0.0)};
  // Points whose world images bound the geometry: all vertices for the static case (exact),
  // the 8 corners of the local box for the swept case (conservative for any affine map).
  std::vector<glm::dvec3> points;
  const int mesh = nodes[size_t(node)].mesh;
  if (mesh >= 0 && mesh < int(meshes.size()))
    for (const MeshTriangle& tri : meshes[size_t(mesh)].triangles)
      for (const glm::dvec3& p : tri.p) points.push_back(p);
  if (points.empty()) points.push_back(glm::dvec3(0.0));
  auto grow = [&](const glm::dvec3& p) {
    box[0] = glm::min(box[0], p);
    box[1] = glm::max(box[1], p);
  };
  if (!isDynamic(node, t0, t1)) {
    glm::dmat4 m = worldTransform(node, t0);
    for (const glm::dvec3& p : points) grow(glm::dvec3(m * glm::dvec4(p, 1.0)));
    return box;
  }
  glm::dvec3 lo(inf), hi(-inf);
  for (const glm::dvec3& p : points) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  std::array<glm::dvec3, 8> corners;
  for (int i = 0; i < 8; ++i)
    corners[size_t(i)] = {(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z};
  // Sample; pad by the largest distance any corner moves between consecutive samples. A path
  // whose length is at most twice its chord stays within one chord of a sample end, which
  // dense sampling (64 uniform + 32 per key segment) makes true for any glTF curve here.
  std::vector<double> ts = sampleTimes(node, t0, t1, 32);
  std::array<glm::dvec3, 8> prev{};
  double pad = 0.0;
  for (size_t i = 0; i < ts.size(); ++i) {
    glm::dmat4 m = worldTransform(node, ts[i]);
    for (size_t c = 0; c < 8; ++c) {
      glm::dvec3 p(m * glm::dvec4(corners[c], 1.0));
      grow(p);
      if (i > 0) pad = std::max(pad, glm::length(p - prev[c]));
      prev[c] = p;
    }
  }
  box[0] -= glm::dvec3(pad);
  box[1] += glm::dvec3(pad);
  return box;
}

namespace {

struct Tri {
  std::array<glm::dvec3, 3> p;
  std::array<glm::dvec2, 3> uv;
  std::array<glm::dvec3, 3> normal;
  int material;
};

double maxEdge(const std::array<glm::dvec3, 4>& v, int count) {
  double e = 0.0;
  for (int i = 0; i < count; ++i)
    e = std::max(e, glm::length(v[size_t((i + 1) % count)] - v[size_t(i)]));
  return e;
}

// Strictly convex, CCW about normal n, no three collinear vertices (relative tolerance).
bool convexQuad(const std::array<glm::dvec3, 4>& v, const glm::dvec3& n) {
  double scale = maxEdge(v, 4);
  for (int i = 0; i < 4; ++i) {
    glm::dvec3 a = v[size_t((i + 1) % 4)] - v[size_t(i)];
    glm::dvec3 b = v[size_t((i + 2) % 4)] - v[size_t((i + 1) % 4)];
    if (glm::dot(glm::cross(a, b), n) <= 1e-9 * scale * scale) return false;
  }
  return true;
}

// Barycentric-affine prediction of the uv at point q from triangle t (q in t's plane).
glm::dvec2 affineUv(const Tri& t, const glm::dvec3& q) {
  glm::dvec3 e1 = t.p[1] - t.p[0], e2 = t.p[2] - t.p[0], d = q - t.p[0];
  double a = glm::dot(e1, e1), b = glm::dot(e1, e2), c = glm::dot(e2, e2);
  double u = glm::dot(d, e1), w = glm::dot(d, e2);
  double det = a * c - b * b;
  if (det == 0.0) return t.uv[0];
  double l1 = (u * c - w * b) / det, l2 = (w * a - u * b) / det;
  return t.uv[0] + l1 * (t.uv[1] - t.uv[0]) + l2 * (t.uv[2] - t.uv[0]);
}

// Merges triangle j into i across i's edge k when the glTF-free criteria hold; returns the
// quad (vertices A, D, B, C for i = (A, B, C) and j = (B, A, D)).
bool tryMerge(const Tri& ti, const Tri& tj, InputPolygon* out) {
  if (ti.material != tj.material) return false;
  for (int k = 0; k < 3; ++k) {
    const glm::dvec3& A = ti.p[size_t(k)];
    const glm::dvec3& B = ti.p[size_t((k + 1) % 3)];
    for (int m = 0; m < 3; ++m) {
      if (tj.p[size_t(m)] != B || tj.p[size_t((m + 1) % 3)] != A) continue;
      const size_t ia = size_t(k), ib = size_t((k + 1) % 3), ic = size_t((k + 2) % 3);
      const size_t jb = size_t(m), ja = size_t((m + 1) % 3), jd = size_t((m + 2) % 3);
      // Same uv at the shared vertices.
      const double uvTol = 1e-9;
      if (glm::length(ti.uv[ia] - tj.uv[ja]) > uvTol || glm::length(ti.uv[ib] - tj.uv[jb]) > uvTol)
        return false;
      const glm::dvec3& C = ti.p[ic];
      const glm::dvec3& D = tj.p[jd];
      std::array<glm::dvec3, 4> v{A, D, B, C};
      double scale = maxEdge(v, 4);
      glm::dvec3 n = glm::normalize(glm::cross(B - A, C - A));
      // Coplanar: D within 1e-7 of the quad's size from i's plane.
      if (std::abs(glm::dot(D - A, n)) > 1e-7 * scale) return false;
      if (!convexQuad(v, n)) return false;
      // A parallelogram only (to 5 % of its size, which keeps measured rectangles such as the
      // Cornell box's walls and box tops): its bilinear (u,v) map is then the plane homography
      // of the shadow masks (transmittance.h) to second order in the departure, so each texel's
      // shadow is taken at the texel's own point. A trapezoid merged from two triangles of a fan
      // had its shadows displaced over the whole quad (a desk's shadow on a wall 6 cm too low;
      // issue 56).
      if (glm::length((A + B) - (D + C)) > 0.05 * scale) return false;
      // The uv map must be one affine map over the quad (else texturing would change).
      glm::dvec2 predicted = affineUv(ti, D);
      double uvScale = 1.0;
      for (const glm::dvec2& uv : ti.uv)
        uvScale = std::max({uvScale, std::abs(uv.x), std::abs(uv.y)});
      if (glm::length(predicted - tj.uv[jd]) > 1e-6 * uvScale) return false;
      out->local.count = 4;
      out->local.v = v;
      out->uv = {ti.uv[ia], tj.uv[jd], ti.uv[ib], ti.uv[ic]};
      out->normal = {ti.normal[ia], tj.normal[jd], ti.normal[ib], ti.normal[ic]};
      out->material = ti.material;
      return true;
    }
  }
  return false;
}

using EdgeKey = std::tuple<double, double, double, double, double, double>;
EdgeKey edgeKey(const glm::dvec3& a, const glm::dvec3& b) {
  return EdgeKey{a.x, a.y, a.z, b.x, b.y, b.z};
}

// A triangle's (u,v) map starts at its vertex opposite the longest edge (the widest corner, of
// largest sine): the texel grid of its texture runs along the two edges there. From a sliver's
// sharp corner (a fan's apex, where a converter puts v0) both edges run along the sliver and a
// grid fine enough along its length wastes texels by its aspect ratio (docs/design.md §6.2,
// issue 56). The rotation keeps the winding; the current v0 is kept unless another corner's
// opposite edge is longer by more than rounding.
void rootAtWidestCorner(InputPolygon& p) {
  if (p.local.count != 3) return;
  double longest[3];
  for (int k = 0; k < 3; ++k)
    longest[k] = glm::length(p.local.v[size_t((k + 2) % 3)] - p.local.v[size_t((k + 1) % 3)]);
  int root = 0;
  for (int k = 1; k < 3; ++k)
    if (longest[k] > longest[root] * (1.0 + 1e-9)) root = k;
  if (root == 0) return;
  const InputPolygon q = p;
  for (int k = 0; k < 3; ++k) {
    const size_t from = size_t((k + root) % 3);
    p.local.v[size_t(k)] = q.local.v[from];
    p.uv[size_t(k)] = q.uv[from];
    p.normal[size_t(k)] = q.normal[from];
  }
}

InputPolygon reversed(const InputPolygon& p) {
  InputPolygon r = p;
  // Keep v0, reverse the rest: (v0, v1, v2[, v3]) -> (v0, v_{n-1}, ..., v1).
  for (int i = 1; i < p.local.count; ++i) {
    r.local.v[size_t(i)] = p.local.v[size_t(p.local.count - i)];
    r.uv[size_t(i)] = p.uv[size_t(p.local.count - i)];
    r.normal[size_t(i)] = -p.normal[size_t(p.local.count - i)];
  }
  r.normal[0] = -p.normal[0];
  r.backFace = true;
  return r;
}

}  // namespace

glm::dvec3 shadingNormalAt(const InputPolygon& p, glm::dvec2 uv) {
  const glm::dvec3 flat = p.local.normal();
  if (p.normal[0] == glm::dvec3(0.0)) return flat;
  Polygon normals;  // the vertex normals, interpolated as points are
  normals.count = p.local.count;
  for (int k = 0; k < p.local.count; ++k) normals.v[size_t(k)] = p.normal[size_t(k)];
  const glm::dvec3 n = polygonPointAt(normals, uv);
  const double len = glm::length(n);
  if (!(len > 1e-12) || !(glm::dot(n, flat) > 0.0)) return flat;
  return n / len;
}

namespace {

// The top-level patches of one mesh in its own frame (node -1): merged quads, triangles rooted
// at their widest corner, a doubleSided material's reversed copies. A mesh that many nodes share
// (glTF instancing) is merged once, not once per node (issue 58's floor of furnished rooms).
std::vector<InputPolygon> meshPolygons(const Mesh& mesh, const std::vector<Material>& materials) {
  std::vector<InputPolygon> out;
  std::vector<Tri> tris;
  for (const MeshTriangle& t : mesh.triangles) tris.push_back({t.p, t.uv, t.normal, t.material});
  // Directed edge -> triangles that have it, to find the neighbour across an edge.
  std::map<EdgeKey, std::vector<size_t>> byEdge;
  for (size_t i = 0; i < tris.size(); ++i)
    for (size_t k = 0; k < 3; ++k)
      byEdge[edgeKey(tris[i].p[k], tris[i].p[(k + 1) % 3])].push_back(i);
  std::vector<char> used(tris.size(), 0);
  for (size_t i = 0; i < tris.size(); ++i) {
    if (used[i]) continue;
    used[i] = 1;
    InputPolygon poly;
    bool merged = false;
    // The lowest-index unused neighbour that merges, over i's edges in order.
    std::set<size_t> candidates;
    for (size_t k = 0; k < 3; ++k) {
      auto it = byEdge.find(edgeKey(tris[i].p[(k + 1) % 3], tris[i].p[k]));
      if (it == byEdge.end()) continue;
      for (size_t j : it->second)
        if (j > i && !used[j]) candidates.insert(j);
    }
    for (size_t j : candidates) {
      if (tryMerge(tris[i], tris[j], &poly)) {
        used[j] = 1;
        merged = true;
        break;
      }
    }
    if (!merged) {
      poly.local.count = 3;
      for (size_t k = 0; k < 3; ++k) {
        poly.local.v[k] = tris[i].p[k];
        poly.uv[k] = tris[i].uv[k];
        poly.normal[k] = tris[i].normal[k];
      }
      poly.material = tris[i].material;
      rootAtWidestCorner(poly);
    }
    out.push_back(poly);
    const int mat = poly.material;
    if (mat >= 0 && mat < int(materials.size()) && materials[size_t(mat)].doubleSided)
      out.push_back(reversed(poly));
  }
  return out;
}

}  // namespace

std::vector<InputPolygon> Scene::inputPolygons() const {
  const std::vector<int> nodeList = meshNodes();
  std::vector<std::vector<InputPolygon>> perMesh(meshes.size());
  std::vector<char> merged(meshes.size(), 0);
  size_t total = 0;
  for (int node : nodeList) {
    const size_t m = size_t(nodes[size_t(node)].mesh);
    if (!merged[m]) {
      perMesh[m] = meshPolygons(meshes[m], materials);
      const bool solid = isClosedSolid(meshes[m].triangles);
      for (InputPolygon& p : perMesh[m]) p.closedSolid = solid;
    }
    merged[m] = 1;
    total += perMesh[m].size();
  }
  std::vector<InputPolygon> out;
  out.reserve(total);
  for (int node : nodeList)
    for (const InputPolygon& p : perMesh[size_t(nodes[size_t(node)].mesh)]) {
      out.push_back(p);
      out.back().node = node;
    }
  return cutAtContacts(*this, std::move(out));
}

std::vector<int> Scene::lightNodes() const {
  std::vector<int> out;
  for (int i : reachableNodes()) {
    const int l = nodes[size_t(i)].light;
    if (l >= 0 && l < int(lights.size()) && lights[size_t(l)].emits()) out.push_back(i);
  }
  return out;
}

std::vector<int> Scene::cameraNodes() const {
  std::vector<int> out;
  for (int i : reachableNodes())
    if (nodes[size_t(i)].camera >= 0 && nodes[size_t(i)].camera < int(cameras.size()))
      out.push_back(i);
  return out;
}

int Scene::cameraNode(const std::string& name) const {
  std::vector<int> cams = cameraNodes();
  if (cams.empty()) return -1;
  if (name.empty()) return cams.front();
  for (int i : cams)  // node name first, then the camera's own name
    if (nodes[size_t(i)].name == name) return i;
  for (int i : cams)
    if (cameras[size_t(nodes[size_t(i)].camera)].name == name) return i;
  return -1;
}

CameraView Scene::cameraAt(int node, double t) const {
  CameraView view;
  if (node < 0 || node >= int(nodes.size())) return view;
  const int cam = nodes[size_t(node)].camera;
  if (cam >= 0 && cam < int(cameras.size())) view.lens = cameras[size_t(cam)];
  glm::dmat4 m = worldTransform(node, t);
  // Remove scale (and shear) keeping the viewing direction -Z and the up vector +Y: the
  // camera's world frame is rigid whatever its parents' scales (glTF §3.10.1 cameras are
  // placed by their node's transform; scale does not change a camera's frustum here).
  glm::dvec3 z(m[2]), y(m[1]);
  double lz = glm::length(z);
  z = lz > 0.0 ? z / lz : glm::dvec3(0, 0, 1);
  y -= glm::dot(y, z) * z;
  double ly = glm::length(y);
  if (ly > 0.0) {
    y /= ly;
  } else {  // degenerate: pick any perpendicular
    y = std::abs(z.x) < 0.9 ? glm::normalize(glm::cross(z, glm::dvec3(1, 0, 0)))
                            : glm::normalize(glm::cross(z, glm::dvec3(0, 1, 0)));
  }
  glm::dvec3 x = glm::cross(y, z);
  view.worldFromCamera = glm::dmat4(glm::dvec4(x, 0.0), glm::dvec4(y, 0.0), glm::dvec4(z, 0.0),
                                    glm::dvec4(glm::dvec3(m[3]), 1.0));
  return view;
}

std::vector<int> movingNodesOf(const Scene& scene, const std::vector<InputPolygon>& polygons,
                               double t0, double t1) {
  // In the order of first appearance; a flag per scene node (rad-movies asks per movie, and a
  // search of the nodes seen so far cost tops x nodes each time).
  std::vector<char> seen(scene.nodes.size(), 0);
  std::vector<int> moving;
  for (const InputPolygon& p : polygons) {
    if (p.node < 0 || size_t(p.node) >= seen.size() || seen[size_t(p.node)]) continue;
    seen[size_t(p.node)] = 1;
    if (scene.isDynamic(p.node, t0, t1)) moving.push_back(p.node);
  }
  return moving;
}

std::string missingEmitterMessage(const Scene& scene) {
  for (int node : scene.meshNodes())
    for (const MeshTriangle& t : scene.meshes[size_t(scene.nodes[size_t(node)].mesh)].triangles)
      if (t.material >= 0 && t.material < int(scene.materials.size()) &&
          scene.materials[size_t(t.material)].isEmitter())
        return "";
  if (!scene.lightNodes().empty()) return "";
  return std::string("no emissive material and no KHR_lights_punctual light") +
         (scene.lights.empty() ? "" : " of non-zero intensity on a node of the scene") +
         ": give a mesh an emissive material (emissiveFactor) or add a lamp";
}

void requireEmitter(const Scene& scene) {
  const std::string what = missingEmitterMessage(scene);
  if (!what.empty()) throw inputError(scene.path, what);
}

}  // namespace rad
