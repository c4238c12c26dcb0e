// Discontinuity meshing at near contacts (contact_cuts.h).
#include "libcommon/scene/contact_cuts.h"

#include "libcommon/scene/box_tree.h"
#include "libcommon/scene/patch_hierarchy.h"
#include "libcommon/scene/scene.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace rad {

namespace {

using Outline = std::vector<glm::dvec3>;  // a convex polygon, CCW about its plane's normal

double outlineArea(const Outline& p, const glm::dvec3& n) {
  glm::dvec3 s(0.0);
  for (size_t i = 0; i < p.size(); ++i) s += glm::cross(p[i], p[(i + 1) % p.size()]);
  return 0.5 * glm::dot(s, n);
}

// The part of convex p on the side of the line through a along e (in the plane of normal n)
// where sign * dot(cross(e, x - a), n) >= 0 (Sutherland-Hodgman against one half-plane).
Outline clipHalfPlane(const Outline& p, const glm::dvec3& a, const glm::dvec3& e,
                      const glm::dvec3& n, double sign) {
  Outline out;
  const size_t m = p.size();
  for (size_t i = 0; i < m; ++i) {
    const glm::dvec3& x = p[i];
    const glm::dvec3& y = p[(i + 1) % m];
    const double sx = sign * glm::dot(glm::cross(e, x - a), n);
    const double sy = sign * glm::dot(glm::cross(e, y - a), n);
    if (sx >= 0.0) out.push_back(x);
    if ((sx >= 0.0) != (sy >= 0.0)) out.push_back(x + (y - x) * (sx / (sx - sy)));
  }
  return out;
}

// Drops vertices within tol of their predecessor (a cut through a vertex repeats it) and
// vertices on the straight line of their neighbours (a quad must have four corners).
Outline dedupe(const Outline& p, double tol, const glm::dvec3& n) {
  Outline out;
  for (const glm::dvec3& x : p)
    if (out.empty() || glm::length(x - out.back()) > tol) out.push_back(x);
  while (out.size() > 1 && glm::length(out.front() - out.back()) <= tol) out.pop_back();
  for (bool again = true; again && out.size() > 3;) {
    again = false;
    for (size_t i = 0; i < out.size(); ++i) {
      const glm::dvec3& a = out[(i + out.size() - 1) % out.size()];
      const glm::dvec3& c = out[(i + 1) % out.size()];
      if (std::abs(glm::dot(glm::cross(out[i] - a, c - out[i]), n)) <= tol * glm::length(c - a)) {
        out.erase(out.begin() + long(i));
        again = true;
        break;
      }
    }
  }
  return out;
}

// The outline with every edge moved outwards by r (inwards for r < 0), in the plane of normal n;
// empty when an edge would turn over (the outline is narrower than 2 |r|).
Outline offsetOutline(const Outline& a, double r, const glm::dvec3& n) {
  const size_t m = a.size();
  std::vector<glm::dvec3> origin(m), dir(m);
  for (size_t k = 0; k < m; ++k) {
    dir[k] = a[(k + 1) % m] - a[k];
    origin[k] = a[k] + r * glm::normalize(glm::cross(dir[k], n));  // right of a CCW edge: out
  }
  Outline out(m);
  for (size_t k = 0; k < m; ++k) {  // vertex k: edges k - 1 and k meet
    const size_t j = (k + m - 1) % m;
    const double den = glm::dot(glm::cross(dir[j], dir[k]), n);
    if (!(std::abs(den) > 0.0)) return {};
    out[k] = origin[j] + dir[j] * (glm::dot(glm::cross(origin[k] - origin[j], dir[k]), n) / den);
  }
  for (size_t k = 0; k < m; ++k)
    if (glm::dot(out[(k + 1) % m] - out[k], dir[k]) <= 0.0) return {};
  return out;
}

// Cuts every piece that the outline a (convex, CCW about n) partly covers into the piece under
// a and, per edge k of a, the piece outside edge k and inside edge k + 1: a pinwheel of convex
// pieces that each reach the old piece's boundary (no sliver along a's edge lines). Pieces a does
// not partly cover stay. Returns whether any piece was cut.
bool pinwheel(std::vector<Outline>& pieces, const Outline& a, const glm::dvec3& n, double tol,
              double minArea) {
  bool cut = false;
  std::vector<Outline> next;
  for (const Outline& piece : pieces) {
    Outline inside = piece;
    for (size_t k = 0; k < a.size() && inside.size() >= 3; ++k)
      inside = clipHalfPlane(inside, a[k], a[(k + 1) % a.size()] - a[k], n, 1.0);
    inside = dedupe(inside, tol, n);
    const double pieceArea = outlineArea(piece, n);
    const double insideArea = inside.size() >= 3 ? outlineArea(inside, n) : 0.0;
    if (insideArea <= minArea || insideArea >= pieceArea - minArea) {
      next.push_back(piece);
      continue;
    }
    next.push_back(inside);
    for (size_t k = 0; k < a.size(); ++k) {
      const size_t k1 = (k + 1) % a.size(), k2 = (k + 2) % a.size();
      Outline w = clipHalfPlane(piece, a[k], a[k1] - a[k], n, -1.0);
      if (w.size() >= 3) w = clipHalfPlane(w, a[k1], a[k2] - a[k1], n, 1.0);
      w = dedupe(w, tol, n);
      if (w.size() >= 3 && outlineArea(w, n) > minArea) next.push_back(w);
    }
    cut = true;
  }
  pieces.swap(next);
  return cut;
}

// uv and shading normal of `source` at point x of its plane, as the rest of the toolchain
// interpolates them: at x's (u,v) in the polygon's own map (polygonUvAt), the texture coordinates
// like points (polygonPointAt) and the normals by shadingNormalAt; a flat source stays flat.
void attributesAt(const InputPolygon& source, const glm::dvec3& x, glm::dvec2& uv,
                  glm::dvec3& normal) {
  const glm::dvec2 at = polygonUvAt(source.local, x);
  Polygon uvs;
  uvs.count = source.local.count;
  for (int k = 0; k < uvs.count; ++k) uvs.v[size_t(k)] = glm::dvec3(source.uv[size_t(k)], 0.0);
  uv = glm::dvec2(polygonPointAt(uvs, at));
  normal = source.normal[0] == glm::dvec3(0.0) ? glm::dvec3(0.0) : shadingNormalAt(source, at);
}

// Whether quad (a, b, c, d) is a parallelogram to 5 % of its longest edge (its diagonals' midpoints
// that close), the rule of Scene::inputPolygons' merge: only then is its bilinear (u,v) map, by
// which the texels are placed and rad-compose looks them up, the plane homography by which the
// shadow masks are rendered (transmittance.h) to second order in the departure. A trapezoid cut
// from a triangle had its masks taken at the homography's points, which crowd towards its short
// edge: the bathroom countertop's quads cut along the backsplash (an edge of 1 cm against one of
// 18 cm) took the shadow of the mirror cabinet behind them over whole triangles (docs/results.md,
// "Contact cuts made trapezoids"; issue 56 found the same for trapezoids merged from a fan).
bool parallelogram(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                   const glm::dvec3& d) {
  const double scale =
      std::max({glm::length(b - a), glm::length(c - b), glm::length(d - c), glm::length(a - d)});
  return glm::length((a + c) - (b + d)) <= 0.05 * scale;
}

// Piece `corners` (indices into `piece`, CCW) as one polygon of source. A triangle starts at its
// corner opposite the longest edge, as Scene::inputPolygons roots every triangle (docs/design.md
// §4: its texel grid runs along the two edges of its widest corner).
void emitPolygon(const InputPolygon& source, const Outline& piece, std::array<size_t, 4> corners,
                 int count, std::vector<InputPolygon>& out) {
  if (count == 3) {
    int root = 0;
    double longest = -1.0;
    for (int k = 0; k < 3; ++k) {
      const double opposite =
          glm::length(piece[corners[size_t((k + 2) % 3)]] - piece[corners[size_t((k + 1) % 3)]]);
      if (opposite > longest * (1.0 + 1e-9)) longest = opposite, root = k;
    }
    std::rotate(corners.begin(), corners.begin() + root, corners.begin() + 3);
  }
  InputPolygon q = source;
  q.local.count = count;
  q.local.v = {};
  q.uv = {};
  q.normal = {};
  for (int k = 0; k < count; ++k) {
    const glm::dvec3& x = piece[corners[size_t(k)]];
    q.local.v[size_t(k)] = x;
    attributesAt(source, x, q.uv[size_t(k)], q.normal[size_t(k)]);
  }
  out.push_back(q);
}

// A convex piece of `source` as quads and at most one triangle: (0,1,2,3), (0,3,4,5), ...; a quad
// that is not a parallelogram as two triangles split along its shorter diagonal.
void emitPiece(const InputPolygon& source, const Outline& piece, std::vector<InputPolygon>& out) {
  for (size_t first = 1; first + 1 < piece.size();) {
    const size_t count = std::min<size_t>(3, piece.size() - first);  // vertices after v0
    const size_t b = first, c = first + 1, d = first + 2;
    if (count < 3) {
      emitPolygon(source, piece, {0, b, c, 0}, 3, out);
      break;
    }
    if (parallelogram(piece[0], piece[b], piece[c], piece[d])) {
      emitPolygon(source, piece, {0, b, c, d}, 4, out);
    } else if (glm::length(piece[c] - piece[0]) <= glm::length(piece[d] - piece[b])) {
      emitPolygon(source, piece, {0, b, c, 0}, 3, out);
      emitPolygon(source, piece, {0, c, d, 0}, 3, out);
    } else {
      emitPolygon(source, piece, {0, b, d, 0}, 3, out);
      emitPolygon(source, piece, {b, c, d, 0}, 3, out);
    }
    first += count - 1;
  }
}

struct Placed {
  bool still = false;  // its node does not move over the scene's time
  Polygon world;
  glm::dvec3 normal{0.0};
  double size = 0.0;  // longest edge
  AxisBox bounds{glm::dvec3(1.0), glm::dvec3(-1.0)};
};

}  // namespace

