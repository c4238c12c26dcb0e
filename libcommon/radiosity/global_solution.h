// The space-time global solution rad-global computes and the second pass reads (paper §3.1,
// §4.2; docs/design.md §6.1): the union over all key times of the patch hierarchy, the links with
// their activity intervals and F·V samples, the radiosity of every node at every key time, and
// what rad-movies needs per receiver: the good-link irradiance as vertex values over the union
// leaves (Gouraud) and the bad (receiver top, shooter top) pairs.
// The light of rad-global's cluster links (above the top-level patches) comes per top:
// topClusterIrradiance.
//
// Good and bad (paper §3.1): a link p <- q is *bad* when the pair (top of p, top of q) is in
// badPairs; everything else is good. The good-link irradiance excludes every link of a bad
// pair at every key time, so  H(x, t) = goodIrradiance(x, t) + sum over bad shooters S of the
// receiver top of  B_S(t) F(x -> S(t)) T(x, S, t)  with nothing counted twice. Cluster light is
// good light: goodIrradiance() includes it.
//
// Times: values are given at key times; between two key times everything is linear in t, and
// before the first / after the last key the end value is held.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/scene/patch_hierarchy.h"

namespace rad {

struct GlobalLink {
  uint32_t receiver = 0;  // dense node index (gathers)
  uint32_t shooter = 0;   // dense node index (shoots)
  uint32_t firstKey = 0;  // activity interval [firstKey, lastKey] in key indices
  uint32_t lastKey = 0;
  uint32_t sampleOffset = 0;  // into linkSampleKeys / linkSampleValues
  uint32_t sampleCount = 0;   // >= 1; a link whose F·V never changes keeps one sample
  uint8_t flags = 0;          // kLinkBad | kLinkVisibilityEvent | kLinkRefined
};
constexpr uint8_t kLinkBad = 1;              // belongs to a bad pair
constexpr uint8_t kLinkVisibilityEvent = 2;  // its F·V changed because visibility changed
constexpr uint8_t kLinkRefined = 4;          // refined (kept for the hierarchy; not gathered)

class GlobalSolution {
 public:
  // --- content (public so the writer and reader are plain; invariants checked by validate())
  std::vector<double> keyTimes;  // K >= 1, strictly increasing, seconds
  // Union hierarchy over all key times: node i has id nodeIds[i]; nodes 0..topCount-1 are the
  // top-level patches in Scene::inputPolygons() order; parents come before children.
  PatchHierarchy hierarchy;
  // Radiosity B (W/m^2, RGB) of node i at key k: nodeRadiosity[i * K + k]. Interior nodes hold
  // the area average of their children (push-pull), so a top's value is its mean radiosity.
  std::vector<glm::vec3> nodeRadiosity;
  // Exposure e of node i at key k (the share of it not covered by a touching surface; rad-global
  // divides the node's gathered irradiance by it): nodeExposure[i * K + k]; empty = every node
  // 1 (files before linkhier 1.2).
  std::vector<float> nodeExposure;
  // Good-link irradiance H_good (W/m^2) at the vertices of every union leaf, per key:
  // leafVertexGoodIrradiance[(leafRow[i] * K + k) * 4 + c] for corner c of node i
  // (triangles use c = 0..2). leafRow[i] = -1 for interior nodes.
  std::vector<int32_t> leafRow;
  std::vector<glm::vec3> leafVertexGoodIrradiance;
  // Links (one row per activity interval) and their F·V samples: piecewise linear in key
  // index through (linkSampleKeys[j], linkSampleValues[j]), held outside.
  std::vector<GlobalLink> links;
  std::vector<uint32_t> linkSampleKeys;
  std::vector<float> linkSampleValues;
  // The visibility V of each sample (kernel-weighted over the pairs of sample points); empty in
  // files before linkhier 1.2.
  std::vector<float> linkSampleVisibility;
  // Bad (receiver top, shooter top) pairs, sorted, unique.
  std::vector<std::pair<uint32_t, uint32_t>> badPairs;
  // Irradiance H_cluster (W/m^2, RGB) that top-level patch t gathers through rad-global's cluster
  // links (Smits et al. 1994; Sillion 1995: links above the top-level patches, not hierarchy
  // nodes) at key k, of its exposed part (the links at the top itself divided by its exposure,
  // those at its ancestor clusters not: their V is the cluster's; 0 for a covered top), uniform
  // over the top and not scaled by any closure factor. Good light: never part of a bad pair.
  // leafVertexGoodIrradiance already includes it; the per-texel gather adds it itself.
  // [T * K]: top t at key k at t * K + k; empty = none (files before linkhier 1.3).
  std::vector<glm::vec3> topClusterIrradiance;

