// Cluster links of one key-time solve (Smits, Arvo, Greenberg 1994; Sillion 1995): the links
// between clusters, and between a cluster and a top-level patch, that rad-global's linking
// starts from instead of pairing every top-level patch with every other.
//
// Linking starts from the root cluster's self-link. A self-link is replaced by the links
// between every ordered pair of the cluster's children (and the children's self-links); a link
// R <- S is refined, by splitting the larger of its two clusters (a top-level patch end is not
// split here), while
//  * S holds an emitter and the link's power bound (below, with S's emitted radiosity where that
//    is larger) exceeds lightShare eps Phi: such links end as patch links, which the second
//    pass recomputes per texel (the bad links, with shadows) and the closure keeps exact; a
//    light's weaker links stay cluster links (smooth light, no per-texel shadows). lightShare
//    0: every link from a light ends as patch links; the lights' links then grow as the
//    top-level patches times the lights, which is quadratic in a hall whose lights grow with
//    its floor;
//  * the two bounding spheres come closer than their radii (the point approximation below
//    does not hold): near geometry ends as patch links, unless S holds no emitter and R and S
//    cannot see each other (blocked): such a link carries nothing and is dropped, not refined.
//    Ends with few members: the rays of every pair of their members that face each other are
//    blocked. Boards of a shelf, boxes in a row: their tops are near each other by their
//    spheres, and most pairs of them cannot see each other (a board between); refining every
//    such pair down to top-level patches made their all-pairs links, 96 % of them with V = 0
//    (issue 58), which the patch links' own oracle never refines either. Larger ends whose
//    boxes do not meet: a fixed number of rays between members drawn by area are all blocked
//    (sampledBlocked, whose contract bounds a false answer). Furniture of neighbouring rooms
//    behind one wall is near by its spheres, and was refined down to every pair of members.
//    A light's links are refined as before: the second pass takes their shadows per texel;
//  * or its power bound exceeds eps Phi: $\max B_S \, V \, \min(A_R \tilde F, A_S)$ with
//    $\tilde F = \min(1, A_S / (\pi d_{min}^2))$, d_min the gap between the spheres (Smits et
//    al. §3's bound on a cluster-to-cluster transfer).
// A link whose two ends are top-level patches becomes a patch link (SolverLink), and the patch
// hierarchy's refinement takes it from there.
//
// Transfer (oriented emission and reception, Sillion 1995 §4.2): at a member patch i of R
// (centroid x_i, normal n_i), the irradiance from S is
//   $H_i = \frac{B_S V_{RS}}{\pi} \sum_g \frac{\max(0, -N_g \cdot d_{gi}) \max(0, n_i \cdot
//   d_{gi})}{|d_{gi}|^4}$,  $d_{gi} = c_g - x_i$,
// over S's facing cells g: its member patches grouped by their normal's dominant axis and sign
// (the facing group, six at most), then by the signs of the two other components and which of
// them is larger (48 cells at most), each with its area-weighted normal sum
// $N_g = \sum_{j \in g} A_j n_j$ and area centroid c_g. $\max(0, -N_g \cdot d)$ is the cell's
// projected area towards the receiver where all its members face it or all face away; a facing
// group's members can be 90 degrees apart, and its N_g cancelled between those that face a
// receiver and those that do not (a sphere's cap seen from its side, the faces of boxes turned
// differently about one axis: the cluster's light too dark, issue 58). Both cosines are taken
// from each member i of R to each cell's own centre.
// One point and one direction for all of S, from R's centre, is first order wrong where a link is
// seen at a grazing angle (a wall's tiles seen from the perpendicular wall beside them) and leaves
// every cluster link of an open room dark against the exact point-to-polygon sums
// (ClusterLinks.ExposedFloorMatchesAllPairsAtTheDefaultSeparation). B_S is S's radiosity as R sees
// it: its facing groups' area-average radiosities B_g weighted by their cells' projected areas
// towards R, $B_S = \sum_g \max(0, -N_g \cdot \omega) B_{a(g)} / \sum_g \max(0, -N_g \cdot
// \omega)$ over the cells g, a(g) a cell's facing group, ω the link's direction (gather), as the
// transfer above weighs the cells; and V_RS the kernel-weighted share of k shadow-ray pairs
// between points of R's and S's patches that are unoccluded, each end's patch drawn by area
// among those that may face the other end
// (evaluateLink). At a member i of a cluster R, V is i's own: the kernel-weighted open share of a
// few more pairs from points of i to S's tops (visibilityAtMember; one V for a wall's tiles had
// given its upper tiles, open to the seats' clusters, the V of its lower ones, hidden behind the
// seats); where i is partly covered (its rays would start under the cover too) or none of its pairs
// has a kernel, the V of the pairs whose R end lies in i's facing group, with the link's V as a
// prior (a group holds few of the k pairs). The irradiance is pushed down to every member top of R,
// so the gather goes through the clusters.
//
// Isotropic clusters (the option; Smits, Arvo, Greenberg 1994 §3): a cluster end is taken as
// emitting and receiving alike in every direction, as if its members' orientations were
// unknown: a shooter cluster's cell g shows its area A_g / 4 (the mean projected area of a
// surface over all directions) instead of max(0, -N_g . d) / |d|, B_S is its groups' area
// average, and a member of a receiver cluster takes 1/4 (the mean of max(0, cos) over the
// sphere) instead of its own cosine. A top-level patch end stays oriented.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/radiosity/cluster_tree.h"
#include "libcommon/radiosity/link_census.h"
#include "libcommon/radiosity/pair_table.h"
#include "libcommon/radiosity/visibility.h"

