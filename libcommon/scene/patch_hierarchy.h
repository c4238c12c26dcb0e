// The patch hierarchy: top-level patches (input polygons) and their 4-way regular
// subdivisions (Hanrahan, Salzman, Aupperle 1991, §3: a quadtree per input polygon).
//
// Every node has a stable id made of its top-level index and its quadtree path, so the same
// patch gets the same id whatever order the hierarchy was refined in; dense node indices are
// only handles into this object.
//
// Geometry stays in the owning mesh node's local frame (see scene.h), so a node's motion (rigid,
// or affine with an animated scale) moves a patch without changing its id or its texture
// parameterisation (an affine map keeps the (u,v) maps and parallelograms).
#pragma once

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "libcommon/scene/geometry.h"
#include "libcommon/scene/scene.h"

namespace rad {

// Stable patch id: top-level index + quadtree path. The path is a leading 1 bit followed by two
// bits per level (child 0..3), so the root's path is 1 and the level is (bit width - 1) / 2.
struct PatchId {
  static constexpr int kMaxLevel = 15;
  uint32_t top = 0;
  uint32_t path = 1;

  int level() const;           // -1 for path 0, which names no patch
  PatchId child(int k) const;  // k in 0..3; level must be < kMaxLevel
  PatchId parent() const;      // level must be > 0
  int childIndex() const;      // which child of its parent (level > 0)
  uint64_t packed() const { return (uint64_t(top) << 32) | path; }
  static PatchId fromPacked(uint64_t v) { return {uint32_t(v >> 32), uint32_t(v & 0xffffffffu)}; }
  bool operator==(const PatchId& o) const { return top == o.top && path == o.path; }
  bool operator!=(const PatchId& o) const { return !(*this == o); }
  // "12/0.3.1": top-level index, then the child index at each level.
  std::string toString() const;
};

struct PatchNode {
  PatchId id;
  int parent = -1;      // dense index, -1 for a top-level patch
  int firstChild = -1;  // dense index of child 0; children are contiguous; -1 for a leaf
  Polygon local;        // in the owning mesh node's frame
};

class PatchHierarchy {
 public:
  PatchHierarchy() = default;
  explicit PatchHierarchy(std::vector<InputPolygon> tops);

  int topCount() const { return int(tops_.size()); }
  const InputPolygon& top(int topIndex) const { return tops_[topIndex]; }
  const std::vector<InputPolygon>& tops() const { return tops_; }
  // Dense node index of top-level patch t is t.
  int size() const { return int(nodes_.size()); }
  const PatchNode& node(int i) const { return nodes_[i]; }
  const InputPolygon& topOf(int i) const { return tops_[nodes_[i].id.top]; }
  bool isLeaf(int i) const { return nodes_[i].firstChild < 0; }

  // Splits node i into 4 children (quads: at edge midpoints and the bilinear centre;
  // triangles: at edge midpoints, the centre child inverted) and returns the first child's
  // dense index; returns the existing first child if already split.
  int subdivide(int i);
  // Room for n nodes in all, so that a caller that knows its final size (rad-intervals' full
  // subdivision) does not hold the growing array twice while it is copied.
  void reserve(size_t n) { nodes_.reserve(n); }
  // Dense index of the node with this id, or -1 when that node does not exist (yet).
  int find(PatchId id) const;
  // Creates the node with this id and its ancestors' siblings as needed; returns its index.
  int findOrCreate(PatchId id);

  // The texture parameterisation of a node: quads map (u,v) in [0,1]^2 bilinearly onto the
  // corners v0 (0,0), v1 (1,0), v2 (1,1), v3 (0,1); triangles map the half square u+v <= 1
  // affinely onto v0 (0,0), v1 (1,0), v2 (0,1). Points outside extend the same map over the
  // polygon's plane (a texel centre just outside a triangle's long edge still gets a value).
  glm::dvec3 pointAt(int i, glm::dvec2 uv) const;
  // Inverse of pointAt for a point in (or projected onto) the node's plane.
  glm::dvec2 uvAt(int i, const glm::dvec3& p) const;

 private:
  std::vector<InputPolygon> tops_;
  std::vector<PatchNode> nodes_;
  std::unordered_map<uint64_t, int> index_;
};

// The (u,v) map of a single polygon (see PatchHierarchy::pointAt).
glm::dvec3 polygonPointAt(const Polygon& p, glm::dvec2 uv);
glm::dvec2 polygonUvAt(const Polygon& p, const glm::dvec3& x);

// polygonUvAt for many points of one polygon, set up once (rad-compose inverts the map at every
// pixel). Triangles and parallelograms (the bilinear map is then affine) take two dot products
// with the rows of the affine inverse; other quads refine the affine guess by Newton's method.
class PolygonUvMap {
 public:
  PolygonUvMap() = default;
  explicit PolygonUvMap(const Polygon& p);
  glm::dvec2 uvAt(const glm::dvec3& x) const;

 private:
  Polygon p_;
  bool valid_ = false;   // non-degenerate: the Gram determinant of the edges is > 0
  bool affine_ = false;  // triangle, or a quad with v0 + v2 = v1 + v3 (to 1e-12 of its size)
  glm::dvec3 gradU_{0.0}, gradV_{0.0};  // rows of the affine inverse: u = gradU . (x - v0)
  glm::dvec3 d10_{0.0}, d23_{0.0}, d30_{0.0}, d21_{0.0};  // quad edges of the Newton Jacobian
};

// The 4 children of a polygon in child order (see PatchHierarchy::subdivide).
std::array<Polygon, 4> subdividePolygon(const Polygon& p);

}  // namespace rad