  int keyCount() const { return int(keyTimes.size()); }
  // Fractional key position of time t: k0, k1 and weight w of k1 (held outside the range).
  void keyWeights(double t, int& k0, int& k1, double& w) const;

  // B of node i at time t (linear between keys).
  glm::dvec3 radiosity(int node, double t) const;
  glm::dvec3 radiosityAtKey(int node, int key) const {
    return nodeRadiosity[size_t(node) * keyCount() + key];
  }
  // B of node i at key k as a texel beside it sees it: a node wholly covered by a touching
  // solid (exposure 0 at its ray start points) has no B of a surface anyone sees (its gather is
  // skipped), yet a texel's point form factor can still take the sliver of it outside the
  // solid's footprint; it then takes the B of its nearest ancestor with an exposed part (the
  // exposed-area mean of that ancestor's children).
  glm::dvec3 exposedRadiosityAtKey(int node, int key) const;
  // H_good at the point of top-level patch `top` with top-level (u,v) `uv`, at key k:
  // Gouraud-interpolated over the union leaf that contains the point.
  glm::dvec3 goodIrradianceAtKey(int top, glm::dvec2 uv, int key) const;
  glm::dvec3 goodIrradiance(int top, glm::dvec2 uv, double t) const;
  // H_cluster of top-level patch `top` at key k (0 when the solution has none), and at time t
  // (linear between keys, held outside).
  glm::dvec3 clusterIrradianceAtKey(int top, int key) const {
    return topClusterIrradiance.empty()
               ? glm::dvec3(0.0)
               : glm::dvec3(topClusterIrradiance[size_t(top) * keyCount() + key]);
  }
  glm::dvec3 clusterIrradiance(int top, double t) const;
  double exposureAtKey(int node, int key) const {
    return nodeExposure.empty() ? 1.0 : double(nodeExposure[size_t(node) * keyCount() + key]);
  }
  // F·V of link row l at key k: piecewise linear through its samples, held outside them; 0 when
  // k is outside the row's activity interval.
  double linkFvAtKey(const GlobalLink& l, int key) const;
  // Whether link row l is active at key k (within [firstKey, lastKey]).
  static bool linkActiveAtKey(const GlobalLink& l, int key) {
    return key >= int(l.firstKey) && key <= int(l.lastKey);
  }
  // V of link row l at key k, the same way (1 when the file has no visibility samples).
  double linkVisibilityAtKey(const GlobalLink& l, int key) const;
  // Shooter tops of the bad pairs whose receiver is `receiverTop`, ascending.
  std::vector<uint32_t> badShooters(uint32_t receiverTop) const;
  bool isBadPair(uint32_t receiverTop, uint32_t shooterTop) const;

  // Throws rad::inputError(where, ...) when sizes or indices are inconsistent.
  void validate(const std::string& where) const;
  // The part of validate() that covers keyTimes, hierarchy, nodeRadiosity, leafRow and
  // nodeExposure only: all a solution read without its links and good irradiance (rad-compose) must
  // satisfy.
  void validateRadiosity(const std::string& where) const;
};

// Where a point of a node lies in its top-level patch's (u,v) square, and back: subdivision
// is exact in parameter space (quads: quarter squares; triangles: midpoint split of the half
// square, child 3 inverted).
glm::dvec2 topUvFromNodeUv(PatchId node, glm::dvec2 nodeUv, bool triangle);
glm::dvec2 nodeUvFromTopUv(PatchId node, glm::dvec2 topUv, bool triangle);
// (u,v) clamped into a node's parameter domain ([0,1]^2, or the half square u+v <= 1).
glm::dvec2 clampToParameterDomain(glm::dvec2 uv, bool triangle);
// One step down the quadtree: the child (0..3) whose domain contains the node-local point uv,
// with uv rewritten in that child's own (u,v) (clamped into its domain).
int descendToChild(glm::dvec2& uv, bool triangle);
// The deepest existing node of `hierarchy` under top-level patch `top` whose parameter domain
// contains topUv (points outside the domain are clamped into it).
int leafAtTopUv(const PatchHierarchy& hierarchy, int top, glm::dvec2 topUv);

}  // namespace rad
