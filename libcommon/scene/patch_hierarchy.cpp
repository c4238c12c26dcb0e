// Hanrahan, Salzman, Aupperle 1991, "A Rapid Hierarchical Radiosity Algorithm": quadtree
// subdivision of input polygons.
#include "libcommon/scene/patch_hierarchy.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <sstream>

#include "libcommon/core/error.h"

namespace rad {

int PatchId::level() const {
  if (path == 0) return -1;  // no patch (path 1 is the top); a hostile file's node id can be 0
  int bits = 32 - __builtin_clz(path);
  return (bits - 1) / 2;
}

PatchId PatchId::child(int k) const {
  if (level() >= kMaxLevel)
    throw Error(ExitCode::kInternal, "", "patch " + toString() + ": too deep");
  return {top, (path << 2) | uint32_t(k & 3)};
}

PatchId PatchId::parent() const {
  return {top, path >> 2};
}

int PatchId::childIndex() const {
  return int(path & 3u);
}

std::string PatchId::toString() const {
  std::ostringstream os;
  os << top;
  int l = level();
  for (int i = l - 1; i >= 0; --i) os << (i == l - 1 ? "/" : ".") << ((path >> (2 * i)) & 3u);
  return os.str();
}

std::array<Polygon, 4> subdividePolygon(const Polygon& p) {
  std::array<Polygon, 4> c;
  if (p.count == 4) {
    // Children are the images of the four (u,v) quarter squares, in order (0,0), (1,0),
    // (1,1), (0,1): child k keeps corner k of the parent.
    glm::dvec3 m01 = 0.5 * (p.v[0] + p.v[1]), m12 = 0.5 * (p.v[1] + p.v[2]);
    glm::dvec3 m23 = 0.5 * (p.v[2] + p.v[3]), m30 = 0.5 * (p.v[3] + p.v[0]);
    glm::dvec3 mc = 0.25 * (p.v[0] + p.v[1] + p.v[2] + p.v[3]);
    c[0] = {4, {p.v[0], m01, mc, m30}};
    c[1] = {4, {m01, p.v[1], m12, mc}};
    c[2] = {4, {mc, m12, p.v[2], m23}};
    c[3] = {4, {m30, mc, m23, p.v[3]}};
  } else {
    // Midpoint subdivision: three corner triangles similar to the parent (child k keeps
    // corner k, same orientation and (u,v) layout) and the inverted centre triangle.
    glm::dvec3 m01 = 0.5 * (p.v[0] + p.v[1]), m12 = 0.5 * (p.v[1] + p.v[2]);
    glm::dvec3 m20 = 0.5 * (p.v[2] + p.v[0]);
    c[0] = {3, {p.v[0], m01, m20, {}}};
    c[1] = {3, {m01, p.v[1], m12, {}}};
    c[2] = {3, {m20, m12, p.v[2], {}}};
    c[3] = {3, {m12, m20, m01, {}}};
  }
  return c;
}

glm::dvec3 polygonPointAt(const Polygon& p, glm::dvec2 uv) {
  double u = uv.x, v = uv.y;
  if (p.count == 4) {
    return (1 - u) * (1 - v) * p.v[0] + u * (1 - v) * p.v[1] + u * v * p.v[2] +
           (1 - u) * v * p.v[3];
  }
  return p.v[0] + u * (p.v[1] - p.v[0]) + v * (p.v[2] - p.v[0]);
}

PolygonUvMap::PolygonUvMap(const Polygon& p) : p_(p) {
  // Work in the polygon's plane with a 2D basis; triangles invert the affine map directly,
  // quads invert the bilinear map with Newton's method started from the affine guess.
  const glm::dvec3 e1 = p.v[1] - p.v[0];
  const glm::dvec3 e2 = (p.count == 4 ? p.v[3] : p.v[2]) - p.v[0];
  const double a = glm::dot(e1, e1), b = glm::dot(e1, e2), c = glm::dot(e2, e2);
  const double det = a * c - b * b;
  valid_ = det > 0.0;
  if (!valid_) return;
  // u = (c (d.e1) - b (d.e2)) / det, v = (a (d.e2) - b (d.e1)) / det for d = x - v0.
  gradU_ = (c * e1 - b * e2) / det;
  gradV_ = (a * e2 - b * e1) / det;
  affine_ = p.count == 3;
  if (p.count == 4) {
    d10_ = p.v[1] - p.v[0];
    d23_ = p.v[2] - p.v[3];
    d30_ = p.v[3] - p.v[0];
    d21_ = p.v[2] - p.v[1];
    // The bilinear term's coefficient v0 - v1 + v2 - v3 = d23 - d10.
    const double size = std::sqrt(std::max(a, c));
    affine_ = glm::length(d23_ - d10_) <= 1e-12 * size;
  }
}

glm::dvec2 PolygonUvMap::uvAt(const glm::dvec3& x) const {
  if (!valid_) return glm::dvec2(0.0);
  const glm::dvec3 d = x - p_.v[0];
  glm::dvec2 uv(glm::dot(d, gradU_), glm::dot(d, gradV_));
  if (affine_) return uv;
  for (int it = 0; it < 20; ++it) {
    glm::dvec3 f = polygonPointAt(p_, uv) - x;
    glm::dvec3 du = (1 - uv.y) * d10_ + uv.y * d23_;
    glm::dvec3 dv = (1 - uv.x) * d30_ + uv.x * d21_;
    double aa = glm::dot(du, du), bb = glm::dot(du, dv), cc = glm::dot(dv, dv);
    double dd = aa * cc - bb * bb;
    if (!(dd > 0.0)) break;
    double s1 = glm::dot(f, du), s2 = glm::dot(f, dv);
    glm::dvec2 step((cc * s1 - bb * s2) / dd, (aa * s2 - bb * s1) / dd);
    uv -= step;
    if (std::abs(step.x) + std::abs(step.y) < 1e-15) break;
  }
  return uv;
}

glm::dvec2 polygonUvAt(const Polygon& p, const glm::dvec3& x) {
  return PolygonUvMap(p).uvAt(x);
}

PatchHierarchy::PatchHierarchy(std::vector<InputPolygon> tops) : tops_(std::move(tops)) {
  nodes_.reserve(tops_.size());
  for (size_t t = 0; t < tops_.size(); ++t) {
    PatchNode n;
    n.id = {uint32_t(t), 1u};
    n.local = tops_[t].local;
    index_.emplace(n.id.packed(), int(t));
    nodes_.push_back(n);
  }
}

int PatchHierarchy::subdivide(int i) {
  if (nodes_[i].firstChild >= 0) return nodes_[i].firstChild;
  std::array<Polygon, 4> kids = subdividePolygon(nodes_[i].local);
  int first = int(nodes_.size());
  PatchId id = nodes_[i].id;
  for (int k = 0; k < 4; ++k) {
    PatchNode n;
    n.id = id.child(k);
    n.parent = i;
    n.local = kids[k];
    index_.emplace(n.id.packed(), first + k);
    nodes_.push_back(n);
  }
  nodes_[i].firstChild = first;
  return first;
}

int PatchHierarchy::find(PatchId id) const {
  auto it = index_.find(id.packed());
  return it == index_.end() ? -1 : it->second;
}

int PatchHierarchy::findOrCreate(PatchId id) {
  if (id.top >= tops_.size()) {
    throw Error(ExitCode::kBadInput, "", "patch " + id.toString() + ": no such top-level patch");
  }
  int found = find(id);
  if (found >= 0) return found;
  int parent = findOrCreate(id.parent());
  return subdivide(parent) + id.childIndex();
}

glm::dvec3 PatchHierarchy::pointAt(int i, glm::dvec2 uv) const {
  return polygonPointAt(nodes_[i].local, uv);
}

glm::dvec2 PatchHierarchy::uvAt(int i, const glm::dvec3& p) const {
  return polygonUvAt(nodes_[i].local, p);
}

}  // namespace rad
