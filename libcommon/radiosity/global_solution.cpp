// Queries on the space-time global solution (paper §3.1: the second pass interpolates the
// good-link irradiance over each patch and adds the bad links' shadows per texel).
#include "libcommon/radiosity/global_solution.h"

#include <algorithm>
#include <cmath>

#include "libcommon/core/error.h"

namespace rad {

namespace {

// Child k's (u,v) square/half-square mapped into its parent's: parent = o + a * uv.x + b * uv.y.
struct ChildMap {
  glm::dvec2 o, a, b;
};

ChildMap childMap(int k, bool triangle) {
  if (!triangle) {
    static const glm::dvec2 origin[4] = {{0, 0}, {0.5, 0}, {0.5, 0.5}, {0, 0.5}};
    return {origin[k], {0.5, 0}, {0, 0.5}};
  }
  switch (k) {
    case 0:
      return {{0, 0}, {0.5, 0}, {0, 0.5}};
    case 1:
      return {{0.5, 0}, {0.5, 0}, {0, 0.5}};
    case 2:
      return {{0, 0.5}, {0.5, 0}, {0, 0.5}};
    default:
      return {{0.5, 0.5}, {-0.5, 0}, {0, -0.5}};
  }
}

// Which child of a node contains the node-local point uv.
int childContaining(glm::dvec2 uv, bool triangle) {
  if (!triangle) return uv.y < 0.5 ? (uv.x < 0.5 ? 0 : 1) : (uv.x < 0.5 ? 3 : 2);
  if (uv.x >= 0.5) return 1;
  if (uv.y >= 0.5) return 2;
  if (uv.x + uv.y <= 0.5) return 0;
  return 3;
}

}  // namespace

glm::dvec2 clampToParameterDomain(glm::dvec2 uv, bool triangle) {
  uv = glm::clamp(uv, glm::dvec2(0.0), glm::dvec2(1.0));
  if (triangle && uv.x + uv.y > 1.0) {
    double excess = 0.5 * (uv.x + uv.y - 1.0);
    uv = glm::clamp(uv - excess, glm::dvec2(0.0), glm::dvec2(1.0));
  }
  return uv;
}

int descendToChild(glm::dvec2& uv, bool triangle) {
  int k = childContaining(uv, triangle);
  ChildMap m = childMap(k, triangle);
  glm::dvec2 d = uv - m.o;
  uv = clampToParameterDomain({d.x / m.a.x, d.y / m.b.y}, triangle);
  return k;
}

glm::dvec2 topUvFromNodeUv(PatchId node, glm::dvec2 uv, bool triangle) {
  for (int l = node.level(); l > 0; --l) {
    ChildMap m = childMap(node.childIndex(), triangle);
    uv = m.o + m.a * uv.x + m.b * uv.y;
    node = node.parent();
  }
  return uv;
}

glm::dvec2 nodeUvFromTopUv(PatchId node, glm::dvec2 uv, bool triangle) {
  // Walk down from the top: invert each child map (all are axis-aligned scalings/flips).
  std::vector<int> path;
  for (PatchId n = node; n.level() > 0; n = n.parent()) path.push_back(n.childIndex());
  for (auto it = path.rbegin(); it != path.rend(); ++it) {
    ChildMap m = childMap(*it, triangle);
    glm::dvec2 d = uv - m.o;
    uv = {d.x / m.a.x, d.y / m.b.y};
  }
  return uv;
}

int leafAtTopUv(const PatchHierarchy& h, int top, glm::dvec2 uv) {
  bool triangle = h.top(top).local.count == 3;
  uv = clampToParameterDomain(uv, triangle);
  int i = top;
  while (!h.isLeaf(i)) i = h.node(i).firstChild + descendToChild(uv, triangle);
  return i;
}

void GlobalSolution::keyWeights(double t, int& k0, int& k1, double& w) const {
  int K = keyCount();
  if (K == 0) throw Error(ExitCode::kInternal, "", "global solution without key times");
  if (t <= keyTimes.front()) {
    k0 = k1 = 0;
    w = 0.0;
    return;
  }
  if (t >= keyTimes.back()) {
    k0 = k1 = K - 1;
    w = 0.0;
    return;
  }
  k1 = int(std::upper_bound(keyTimes.begin(), keyTimes.end(), t) - keyTimes.begin());
  k0 = k1 - 1;
  w = (t - keyTimes[k0]) / (keyTimes[k1] - keyTimes[k0]);
}

glm::dvec3 GlobalSolution::exposedRadiosityAtKey(int node, int key) const {
  int n = node;
  while (!(exposureAtKey(n, key) > 0.0) && hierarchy.node(n).parent >= 0)
    n = hierarchy.node(n).parent;
  return radiosityAtKey(exposureAtKey(n, key) > 0.0 ? n : node, key);
}

glm::dvec3 GlobalSolution::radiosity(int node, double t) const {
  int k0, k1;
  double w;
  keyWeights(t, k0, k1, w);
  return (1.0 - w) * radiosityAtKey(node, k0) + w * radiosityAtKey(node, k1);
}

glm::dvec3 GlobalSolution::goodIrradianceAtKey(int top, glm::dvec2 uv, int key) const {
  int leaf = leafAtTopUv(hierarchy, top, uv);
  int row = leafRow[leaf];
  if (row < 0) return glm::dvec3(0.0);
  bool triangle = hierarchy.node(leaf).local.count == 3;
  glm::dvec2 l =
      clampToParameterDomain(nodeUvFromTopUv(hierarchy.node(leaf).id, uv, triangle), triangle);
  const glm::vec3* c = &leafVertexGoodIrradiance[(size_t(row) * keyCount() + key) * 4];
  if (triangle)
    return (1.0 - l.x - l.y) * glm::dvec3(c[0]) + l.x * glm::dvec3(c[1]) + l.y * glm::dvec3(c[2]);
  return (1.0 - l.x) * (1.0 - l.y) * glm::dvec3(c[0]) + l.x * (1.0 - l.y) * glm::dvec3(c[1]) +
         l.x * l.y * glm::dvec3(c[2]) + (1.0 - l.x) * l.y * glm::dvec3(c[3]);
}

glm::dvec3 GlobalSolution::goodIrradiance(int top, glm::dvec2 uv, double t) const {
  int k0, k1;
  double w;
  keyWeights(t, k0, k1, w);
  glm::dvec3 a = goodIrradianceAtKey(top, uv, k0);
  if (k1 == k0 || w == 0.0) return a;
  return (1.0 - w) * a + w * goodIrradianceAtKey(top, uv, k1);
}

glm::dvec3 GlobalSolution::clusterIrradiance(int top, double t) const {
  if (topClusterIrradiance.empty()) return glm::dvec3(0.0);
  int k0, k1;
  double w;
  keyWeights(t, k0, k1, w);
  glm::dvec3 a = clusterIrradianceAtKey(top, k0);
  if (k1 == k0 || w == 0.0) return a;
  return (1.0 - w) * a + w * clusterIrradianceAtKey(top, k1);
}

namespace {
// A row's samples (keys[0..n), values) at key k: piecewise linear, held outside.
double sampleAtKey(const uint32_t* keys, const float* values, uint32_t n, int key) {
  if (key <= int(keys[0])) return values[0];
  if (key >= int(keys[n - 1])) return values[n - 1];
  const uint32_t j = uint32_t(std::upper_bound(keys, keys + n, uint32_t(key)) - keys);
  const double w = double(key - int(keys[j - 1])) / double(keys[j] - keys[j - 1]);
  return (1.0 - w) * values[j - 1] + w * values[j];
}
}  // namespace

double GlobalSolution::linkFvAtKey(const GlobalLink& l, int key) const {
  if (!linkActiveAtKey(l, key)) return 0.0;
  return sampleAtKey(&linkSampleKeys[l.sampleOffset], &linkSampleValues[l.sampleOffset],
                     l.sampleCount, key);
}

double GlobalSolution::linkVisibilityAtKey(const GlobalLink& l, int key) const {
  if (linkSampleVisibility.empty()) return 1.0;
  if (!linkActiveAtKey(l, key)) return 0.0;
  return sampleAtKey(&linkSampleKeys[l.sampleOffset], &linkSampleVisibility[l.sampleOffset],
                     l.sampleCount, key);
}

std::vector<uint32_t> GlobalSolution::badShooters(uint32_t receiverTop) const {
  std::vector<uint32_t> out;
  auto it = std::lower_bound(badPairs.begin(), badPairs.end(), std::make_pair(receiverTop, 0u));
  for (; it != badPairs.end() && it->first == receiverTop; ++it) out.push_back(it->second);
  return out;
}

bool GlobalSolution::isBadPair(uint32_t receiverTop, uint32_t shooterTop) const {
  return std::binary_search(badPairs.begin(), badPairs.end(),
                            std::make_pair(receiverTop, shooterTop));
}

void GlobalSolution::validateRadiosity(const std::string& where) const {
  auto bad = [&](const std::string& what) { throw inputError(where, what); };
  size_t K = keyTimes.size(), N = size_t(hierarchy.size());
  if (K == 0) bad("no key times");
  for (size_t k = 1; k < K; ++k)
    if (!(keyTimes[k] > keyTimes[k - 1])) bad("key times are not strictly increasing");
  for (double t : keyTimes)
    if (!std::isfinite(t)) bad("key time is not finite");
  if (nodeRadiosity.size() != N * K) bad("node radiosity has the wrong size");
  if (leafRow.size() != N) bad("leaf rows have the wrong size");
  size_t leaves = 0;
  for (size_t i = 0; i < N; ++i) {
    if (leafRow[i] >= 0) {
      if (!hierarchy.isLeaf(int(i))) bad("interior node has a leaf row");
      if (size_t(leafRow[i]) != leaves) bad("leaf rows are not consecutive");
      ++leaves;
    } else if (hierarchy.isLeaf(int(i))) {
      bad("leaf node without a leaf row");
    }
  }
  if (!nodeExposure.empty()) {
    if (nodeExposure.size() != size_t(hierarchy.size()) * keyTimes.size())
      bad("node_exposure has the wrong size");
    for (float e : nodeExposure)
      if (!(e >= 0.0f && e <= 1.0f)) bad("node exposure outside [0, 1]");
  }
}

void GlobalSolution::validate(const std::string& where) const {
  validateRadiosity(where);
  auto bad = [&](const std::string& what) { throw inputError(where, what); };
  size_t K = keyTimes.size(), N = size_t(hierarchy.size());
  size_t leaves = 0;
  for (int32_t row : leafRow) leaves += row >= 0;
  if (leafVertexGoodIrradiance.size() != leaves * K * 4) bad("leaf irradiance has the wrong size");
  if (linkSampleKeys.size() != linkSampleValues.size()) bad("link sample arrays differ in size");
  if (!linkSampleVisibility.empty()) {
    if (linkSampleVisibility.size() != linkSampleKeys.size())
      bad("link_sample_visibility has the wrong size");
    for (float v : linkSampleVisibility)
      if (!(v >= 0.0f && v <= 1.0f)) bad("link visibility outside [0, 1]");
  }
  for (const GlobalLink& l : links) {
    if (l.receiver >= N || l.shooter >= N) bad("link names a node out of range");
    if (l.firstKey > l.lastKey || l.lastKey >= K) bad("link interval out of range");
    if (l.sampleCount == 0 || uint64_t(l.sampleOffset) + l.sampleCount > linkSampleKeys.size())
      bad("link samples out of range");
  }
  for (uint32_t k : linkSampleKeys)
    if (k >= K) bad("link sample key out of range");
  for (size_t i = 0; i < badPairs.size(); ++i) {
    if (badPairs[i].first >= uint32_t(hierarchy.topCount()) ||
        badPairs[i].second >= uint32_t(hierarchy.topCount()))
      bad("bad pair names a top-level patch out of range");
    if (i && !(badPairs[i - 1] < badPairs[i])) bad("bad pairs are not sorted and unique");
  }
  if (!topClusterIrradiance.empty()) {
    if (topClusterIrradiance.size() != size_t(hierarchy.topCount()) * K)
      bad("top_cluster_irradiance has the wrong size");
    for (const glm::vec3& h : topClusterIrradiance)
      for (int c = 0; c < 3; ++c)
        if (!(std::isfinite(h[c]) && h[c] >= 0.0f))
          bad("top cluster irradiance is negative or not finite");
  }
}

}  // namespace rad