namespace rad {

// V of a cluster link at the members of one of its receiver's facing groups, in 1/255ths.
using GroupVisibility = std::array<uint8_t, 6>;
inline uint8_t quantizedVisibility(double v) {
  return uint8_t(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
}

// 36 bytes: the direction and V in single precision, V per receiver facing group in bytes, and
// where its members' own V start: a key holds a million or more of them, beside the next key's
// cache of them, at rad-global's peak.
struct ClusterLink {
  ClusterRef receiver = 0, shooter = 0;
  glm::vec3 direction{0.0f};  // unit, from the receiver's centre towards the shooter's
  float visibility = 1;       // V_RS (1 until evaluated)
  // V_RS at R's members of each facing group (facingGroupOf their normal), for a cluster
  // receiver (evaluateLink); the transfer takes each member's group's.
  GroupVisibility groupVisibility{255, 255, 255, 255, 255, 255};
  bool evaluated = false;
  // For a cluster receiver: where V at each of its member tops (in the tree's member order, in
  // 1/255ths) starts in the ClusterLinks' member visibility (ClusterLinks::visibilityAtMember);
  // kNoMemberVisibility: the members take their facing group's V.
  uint32_t memberVisibility = kNoMemberVisibility;
  static constexpr uint32_t kNoMemberVisibility = ~0u;
};

// A cluster link's values that the next key time may take over (coherence, paper §4.2), keyed
// by (receiver, shooter) as clusterLinkEnd: valid while both ends are static and no moving
// object's swept bounds meet the box around both.
struct CachedClusterLink {
  glm::vec3 direction{0.0f};
  float visibility = 1;
  GroupVisibility groupVisibility{255, 255, 255, 255, 255, 255};
  uint32_t memberVisibility = ClusterLink::kNoMemberVisibility;  // in ClusterLinkCache's
};
// The cluster links the next key time may take over, and their members' own V (one byte a
// member of a cluster receiver, as ClusterLinks keeps them).
// A near cluster link without a light tested for being blocked (ClusterLinks::blocked): dropped
// when blocked, else refined.
struct NearLinkTest {
  ClusterRef receiver, shooter;
  uint8_t blocked;
};

struct ClusterLinkCache {
  PairTable<CachedClusterLink> links;
  std::vector<uint8_t> memberVisibility;  // each cached link's, as ClusterLink::memberVisibility
  // The near links the previous key tested for being blocked (ClusterLinks::nearTests), under
  // the same condition: their rays meet the same geometry, so the test would give the same
  // answer. Value 1: blocked (dropped), 0: not (refined).
  PairTable<uint8_t> blocked;
  const CachedClusterLink* find(uint32_t row, uint32_t column) const {
    return links.find(row, column);
  }
};
// A cluster link end as a ClusterLinkCache row or column: top-level patch t as t, cluster c as
// topCount + c (topCount + the tree's size rows in all).
inline uint32_t clusterLinkEnd(ClusterRef r, size_t topCount) {
  return isCluster(r) ? uint32_t(topCount + size_t(clusterIndex(r))) : uint32_t(r);
}
// The seed of the link r <- s's random draws (its rays, its blocked test): a function of its ends
// alone, so that every run and thread count draws the same.
inline uint64_t clusterLinkSeed(ClusterRef r, ClusterRef s) {
  return splitMix64(splitMix64(uint64_t(int64_t(r)) ^ 0x636c757374657221ull) ^
                    uint64_t(int64_t(s)));
}

class ClusterLinks {
 public:
  // `world`, `area`: per top-level patch at this key; `topEmission`: per top, its emitted
  // radiosity's largest channel (> 0: a light). `lightShare`: see the top of this file.
  ClusterLinks(const ClusterTree& tree, const std::vector<Polygon>& world,
               const std::vector<double>& area, const std::vector<double>& topEmission,
               const VisibilityScene* visibility, int rays, double separation, double lightShare,
               int memberRays, bool isotropic, const ClusterLinkCache* reuse = nullptr);

  // One round of refinement (see the top of this file) with eps Phi = epsAbs (refineAll: every
  // link is refined down to patch pairs, the all-pairs linking). The pairs of top-level
  // patches reached go to `patchPairs` (receiver, shooter). Once `budget` new links were made
  // only the links whose shooter holds a light are refined further (down to patch pairs, so
  // that every light keeps its per-texel shadows in the second pass), and `overBudget` is set.
  // Returns the number of links refined or dropped.
  size_t refine(double epsAbs, bool refineAll, size_t budget,
                std::vector<std::pair<int, int>>& patchPairs, bool& overBudget);
  // About how many links refinement will keep (the previous key's count with a margin): the
  // kept links are reserved once instead of doubling as they grow (no spare capacity held).
  void expectLinks(size_t n) { expectedLinks_ = n; }
  // Transfer and visibility of the links made since the last call (parallel, deterministic).
  void evaluate();
  // Per top: the irradiance of its exposed part through the cluster links, from the tops'
  // radiosity `topB` (B_S of a cluster: the area average of its tops'), summed in link order.
  // `exposure` (per node, the tops first; empty: every top exposed) is the share of each top
  // that no touching surface covers. A link at the top itself took its V from points all over
  // the top, the covered ones included, so its irradiance is divided by the exposure (as the
  // patch links' is); a link at an ancestor cluster took V from points all over the cluster's
  // tops, where this top's covered part is a sliver, so its irradiance is the exposed part's
  // as it is. Dividing that too would make a ceiling tile mostly behind a light (exposure 1/16)
  // gather many times its neighbours' cluster light, which rad-movies spreads along every
  // light. A covered top
  // (exposure 0) gathers nothing.
  void gather(const std::vector<glm::dvec3>& topB, const std::vector<double>& exposure,
              std::vector<glm::dvec3>& out);
  // The tops' radiosity `topB` (per top) that refinement judges the links by (their shooters'
  // largest B); gather sets it too. Until it is given, near links are refined by the
  // separation alone (fateOf).
  void setRadiosity(const std::vector<glm::dvec3>& topB);
  bool radiosityKnown() const { return radiosityKnown_; }
  // An estimate of the tops' radiosity `topB` before the first solve (per top), which fateOf
  // judges weak near links by, with the known B, until the first gather drops it. Without it
  // the first round knows only the lights' B, keeps every near link without a light, and the
  // refinement then follows the light one bounce a round and does not settle within
  // RadiosityOptions::maxRefineRounds (docs/results.md, "Weak near links kept by default").
  void estimateRadiosity(const std::vector<glm::dvec3>& topB);
  // fateOf keeps near links that cannot carry eps Phi (RadiosityOptions::keepWeakNearLinks).
  void keepWeakNearLinks(bool on) { keepWeakNear_ = on; }
  // Rays of the blocked test of near links between large ends (sampledBlocked; RadiosityOptions::
  // nearBlockRays); 0: such links are refined untested.
  void nearBlockRays(int n) { nearBlockRays_ = std::max(0, n); }
  // Per top: the sum of its cluster links' form factors H_i / B_S over the exposed part, as
  // gather weighs them (its row sum's cluster part).
  std::vector<double> rowSums(const std::vector<double>& exposure);

  // The near links tested for being blocked in this key's rounds, with the answer, for the next
  // key's coherence (ClusterLinkCache::blocked).
  const std::vector<NearLinkTest>& nearTests() const { return nearTests_; }
  // Whether the ends r and s are near: their bounding spheres' centres closer than the
  // separation times the radii's sum (the point approximation does not hold; fateOf).
  bool near(ClusterRef r, ClusterRef s) const;
  // The kept links and this key's near tests into `census` (link_census.h).
  void countInto(LinkCensus& census) const;
  size_t size() const { return links_.size(); }
  size_t reusedCount() const { return reused_; }
  const std::vector<ClusterBounds>& clusterBounds() const { return clusterBounds_; }
  const std::vector<ClusterLink>& links() const { return links_; }
  std::vector<ClusterLink> takeLinks() && { return std::move(links_); }
  // The links' V at their receivers' members (ClusterLink::memberVisibility), after takeLinks.
  std::vector<uint8_t> takeMemberVisibility() && { return std::move(memberVisibility_); }
  // Links evaluated from now on are computed, not taken over (the cache is about to go).
  void forgetReuse() { reuse_ = nullptr; }
  bool reusing() const { return reuse_ != nullptr; }

 private:
  struct LinkEnds {
    ClusterRef receiver, shooter;
  };
  // One call of refine, as its named steps (cluster_links.cpp).
  class RefineRound;
  // Whether a link between r and s may carry energy (see the .cpp).
  bool canExchange(ClusterRef r, ClusterRef s) const;
  // The children of refined link l, in order: links through sink.link(r, s), pairs of
  // top-level patches through sink.pair(r, s).
  template <class Sink>
  void expand(const ClusterLink& l, Sink& sink) const;
  // What a refinement round does with a link (see the top of this file).
  // kRefineNear: a near link tested and not blocked, refined (recorded in nearTests_).
  enum class Fate : uint8_t { kKeep, kRefine, kRefineNear, kDrop };
  Fate fateOf(const ClusterLink& l, double epsAbs) const;
  // Ray pair i of the link r <- s, as evaluateLink draws it from the link's seed: a member of
  // each end drawn among those that may face the other end, a point on each, and the kernel
  // cos cos / r^2 between them (0 behind either plane).
  struct RayPair {
    glm::dvec3 x, y;
    uint32_t a = 0, b = 0;
    double kernel = 0;
  };
  RayPair rayPair(ClusterRef r, ClusterRef s, int i, int k) const;
  // Whether no light passes between the ends r and s: of every pair (a, b) of their members
  // that face each other (mayFace, then mutuallyFacing), `rays` rays between stratified points
  // of a in front of b's plane and of b in front of a's (every ray carries energy) are all
  // blocked: what the patch link a <- b would find before its oracle left it unrefined at V = 0.
  // Ends with more than kTestedMemberPairs such pairs take sampledBlocked instead. False without
  // a visibility scene.
  bool blocked(ClusterRef r, ClusterRef s) const;
  static constexpr int kTestedMemberPairs = 16;
  // blocked for ends of any size (rooms behind a wall, a cabinet's two sides): n =
  // nearBlockRays_ rays, each between a member of r drawn by area among those facing s's box
  // (the draw stratified: every facing member with 1/n of r's area is drawn at least once) and
  // one of s drawn the same way among those facing it, both points in front of the other's
  // plane; true when all n are blocked. Contract, the error of a false answer (a gap the rays
  // miss): where a share p of such pairs sees through, all n rays are blocked with probability
  // (1 - p)^n, under 5 % for p >= 3 / n, so a link dropped here has, at 95 % confidence, an open
  // share of its pairs under 3 / n; the light it would carry is that share of its unoccluded
  // transfer, weighted by the pairs' kernel. The kernel is what area draws cannot bound where
  // the ends interlock (a cubby's two sides within clusters of the whole shelf: near pairs with
  // a large kernel see each other while most pairs do not; tried in issue 58's first round:
  // near cluster links with V = 0.6 dropped), so only ends whose bounding boxes are apart
  // (boxesApart: no pair closer than the boxes' gap) are tested; others answer false (refined).
  // False too when fewer than n of kDrawsPerRay n draws make a pair that carries energy.
  bool sampledBlocked(ClusterRef r, ClusterRef s) const;
  static constexpr int kDrawsPerRay = 2;
  // Whether the bounding boxes of r and s are apart along some axis (they do not meet).
  bool boxesApart(ClusterRef r, ClusterRef s) const;
  // Whether sampledBlocked tests the ends r and s (a visibility scene, rays, boxes apart).
  bool sampleTested(ClusterRef r, ClusterRef s) const;
  // The member tops of `end` whose plane has some of `other`'s box in front (the others see
  // none of it) into `out`; false when there are more than `most` (blocked does not test).
  bool facingMembers(ClusterRef end, ClusterRef other, size_t most,
                     std::vector<uint32_t>& out) const;
  // Whether blocked(r, s) takes more member pairs than it tests one by one (sampledBlocked
  // then answers).
  bool tooManyPairsToTest(ClusterRef r, ClusterRef s) const;
  size_t memberCount(ClusterRef r) const {
    return isCluster(r) ? tree_.node(clusterIndex(r)).count : 1;
  }
  const ClusterBounds& bounds(ClusterRef r) const {
    return isCluster(r) ? clusterBounds_[size_t(clusterIndex(r))] : topBounds_[size_t(r)];
  }
  // The largest emitted radiosity channel of r's tops (> 0: r holds a light).
  double emission(ClusterRef r) const {
    return isCluster(r) ? clusterEmission_[size_t(clusterIndex(r))] : emission_[size_t(r)];
  }
  bool emits(ClusterRef r) const { return emission(r) > 0.0; }
  double maxRadiosity(ClusterRef r) const {
    return isCluster(r) ? clusterMaxB_[size_t(clusterIndex(r))] : topMaxB_[size_t(r)];
  }
  // estimateRadiosity's largest over r's tops; 0 once dropped (or never given).
  double estimatedRadiosity(ClusterRef r) const {
    if (topEstimateB_.empty()) return 0.0;
    return isCluster(r) ? clusterEstimateB_[size_t(clusterIndex(r))] : topEstimateB_[size_t(r)];
  }
  // The largest over each top's channels, and over each cluster's tops, of `topB`.
  void maxOverMembers(const std::vector<glm::dvec3>& topB, std::vector<double>& top,
                      std::vector<double>& cluster) const;
  void evaluateLink(ClusterLink& l);
  // Draws of a link end's member for one ray pair until one faces the other end (evaluateLink).
  static constexpr int kFacingTries = 8;
  // Members whose normals' cosine is within this of 1 count as parallel (MemberPlanes).
  static constexpr double kParallelCosine = 1e-6;
  // The group V's prior weight, in mean pair kernels: a group's V is (its open kernel + p k V)
  // / (its kernel + p k), so that a group that drew one or two of the link's pairs does not
  // take 0 or 1 from them (0.5: as good as 2 against all pairs, better than 0).
  static constexpr double kGroupPrior = 0.5;
  // F V of link l at member top `top` of its receiver, whose exposure is `exposure`.
  double formFactor(const ClusterLink& l, uint32_t top, double exposure) const;
  // V of link l at member top t of its cluster receiver: the kernel-weighted open share of
  // memberRays_ ray pairs from points of t to points of the shooter's tops that may face t, in
  // 1/255ths; the member's facing group's V where no pair has a kernel (see the top of this
  // file).
  uint8_t visibilityAtMember(const ClusterLink& l, uint32_t t) const;
  // A member top of `end` (itself for a top) drawn by `prefix` (area, or emitted power) among
  // those whose plane has some of `other` in front: up to kFacingTries draws, the t-th with
  // uniform u(t) (the last one drawn when none faces).
  // Whether top t's plane has some of `box` in front (else t sees none of it).
  bool mayFace(uint32_t t, const ClusterBounds& box) const;
  template <class U>
  uint32_t drawFacingMember(ClusterRef end, const ClusterBounds& other,
                            const std::vector<double>& prefix, U u) const;
  void buildReceiverLists(const std::vector<double>& exposure);

  const ClusterTree& tree_;
  const std::vector<Polygon>& world_;
  const std::vector<double>& area_;
  const std::vector<double>& emission_;
  const VisibilityScene* visibility_;
  int rays_;
  double separation_;
  double lightShare_;
  int memberRays_;
  bool isotropic_;
  const ClusterLinkCache* reuse_;
  std::atomic<size_t> reused_{0};
  std::vector<glm::dvec3> centroid_, normal_;  // per top
  // A link end whose members all face one way (a top; a cluster of a wall's tiles, of a row of
  // desk tops): that normal and the lowest of its members' plane offsets, so that a link to a
  // cluster or top lying wholly on or behind every member's plane is not made (canExchange), and
  // how far in front of that plane a box may reach and still count as on it (0 for a top).
  // `parallel` false: the members face several ways.
  struct MemberPlanes {
    glm::dvec3 normal{0.0};
    double lowestOffset = 0, tolerance = 0;
    bool parallel = false;
  };
  std::vector<MemberPlanes> clusterPlanes_, topPlanes_;
  const MemberPlanes& planes(ClusterRef r) const {
    return isCluster(r) ? clusterPlanes_[size_t(clusterIndex(r))] : topPlanes_[size_t(r)];
  }
  std::vector<ClusterBounds> clusterBounds_, topBounds_;
  std::vector<double> clusterRadius_, topRadius_;  // of the bounding spheres
  // A cluster's facing cells (see the top of this file): its members grouped by facingCellOf.
  struct FacingGroup {
    glm::vec3 normalArea{0.0f};  // N_g
    glm::vec3 centre{0.0f};      // c_g
    int axisSign = 0;            // facingGroupOf its members' normals (the cell's facing group)
    float area = 0.0f;           // A_g, the sum of its members' areas
  };
  // A top's facing group by its normal: the dominant axis and its sign, 2 axis + (n < 0).
  static int facingGroupOf(const glm::dvec3& n);
  // A top's facing cell, one of kFacingCells: its facing group split by the signs of the two
  // other components and by which of them is larger (the 48 cells of the cube's symmetry).
  static int facingCellOf(const glm::dvec3& n);
  static constexpr int kFacingCells = 48;
  // Cluster c's non-empty cells, in cell order: facingCells_[facingStart_[c], facingStart_[c + 1]).
  std::vector<FacingGroup> facingCells_;
  std::vector<uint32_t> facingStart_;
  std::vector<double> clusterEmission_;
  std::vector<double> clusterMaxB_, topMaxB_;  // max over channels and members, last gather
  bool radiosityKnown_ = false;                // setRadiosity or gather has run
  bool keepWeakNear_ = false;                  // keepWeakNearLinks
  int nearBlockRays_ = 0;                      // nearBlockRays
  std::vector<double> memberAreaPrefix_;       // over tree_.members(), for area sampling
  std::vector<double> memberPowerPrefix_;      // the same of area x emission (lights' V)
  // estimateRadiosity's, as clusterMaxB_ and topMaxB_, until a gather.
  std::vector<double> clusterEstimateB_, topEstimateB_;
  std::vector<ClusterLink> links_;
  std::vector<NearLinkTest> nearTests_;  // nearTests()
  // The links' V at their receivers' members (ClusterLink::memberVisibility); a refined link's
  // stay until the key's end.
  std::vector<uint8_t> memberVisibility_;
  std::vector<uint32_t> memberPosition_;  // per top: its index in tree_.members()
  size_t expectedLinks_ = 0;
  // Per link: its shooter's B towards its receiver (gather). This and the gather's form
  // factors in single precision: there are millions of them on a large scene.
  std::vector<glm::vec3> linkB_;
  // Per top, what the gather sums at every sweep: the links at the top and at its ancestor
  // clusters, in that order, with their form factor to the top where it is > 0. The geometry is
  // fixed within a key time, and walking the links themselves at every sweep (each a cache
  // miss) would cost far more than reading these lists in order. Held in blocks of
  // kGatherBlockTops tops, each built by one task: top t's entries start at gatherStart_[t] in
  // its block and end where the next top's start (its block's end for the block's last top).
  struct GatherEntry {
    uint32_t link;
    float formFactor;
  };
  static constexpr size_t kGatherBlockTops = 256;
  std::vector<std::vector<GatherEntry>> gatherBlocks_;
  std::vector<uint32_t> gatherStart_;
  // Per top: how many of its entries, first, are the links at the top itself (gather divides
  // them by its exposure): counted when the lists are made, so that the sweeps read no link.
  std::vector<uint32_t> gatherOwn_;
  bool listsValid_ = false;
  // After a refinement round that changed links, until the lists are made again: each link of
  // the lists' link order at its new index (kGone: refined), and the receivers (clusterLinkEnd
  // rows) that gained or lost links. Empty: the lists are made anew.
  static constexpr uint32_t kGone = ~0u;
  std::vector<uint32_t> movedTo_;
  std::vector<char> changedReceiver_;
  // Top t's entries in its block.
  std::pair<const GatherEntry*, const GatherEntry*> entriesOf(size_t t) const;
  // Sum of term(entry) over top t's entries for its exposed part: the links at the top over its
  // exposure, those at its ancestor clusters as they are (gather's header comment); 0 for a
  // covered top.
  template <class Sum, class Term>
  Sum overExposedPart(size_t t, const std::vector<double>& exposure, Term term) const;
};

// In the header: both the links' rays (cluster_links.cpp) and the blocked test draw with it.
template <class U>
inline uint32_t ClusterLinks::drawFacingMember(ClusterRef end, const ClusterBounds& other,
                                               const std::vector<double>& prefix, U u) const {
  if (!isCluster(end)) return uint32_t(end);
  const ClusterNode& n = tree_.node(clusterIndex(end));
  const double lo = prefix[n.first], hi = prefix[n.first + n.count];
  uint32_t j = 0;
  for (int t = 0; t < kFacingTries; ++t) {
    const double target = lo + u(t) * (hi - lo);
    auto it =
        std::upper_bound(prefix.begin() + n.first + 1, prefix.begin() + n.first + n.count, target);
    j = tree_.members()[size_t(it - prefix.begin()) - 1];
    if (mayFace(j, other)) break;
  }
  return j;
}

}  // namespace rad
