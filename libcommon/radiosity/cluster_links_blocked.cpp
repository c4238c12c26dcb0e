// The blocked test of near cluster links without a light (cluster_links.h, fateOf): whether the
// two ends of a near link can see each other at all, so that a link that carries nothing is
// dropped instead of refined down to every pair of its members (Smits, Arvo, Greenberg 1994 §3
// refine a cluster link for its error; a link with V = 0 has none). Issue 58: rooms behind walls
// (docs/results.md, "Near links behind walls dropped").
#include <algorithm>
#include <cmath>
#include <vector>

#include "libcommon/radiosity/cluster_links.h"
#include "libcommon/radiosity/link_form_factor.h"

namespace rad {
namespace {
constexpr uint64_t kShuffleSalt = 0x73687566666c65ull;  // "shuffle"
}  // namespace

bool ClusterLinks::facingMembers(ClusterRef end, ClusterRef other, size_t most,
                                 std::vector<uint32_t>& out) const {
  const ClusterBounds& box = bounds(other);
  if (!isCluster(end)) {
    if (mayFace(uint32_t(end), box)) out.push_back(uint32_t(end));
    return true;
  }
  const ClusterNode& n = tree_.node(clusterIndex(end));
  for (uint32_t i = n.first; i < n.first + n.count; ++i)
    if (mayFace(tree_.members()[i], box)) {
      if (out.size() == most) return false;
      out.push_back(tree_.members()[i]);
    }
  return true;
}

bool ClusterLinks::tooManyPairsToTest(ClusterRef r, ClusterRef s) const {
  std::vector<uint32_t> a, b;
  if (!facingMembers(r, s, kTestedMemberPairs, a)) return true;
  return !a.empty() && !facingMembers(s, r, kTestedMemberPairs / a.size(), b);
}

bool ClusterLinks::boxesApart(ClusterRef r, ClusterRef s) const {
  const ClusterBounds &R = bounds(r), &S = bounds(s);
  for (int a = 0; a < 3; ++a)
    if (R.hi[a] < S.lo[a] || S.hi[a] < R.lo[a]) return true;
  return false;
}

bool ClusterLinks::sampleTested(ClusterRef r, ClusterRef s) const {
  return visibility_ && nearBlockRays_ > 0 && boxesApart(r, s);
}

bool ClusterLinks::sampledBlocked(ClusterRef r, ClusterRef s) const {
  if (!sampleTested(r, s)) return false;
  const int n = nearBlockRays_;
  const uint64_t seed = splitMix64(clusterLinkSeed(r, s) ^ 0x6e656172626c6bull);  // "nearblk"
  // s's strata in a random order against r's, as blocked() pairs them.
  const std::vector<int> order = permutation(n, splitMix64(seed ^ kShuffleSalt));
  // Counters of draw i: 0, 1 the strata's jitter of r's and s's member, 2-5 the points, then
  // kFacingTries retries of each member.
  constexpr uint64_t kPerDraw = 6 + 2 * kFacingTries;
  int cast = 0;
  for (int i = 0; i < kDrawsPerRay * n && cast < n; ++i) {
    const uint64_t c = uint64_t(i) * kPerDraw;
    const int stratum = i % n;
    auto u = [&](uint64_t k) { return uniformOpen01(seed, c + k); };
    const uint32_t a = drawFacingMember(r, bounds(s), memberAreaPrefix_, [&](int t) {
      return t == 0 ? (stratum + u(0)) / n : u(6 + uint64_t(t));
    });
    const uint32_t b = drawFacingMember(s, topBounds_[a], memberAreaPrefix_, [&](int t) {
      return t == 0 ? (order[size_t(stratum)] + u(1)) / n : u(6 + kFacingTries + uint64_t(t));
    });
    const glm::dvec3 x = pointOnPolygon(world_[a], u(2), u(3));
    const glm::dvec3 y = pointOnPolygon(world_[b], u(4), u(5));
    // Only rays that carry energy (each point in front of the other's plane) count.
    if (!(glm::dot(normal_[a], y - x) > 0.0 && glm::dot(normal_[b], x - y) > 0.0)) continue;
    ++cast;
    if (!visibility_->occluded(x, y, a, b)) return false;
  }
  return cast == n;  // fewer pairs that carry energy: not enough rays to tell, so refined
}

bool ClusterLinks::blocked(ClusterRef r, ClusterRef s) const {
  if (!visibility_) return false;
  std::vector<uint32_t> a, b;
  if (!facingMembers(r, s, kTestedMemberPairs, a)) return sampledBlocked(r, s);
  if (a.empty()) return true;  // nothing of r faces s
  if (!facingMembers(s, r, kTestedMemberPairs / a.size(), b)) return sampledBlocked(r, s);
  // One ray between the centroids of each pair that face each other there first: where the
  // ends see each other (most near links of an open room), one of them gets through.
  for (const uint32_t i : a)
    for (const uint32_t j : b) {
      const glm::dvec3 d = centroid_[j] - centroid_[i];
      if (glm::dot(normal_[i], d) > 0.0 && glm::dot(normal_[j], d) < 0.0 &&
          !visibility_->occluded(centroid_[i], centroid_[j], i, j))
        return false;
    }
  const uint64_t seed = splitMix64(clusterLinkSeed(r, s) ^ 0x626c6f636b6564ull);  // "blocked"
  for (const uint32_t i : a)
    for (const uint32_t j : b) {
      const Polygon &p = world_[i], &q = world_[j];
      if (!mutuallyFacing(p, facingPlane(p), q, facingPlane(q))) continue;  // they exchange nothing
      // Points of each in front of the other's plane: every ray between them carries energy.
      const uint64_t pairSeed = splitMix64(seed ^ (uint64_t(i) << 32 | j));
      const std::vector<glm::dvec3> x =
          VisibilityScene::samplePointsInFront(p, q.v[0], normal_[j], rays_, pairSeed);
      const std::vector<glm::dvec3> y =
          VisibilityScene::samplePointsInFront(q, p.v[0], normal_[i], rays_, splitMix64(pairSeed));
      // y's strata in a random order against x's: pairing stratum k with stratum k would test
      // the same few of the stratum pairs every time.
      const std::vector<int> order = permutation(rays_, splitMix64(pairSeed ^ kShuffleSalt));
      for (int k = 0; k < rays_; ++k)
        if (!visibility_->occluded(x[size_t(k)], y[size_t(order[size_t(k)])], i, j)) return false;
    }
  return true;
}

}  // namespace rad