std::vector<InputPolygon> cutAtContacts(const Scene& scene, std::vector<InputPolygon> polygons) {
  const double t0 = scene.startTime(), t1 = scene.endTime();
  // Per mesh node, once: whether it stays still, and where.
  std::vector<int> still(scene.nodes.size(), -1);
  std::vector<glm::dmat4> toWorld(scene.nodes.size());
  std::vector<Placed> placed(polygons.size());
  std::vector<AxisBox> reach(polygons.size(), AxisBox{glm::dvec3(1.0), glm::dvec3(-1.0)});
  for (size_t i = 0; i < polygons.size(); ++i) {
    const size_t node = size_t(polygons[i].node);
    if (still[node] < 0) {
      still[node] = !scene.isDynamic(int(node), t0, t1);
      if (still[node]) toWorld[node] = scene.worldTransform(int(node), t0);
    }
    Placed& p = placed[i];
    p.still = still[node];
    if (!p.still) continue;
    p.world = polygons[i].local.transformed(toWorld[node]);
    p.normal = p.world.normal();
    if (p.normal == glm::dvec3(0.0)) {
      p.still = false;  // degenerate: cuts nothing, is cut by nothing
      continue;
    }
    p.bounds = {p.world.v[0], p.world.v[0]};
    for (int k = 0; k < p.world.count; ++k) {
      const glm::dvec3& v = p.world.v[size_t(k)];
      p.size = std::max(p.size, glm::length(p.world.v[size_t((k + 1) % p.world.count)] - v));
      p.bounds = {glm::min(p.bounds[0], v), glm::max(p.bounds[1], v)};
    }
    // A's reach: its bounds grown by the gap it may have to a polygon it cuts, or by its rim.
    const glm::dvec3 grow(std::max(1.0, kRimGaps) * kContactGap * p.size);
    reach[i] = {p.bounds[0] - grow, p.bounds[1] + grow};
  }
  const BoxTree tree(reach);

  std::vector<InputPolygon> out;
  out.reserve(polygons.size());
  std::vector<int> near;
  for (size_t bi = 0; bi < polygons.size(); ++bi) {
    const Placed& B = placed[bi];
    if (!B.still) {
      out.push_back(polygons[bi]);
      continue;
    }
    near.clear();
    tree.query(B.bounds[0], B.bounds[1], near);
    const double tol = 1e-9 * B.size;
    const double minArea = 1e-9 * B.world.area();
    std::vector<Outline> pieces{Outline(B.world.v.begin(), B.world.v.begin() + B.world.count)};
    bool cut = false;
    for (int ai : near) {
      const Placed& A = placed[size_t(ai)];
      if (size_t(ai) == bi || !A.still) continue;
      const double facing = glm::dot(A.normal, B.normal);
      if (std::abs(facing) < std::cos(1e-3)) continue;  // not parallel (1 mrad)
      // A's height above B's plane, every vertex in front and within the gap.
      double lo = INFINITY, hi = -INFINITY;
      for (int k = 0; k < A.world.count; ++k) {
        const double h = glm::dot(A.world.v[size_t(k)] - B.world.v[0], B.normal);
        lo = std::min(lo, h);
        hi = std::max(hi, h);
      }
      // A gap there must be: a polygon lying on B (a box's bottom on a floor, a partition's top
      // against a ceiling) hides what it covers, which rad-global's exposure and rad-movies'
      // covered texels already leave out; cutting B there too only adds patches, and error.
      if (lo < -tol || hi <= tol || hi > kContactGap * A.size) continue;
      // A's outline on B's plane, CCW about B's normal.
      Outline a;
      for (int k = 0; k < A.world.count; ++k) {
        const glm::dvec3 x = A.world.v[size_t(k)];
        a.push_back(x - glm::dot(x - B.world.v[0], B.normal) * B.normal);
      }
      if (facing < 0.0) std::reverse(a.begin(), a.end());
      // A gap makes B's radiosity fall towards the outline over a few gaps on either side: a point
      // d from a long edge loses (1 - a / sqrt(1 + a^2)) / 2 of its cosine hemisphere to A, a = d /
      // gap (50 % at the edge, 15 % at 1 gap, 5 % at 2, 1.5 % at 4). Rims 2 gaps wide outside and
      // inside the outline are pieces of their own, whose movies resolve that fall.
      const double rim = kRimGaps * hi;
      std::vector<Outline> outlines{a};
      if (rim > tol) {
        outlines.insert(outlines.begin(), offsetOutline(a, rim, B.normal));
        Outline inner = offsetOutline(a, -rim, B.normal);
        if (!inner.empty()) outlines.push_back(inner);
      }
      for (const Outline& o : outlines) cut = pinwheel(pieces, o, B.normal, tol, minArea) || cut;
    }
    if (!cut) {
      out.push_back(polygons[bi]);
      continue;
    }
    // Back to B's local frame, where its attributes are defined.
    const glm::dmat4 toLocal = glm::inverse(toWorld[size_t(polygons[bi].node)]);
    for (Outline& piece : pieces) {
      for (glm::dvec3& x : piece) x = glm::dvec3(toLocal * glm::dvec4(x, 1.0));
      emitPiece(polygons[bi], piece, out);
    }
  }
  return out;
}

}  // namespace rad
