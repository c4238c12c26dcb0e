// The conforming vertex mesh over the union leaves; see leaf_vertices.h.
#include "libcommon/radiosity/leaf_vertices.h"

#include <algorithm>
#include <map>
#include <utility>

#include <glm/glm.hpp>

#include "libcommon/radiosity/global_solution.h"

namespace rad {

namespace {

// The corners of a leaf in its top-level patch's (u,v).
std::array<glm::dvec2, 4> leafCornersUv(const PatchNode& n) {
  const bool tri = n.local.count == 3;
  const glm::dvec2 corners[4] = {{0, 0}, {1, 0}, tri ? glm::dvec2(0, 1) : glm::dvec2(1, 1), {0, 1}};
  std::array<glm::dvec2, 4> uv;
  for (int c = 0; c < 4; ++c) uv[size_t(c)] = topUvFromNodeUv(n.id, corners[c], tri);
  return uv;
}

// Union-find over vertex indices (merging vertices of different top-level patches).
int findRoot(std::vector<int>& parent, int v) {
  while (parent[size_t(v)] != v) v = parent[size_t(v)] = parent[size_t(parent[size_t(v)])];
  return v;
}

// Per top-level patch its vertices by exact (u,v), then the ones of coplanar patches of the same
// mesh node at the same point merged; returns the vertex index of each (top, u, v) key.
std::vector<std::map<std::pair<double, double>, int>> patchVertices(const PatchHierarchy& h,
                                                                    const std::vector<int>& leaves,
                                                                    int& vertexTotal) {
  std::vector<std::map<std::pair<double, double>, int>> perTop(size_t(h.topCount()));
  std::vector<std::pair<int, glm::dvec2>> at;  // per vertex: (top, uv)
  for (int leaf : leaves) {
    const PatchNode& n = h.node(leaf);
    const std::array<glm::dvec2, 4> uv = leafCornersUv(n);
    for (int c = 0; c < (n.local.count == 3 ? 3 : 4); ++c) {
      auto [it, fresh] = perTop[n.id.top].emplace(std::make_pair(uv[size_t(c)].x, uv[size_t(c)].y),
                                                  int(at.size()));
      if (fresh) at.emplace_back(int(n.id.top), uv[size_t(c)]);
    }
  }
  // Merge across patches: the key is the mesh node, the plane's normal and the point, rounded
  // to 1e-9 of the largest patch (both patches compute the point in the same local frame).
  double size = 0;
  for (int t = 0; t < h.topCount(); ++t)
    for (int k = 1; k < h.top(t).local.count; ++k)
      size = std::max(size, glm::length(h.top(t).local.v[size_t(k)] - h.top(t).local.v[0]));
  const double q = size > 0 ? 1e-9 * size : 1.0;
  std::map<std::array<long long, 7>, int> byPoint;
  std::vector<int> parent(at.size());
  for (size_t v = 0; v < at.size(); ++v) {
    parent[v] = int(v);
    const InputPolygon& top = h.top(at[v].first);
    const glm::dvec2 uv = at[v].second;
    const glm::dvec3 p = polygonPointAt(top.local, uv);
    const glm::dvec3 nrm = top.local.normal();
    const std::array<long long, 7> key = {top.node,
                                          std::llround(p.x / q),
                                          std::llround(p.y / q),
                                          std::llround(p.z / q),
                                          std::llround(nrm.x * 1e6),
                                          std::llround(nrm.y * 1e6),
                                          std::llround(nrm.z * 1e6)};
    auto [it, fresh] = byPoint.emplace(key, int(v));
    if (!fresh) parent[v] = findRoot(parent, it->second);
  }
  // Dense indices of the merged vertices.
  std::vector<int> dense(at.size(), -1);
  vertexTotal = 0;
  for (size_t v = 0; v < at.size(); ++v) {
    int r = findRoot(parent, int(v));
    if (dense[size_t(r)] < 0) dense[size_t(r)] = vertexTotal++;
    dense[v] = dense[size_t(r)];
  }
  for (auto& m : perTop)
    for (auto& [uv, v] : m) v = dense[size_t(v)];
  return perTop;
}

// The T-vertex constraints of one top-level patch: its leaves coarse first, each edge's inner
// vertices (on the same u, v or u + v line strictly between the ends).
void addTVertexConstraints(const PatchHierarchy& h, std::vector<int> leaves,
                           const std::map<std::pair<double, double>, int>& vertexOf,
                           std::vector<LeafVertices::Constraint>& out) {
  std::stable_sort(leaves.begin(), leaves.end(),
                   [&](int a, int b) { return h.node(a).id.level() < h.node(b).id.level(); });
  std::map<double, std::vector<std::pair<double, int>>> onU, onV, onDiagonal;  // line -> (pos, v)
  for (const auto& [uv, v] : vertexOf) {
    onU[uv.first].emplace_back(uv.second, v);
    onV[uv.second].emplace_back(uv.first, v);
    onDiagonal[uv.first + uv.second].emplace_back(uv.first, v);
  }
  for (auto* m : {&onU, &onV, &onDiagonal})
    for (auto& [line, list] : *m) std::sort(list.begin(), list.end());
  for (int leaf : leaves) {
    const PatchNode& n = h.node(leaf);
    const std::array<glm::dvec2, 4> uv = leafCornersUv(n);
    const int corners = n.local.count == 3 ? 3 : 4;
    for (int c = 0; c < corners; ++c) {
      const glm::dvec2 a = uv[size_t(c)], b = uv[size_t((c + 1) % corners)];
      const std::vector<std::pair<double, int>>* list = nullptr;
      double from, to;
      if (a.x == b.x) {
        auto it = onU.find(a.x);
        list = it == onU.end() ? nullptr : &it->second;
        from = a.y, to = b.y;
      } else if (a.y == b.y) {
        auto it = onV.find(a.y);
        list = it == onV.end() ? nullptr : &it->second;
        from = a.x, to = b.x;
      } else {
        auto it = onDiagonal.find(a.x + a.y);
        list = it == onDiagonal.end() ? nullptr : &it->second;
        from = a.x, to = b.x;
      }
      if (!list) continue;
      const int va = vertexOf.at({a.x, a.y}), vb = vertexOf.at({b.x, b.y});
      const double lo = std::min(from, to), hi = std::max(from, to);
      auto it = std::upper_bound(list->begin(), list->end(), std::make_pair(lo, INT32_MAX));
      for (; it != list->end() && it->first < hi; ++it)
        out.push_back({it->second, va, vb, (it->first - from) / (to - from)});
    }
  }
}

}  // namespace

LeafVertices leafVerticesOf(const PatchHierarchy& h, const std::vector<int>& leaves) {
  LeafVertices out;
  int total = 0;
  const std::vector<std::map<std::pair<double, double>, int>> perTop =
      patchVertices(h, leaves, total);
  out.vertexCount.assign(size_t(total), 0);
  out.leafVertex.resize(leaves.size());
  std::vector<std::vector<int>> leavesOfTop(size_t(h.topCount()));
  for (size_t li = 0; li < leaves.size(); ++li) {
    const PatchNode& n = h.node(leaves[li]);
    leavesOfTop[n.id.top].push_back(leaves[li]);
    const std::array<glm::dvec2, 4> uv = leafCornersUv(n);
    const bool tri = n.local.count == 3;
    for (int c = 0; c < 4; ++c) {
      const glm::dvec2 p = uv[size_t(tri && c == 3 ? 0 : c)];
      const int v = perTop[n.id.top].at({p.x, p.y});
      out.leafVertex[li][size_t(c)] = v;
      if (!(tri && c == 3)) out.vertexCount[size_t(v)]++;
    }
  }
  for (int t = 0; t < h.topCount(); ++t)
    addTVertexConstraints(h, leavesOfTop[size_t(t)], perTop[size_t(t)], out.constraints);
  return out;
}

}  // namespace rad
