// The cluster light per texel (contract in cluster_light_rays.h): the far candidates of a key,
// a top's far points and mean open share, and the per-texel ratio of a movie.
#include "libcommon/movies/cluster_light_rays.h"

#include <algorithm>
#include <array>
#include <bitset>

#include <tbb/parallel_for.h>

#include "libcommon/movies/good_link_gather.h"
#include "libcommon/movies/solid_contact.h"

namespace rad {

std::vector<ClusterLightStore::FarCandidate> drawFarCandidates(const GlobalSolution& solution,
                                                               const ClusterLightStore& store,
                                                               int key) {
  const uint32_t T = uint32_t(solution.hierarchy.topCount());
  const std::vector<Polygon>& world = store.staticTopWorld;
  std::vector<ClusterLightStore::FarCandidate> candidates;
  std::vector<double> cumulative(T, 0.0);
  double total = 0.0;
  for (uint32_t s = 0; s < T; ++s) {
    if (!store.topMoves[s]) {
      const glm::dvec3 B = solution.exposedRadiosityAtKey(int(s), key);
      total += std::max(0.0, B.x + B.y + B.z) * world[s].area();
    }
    cumulative[s] = total;
  }
  if (!(total > 0.0)) return candidates;
  const uint64_t seed = splitMix64(0x66617263616e64ull ^ uint64_t(key));
  const int m = ClusterLightStore::kFarCandidates;
  candidates.resize(size_t(m));
  for (int j = 0; j < m; ++j) {
    const double u = (double(j) + uniformOpen01(seed, 3 * uint64_t(j))) / double(m) * total;
    const uint32_t s = uint32_t(std::min(
        size_t(std::upper_bound(cumulative.begin(), cumulative.end(), u) - cumulative.begin()),
        size_t(T) - 1));
    candidates[size_t(j)] = {pointOnPolygon(world[s], uniformOpen01(seed, 3 * uint64_t(j) + 1),
                                            uniformOpen01(seed, 3 * uint64_t(j) + 2)),
                             world[s].normal(), s};
  }
  return candidates;
}

const ClusterLightStore::Rays& GoodLinkGather::clusterLightRays(int key) {
  const PatchHierarchy& h = solution_.hierarchy;
  const uint32_t R = uint32_t(receiverTop_), T = uint32_t(h.topCount());
  ClusterLightStore& store = byReceiver_.clusterLight;
  auto [at, fresh] =
      store.rays.try_emplace(uint64_t(R) * uint64_t(solution_.keyCount()) + uint64_t(key));
  ClusterLightStore::Rays& out = at->second;
  if (!fresh) return out;
  const std::vector<Polygon>& world = store.staticTopWorld;
  // What the top gathers itself, the shooters of its nodes' links and of its bad pairs, is not
  // the cluster light's.
  std::vector<char> gathered(T, 0);
  gathered[R] = 1;
  for (std::vector<int> stack{int(R)}; !stack.empty();) {
    const int node = stack.back();
    stack.pop_back();
    for (uint32_t k = byReceiver_.start[size_t(node)]; k < byReceiver_.start[size_t(node) + 1]; ++k)
      gathered[h.node(int(solution_.links[byReceiver_.rows[k]].shooter)).id.top] = 1;
    if (!h.isLeaf(node))
      for (int c = 0; c < 4; ++c) stack.push_back(h.node(node).firstChild + c);
  }
  const auto& bad = solution_.badPairs;
  for (auto it = std::lower_bound(bad.begin(), bad.end(), std::make_pair(R, uint32_t(0)));
       it != bad.end() && it->first == R; ++it)
    gathered[it->second] = 1;
  std::vector<ClusterLightStore::FarCandidate>& candidates = store.farCandidates[key];
  if (candidates.empty()) candidates = drawFarCandidates(solution_, store, key);
  if (candidates.empty()) return out;
  // The top's far points: the candidates it does not gather itself, drawn again by its kernel
  // cos cos / d^4 from its centroid (the candidates carry B A already), stratified.
  const Polygon& receiver = world[R];
  const glm::dvec3 centre = receiver.centroid(), n = receiver.normal();
  std::vector<double> cumulative(candidates.size(), 0.0);
  double total = 0.0;
  for (size_t c = 0; c < candidates.size(); ++c) {
    const ClusterLightStore::FarCandidate& f = candidates[c];
    if (!gathered[f.top]) {
      const glm::dvec3 d = f.point - centre;
      const double r2 = glm::dot(d, d);
      total += std::max(0.0, glm::dot(n, d)) * std::max(0.0, -glm::dot(f.normal, d)) / (r2 * r2);
    }
    cumulative[c] = total;
  }
  if (!(total > 0.0)) return out;
  const int k = clusterVisibilityRays_;
  const uint64_t seed = splitMix64(0x636c7573746572ull ^ uint64_t(R));
  out.points.resize(static_cast<size_t>(k));
  for (int j = 0; j < k; ++j) {
    const double u = (double(j) + uniformOpen01(seed, uint64_t(j))) / double(k) * total;
    const size_t c = std::min(
        size_t(std::upper_bound(cumulative.begin(), cumulative.end(), u) - cumulative.begin()),
        candidates.size() - 1);
    out.points[size_t(j)] = candidates[c].point;
  }
  // The mean over the top's uncovered part (rad-global's cluster light is the exposed part's).
  const VisibilityScene& blockers = visibility_->staticPart();
  const double size = polygonSize(receiver);
  double sum = 0.0;
  int uncovered = 0;
  for (const glm::dvec3& p :
       VisibilityScene::samplePoints(receiver, kClusterVisibilityPoints, seed)) {
    if (insideSolid(blockers, scene_, h, R, p, n, size, keyTimes_.front())) continue;
    sum += double(std::bitset<64>(blockers.openFrom(p, out.points, R)).count()) / double(k);
    ++uncovered;
  }
  out.meanOpenShare = uncovered > 0 ? sum / double(uncovered) : 0.0;
  return out;
}

void GoodLinkGather::planClusterVisibility() {
  clusterVisibility_.clear();
  const int k = clusterVisibilityRays_;
  if (k <= 0 || !visibility_ || clusterCorners_.empty()) return;
  const PatchHierarchy& h = solution_.hierarchy;
  const double t0 = keyTimes_.front();
  const uint32_t R = uint32_t(receiverTop_);
  ClusterLightStore& store = byReceiver_.clusterLight;
  // A moving receiver's rays would hold only at its first key.
  if (store.topMoves.empty()) {  // the static tops' world polygons, once per worker
    const uint32_t T = uint32_t(h.topCount());
    store.staticTopWorld.resize(T);
    store.topMoves.assign(T, 0);
    for (uint32_t s = 0; s < T; ++s) {
      store.topMoves[s] = std::find(movingNodes_.begin(), movingNodes_.end(), h.top(int(s)).node) !=
                          movingNodes_.end();
      if (!store.topMoves[s]) store.staticTopWorld[s] = nodeWorld(s, t0);
    }
  }
  if (store.topMoves[R]) return;
  int k0, k1;
  double w;
  solution_.keyWeights(t0, k0, k1, w);
  const glm::dvec3 own = solution_.clusterIrradianceAtKey(int(R), k0);
  if (!(own.x + own.y + own.z > 0.0)) return;
  const ClusterLightStore::Rays& rays = clusterLightRays(k0);
  if (rays.points.empty() || !(rays.meanOpenShare > 0.0)) return;
  const VisibilityScene& blockers = visibility_->staticPart();
  const TexelFrame frame = texelFrame(t0);
  // At the tiles' corner texels (planTexels' corners_, sorted by texel; its last entry only
  // ends the list), bilinear in between.
  const size_t C = corners_.size() - 1;
  std::vector<double> atCorner(C);
  tbb::parallel_for(size_t(0), C, [&](size_t i) {
    const glm::dvec3 x = frame.point(texels_.localPoint[corners_[i].texel]);
    atCorner[i] = double(std::bitset<64>(blockers.openFrom(x, rays.points, R)).count()) /
                  double(k) / rays.meanOpenShare;
  });
  auto ratioAt = [&](size_t x) {
    return atCorner[size_t(std::lower_bound(corners_.begin(), corners_.begin() + long(C), x,
                                            [](const Corner& c, size_t t) { return c.texel < t; }) -
                           corners_.begin())];
  };
  const int width = texels_.width, height = texels_.height;
  clusterVisibility_.assign(size_t(width) * size_t(height), 1.0f);
  for (const Tile& tile : tiles_) {
    const std::array<size_t, 4> c = tile.cornerTexels(width);
    const double m[4] = {ratioAt(c[0]), ratioAt(c[1]), ratioAt(c[2]), ratioAt(c[3])};
    for (int j = tile.j0; j < std::min(tile.j0 + kTile, height); ++j)
      for (int i = tile.i0; i < std::min(tile.i0 + kTile, width); ++i)
        clusterVisibility_[size_t(j) * size_t(width) + size_t(i)] = float(tile.bilinear(i, j, m));
  }
}

}  // namespace rad
