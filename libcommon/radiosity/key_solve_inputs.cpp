// What the space-time pass gives a key-time solve; see key_solve_inputs.h.
#include "libcommon/radiosity/key_solve_inputs.h"

#include <algorithm>
#include <array>
#include <unordered_map>
#include <utility>

#include <tbb/parallel_for.h>

namespace rad {

std::vector<char> movingTopsOf(const Scene& scene, const PatchHierarchy& hierarchy, double t0,
                               double t1) {
  std::unordered_map<int, bool> dynamic;
  for (int node : scene.meshNodes()) dynamic[node] = scene.isDynamic(node, t0, t1);
  std::vector<char> out(size_t(hierarchy.topCount()), 0);
  for (int t = 0; t < hierarchy.topCount(); ++t) {
    auto it = dynamic.find(hierarchy.top(t).node);
    out[size_t(t)] = it != dynamic.end() && it->second;
  }
  return out;
}

ClusterLinkCache reusableClusterLinks(const KeySolution& prev, const ClusterTree& tree,
                                      const PatchHierarchy& h, const Scene& scene, double t0,
                                      double t1) {
  const std::vector<char> moving = movingTopsOf(scene, h, t0, t1);
  std::vector<std::array<glm::dvec3, 2>> swept;
  for (int node : scene.meshNodes())
    if (scene.isDynamic(node, t0, t1)) swept.push_back(scene.sweptBounds(node, t0, t1));
  // A cluster below the root holds one mesh node's patches (or only static ones).
  auto isStatic = [&](ClusterRef r) {
    if (!isCluster(r)) return !moving[size_t(r)];
    const ClusterNode& n = tree.node(clusterIndex(r));
    return clusterIndex(r) != tree.root() && !moving[tree.members()[n.first]];
  };
  auto box = [&](ClusterRef r) {
    return isCluster(r) ? prev.clusterBounds[size_t(clusterIndex(r))]
                        : polygonBounds(prev.world[size_t(r)]);
  };
  const size_t T = size_t(h.topCount());
  // Both ends static and no moving node's swept bounds meeting the box around both.
  auto stays = [&](ClusterRef r, ClusterRef s) {
    if (!isStatic(r) || !isStatic(s)) return false;
    const ClusterBounds a = box(r), b = box(s);
    const glm::dvec3 lo = glm::min(a.lo, b.lo), hi = glm::max(a.hi, b.hi);
    for (const auto& m : swept)
      if (glm::all(glm::lessThanEqual(m[0], hi)) && glm::all(glm::lessThanEqual(lo, m[1])))
        return false;
    return true;
  };
  // Per link, in parallel, whether it is kept; then the kept ones in link order.
  const std::vector<ClusterLink>& links = prev.clusterLinkValues;
  std::vector<char> kept(links.size());
  tbb::parallel_for(size_t(0), links.size(), [&](size_t i) {
    const ClusterLink& l = links[i];
    kept[i] = l.evaluated && stays(l.receiver, l.shooter) ? 1 : 0;
  });
  std::vector<std::pair<uint32_t, uint32_t>> keys;
  std::vector<CachedClusterLink> values;
  const size_t count = size_t(std::count(kept.begin(), kept.end(), char(1)));
  keys.reserve(count);
  values.reserve(count);
  ClusterLinkCache cache;
  for (size_t i = 0; i < links.size(); ++i)
    if (kept[i]) {
      const ClusterLink& l = links[i];
      keys.emplace_back(clusterLinkEnd(l.receiver, T), clusterLinkEnd(l.shooter, T));
      values.push_back(CachedClusterLink{l.direction, l.visibility, l.groupVisibility});
      if (l.memberVisibility != ClusterLink::kNoMemberVisibility) {
        values.back().memberVisibility = uint32_t(cache.memberVisibility.size());
        const auto from = prev.clusterMemberVisibility.begin() + long(l.memberVisibility);
        cache.memberVisibility.insert(cache.memberVisibility.end(), from,
                                      from + long(tree.node(clusterIndex(l.receiver)).count));
      }
    }
  cache.links =
      PairTable<CachedClusterLink>(keys, std::move(values), uint32_t(T + size_t(tree.size())));
  const std::vector<NearLinkTest>& tests = prev.clusterNearTests;
  std::vector<char> still(tests.size());
  tbb::parallel_for(size_t(0), tests.size(), [&](size_t i) {
    still[i] = stays(tests[i].receiver, tests[i].shooter) ? 1 : 0;
  });
  std::vector<std::pair<uint32_t, uint32_t>> testKeys;
  std::vector<uint8_t> answers;
  for (size_t i = 0; i < tests.size(); ++i)
    if (still[i]) {
      testKeys.emplace_back(clusterLinkEnd(tests[i].receiver, T),
                            clusterLinkEnd(tests[i].shooter, T));
      answers.push_back(tests[i].blocked);
    }
  cache.blocked =
      PairTable<uint8_t>(testKeys, std::move(answers), uint32_t(T + size_t(tree.size())));
  return cache;
}

ClusterTree clusterTreeOf(const Scene& scene, const PatchHierarchy& h, double t0, double t1) {
  const std::vector<glm::dmat4> m = topTransforms(scene, h, t0);
  std::vector<Polygon> world(size_t(h.topCount()));
  for (int t = 0; t < h.topCount(); ++t)
    world[size_t(t)] = h.top(t).local.transformed(m[size_t(t)]);
  return ClusterTree(h, world, movingTopsOf(scene, h, t0, t1));
}

std::vector<glm::dmat4> topTransforms(const Scene& scene, const PatchHierarchy& hierarchy,
                                      double t) {
  std::vector<glm::dmat4> out(size_t(hierarchy.topCount()), glm::dmat4(1.0));
  std::unordered_map<int, glm::dmat4> perNode;
  for (int i = 0; i < hierarchy.topCount(); ++i) {
    int node = hierarchy.top(i).node;
    if (node < 0) continue;
    auto it = perNode.find(node);
    if (it == perNode.end()) it = perNode.emplace(node, scene.worldTransform(node, t)).first;
    out[size_t(i)] = it->second;
  }
  return out;
}

}  // namespace rad
