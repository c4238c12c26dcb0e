// Cluster links of one key-time solve (see the header). The figures behind the reasons given here:
// docs/results.md, "Figures moved out of the radiosity code's comments (issue 55)".
#include "libcommon/radiosity/cluster_links.h"
#include "libcommon/radiosity/link_form_factor.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <tbb/parallel_for.h>

namespace rad {

namespace {

double maxComponent(const glm::dvec3& v) {
  return std::max(v.x, std::max(v.y, v.z));
}

}  // namespace

ClusterLinks::ClusterLinks(const ClusterTree& tree, const std::vector<Polygon>& world,
                           const std::vector<double>& area, const std::vector<double>& topEmission,
                           const VisibilityScene* visibility, int rays, double separation,
                           double lightShare, int memberRays, bool isotropic,
                           const ClusterLinkCache* reuse)
    : tree_(tree),
      world_(world),
      area_(area),
      emission_(topEmission),
      visibility_(visibility),
      rays_(std::max(1, rays)),
      separation_(separation),
      lightShare_(lightShare),
      memberRays_(std::max(0, memberRays)),
      isotropic_(isotropic),
      reuse_(reuse) {
  const size_t T = topEmission.size();
  topBounds_.resize(T);
  centroid_.resize(T);
  normal_.resize(T);
  for (size_t t = 0; t < T; ++t) {
    topBounds_[t] = polygonBounds(world[t]);
    centroid_[t] = world[t].centroid();
    normal_[t] = world[t].normal();
  }
  clusterBounds_ = clusterBoundsOf(tree, world);
  // The bounding spheres' radii, read by formFactor for every gather entry.
  for (const ClusterBounds& b : clusterBounds_) clusterRadius_.push_back(b.radius());
  for (const ClusterBounds& b : topBounds_) topRadius_.push_back(b.radius());
  clusterEmission_.assign(size_t(tree.size()), 0.0);
  for (int c = tree.size(); c-- > 0;)  // sub-clusters (higher indices) first
    for (ClusterRef r : tree.node(c).children)
      clusterEmission_[size_t(c)] = std::max(clusterEmission_[size_t(c)], emission(r));
  clusterMaxB_.assign(size_t(tree.size()), 0.0);
  topMaxB_.assign(T, 0.0);
  const std::vector<uint32_t>& m = tree.members();
  memberPosition_.assign(T, 0);
  for (size_t i = 0; i < m.size(); ++i) memberPosition_[m[i]] = uint32_t(i);
  memberAreaPrefix_.assign(m.size() + 1, 0.0);
  memberPowerPrefix_.assign(m.size() + 1, 0.0);
  for (size_t i = 0; i < m.size(); ++i) {
    memberAreaPrefix_[i + 1] = memberAreaPrefix_[i] + area[m[i]];
    memberPowerPrefix_[i + 1] = memberPowerPrefix_[i] + area[m[i]] * topEmission[m[i]];
  }
  // Each cluster's facing cells (facingCellOf), from its members' normals, areas and centroids.
  facingStart_.assign(size_t(tree.size()) + 1, 0);
  for (int c = 0; c < tree.size(); ++c) {
    const ClusterNode& n = tree.node(c);
    std::array<glm::dvec3, kFacingCells> normalArea{}, moment{};
    std::array<double, kFacingCells> cellArea{};
    for (uint32_t i = n.first; i < n.first + n.count; ++i) {
      const uint32_t j = m[i];
      const size_t g = size_t(facingCellOf(normal_[j]));
      normalArea[g] += area[j] * normal_[j];
      moment[g] += area[j] * centroid_[j];
      cellArea[g] += area[j];
    }
    for (size_t g = 0; g < size_t(kFacingCells); ++g)
      if (cellArea[g] > 0.0)
        facingCells_.push_back({glm::vec3(normalArea[g]), glm::vec3(moment[g] / cellArea[g]),
                                int(g) / (kFacingCells / 6), float(cellArea[g])});
    facingStart_[size_t(c) + 1] = uint32_t(facingCells_.size());
  }
  facingCells_.shrink_to_fit();
  // Every top's plane; a cluster's when its members are parallel (MemberPlanes): normals within
  // about a milliradian of the first's, which with rounding is the tolerance of a box on it.
  topPlanes_.resize(T);
  for (size_t t = 0; t < T; ++t)
    topPlanes_[t] = {normal_[t], glm::dot(normal_[t], centroid_[t]), 0.0, true};
  clusterPlanes_.resize(size_t(tree.size()));
  for (int c = 0; c < tree.size(); ++c) {
    const ClusterNode& n = tree.node(c);
    MemberPlanes& p = clusterPlanes_[size_t(c)];
    p = topPlanes_[m[n.first]];
    p.tolerance = kParallelCosine * clusterRadius_[size_t(c)];
    for (uint32_t i = n.first + 1; i < n.first + n.count && p.parallel; ++i) {
      const uint32_t j = m[i];
      p.parallel = glm::dot(normal_[j], p.normal) >= 1.0 - kParallelCosine;
      p.lowestOffset = std::min(p.lowestOffset, glm::dot(p.normal, centroid_[j]));
    }
  }
  ClusterLink root;
  root.receiver = root.shooter = clusterRef(tree.root());
  links_.push_back(root);
}

int ClusterLinks::facingGroupOf(const glm::dvec3& n) {
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(n[k]) > std::abs(n[axis])) axis = k;
  return axis * 2 + (n[axis] < 0.0 ? 1 : 0);
}

// Within a facing cell every member's normal has the same sign on each axis and the same order
// of its components' magnitudes, so the cell's members all face a receiver or all face away
// except where the receiver's direction lies within the cell's narrow band of grazing angles:
// the signed normal sum N_g of a cell does not cancel as that of a facing group of six did (a
// group's members 90 degrees apart, a sphere's cap seen from its side: 0.55 of its true
// projected area).
int ClusterLinks::facingCellOf(const glm::dvec3& n) {
  const int group = facingGroupOf(n);
  const int axis = group / 2, u = (axis + 1) % 3, v = (axis + 2) % 3;
  const int signs = (n[u] < 0.0 ? 2 : 0) + (n[v] < 0.0 ? 1 : 0);
  const int order = std::abs(n[u]) < std::abs(n[v]) ? 1 : 0;
  return group * 8 + signs * 2 + order;
}

// Whether a link between r and s may carry energy: not when an end whose member patches all
// face one way (a top-level patch, or a cluster of parallel ones: a wall's tiles) sees nothing
// of a cluster or top whose bounding box lies wholly on or behind every member's plane.
// Coplanar clusters (two parts of one wall, of one ceiling) are such a pair: their transfer is 0,
// and without this test a near pair of them would be refined down to top-level patches (whose pairs
// the patch links' facing test then drops), and a far pair kept as a link that carries nothing.
bool ClusterLinks::canExchange(ClusterRef r, ClusterRef s) const {
  auto behind = [&](ClusterRef end, ClusterRef other) {
    if (!isCluster(end) && !isCluster(other)) return false;  // the patch links' own test
    const MemberPlanes& p = planes(end);
    if (!p.parallel) return false;
    const ClusterBounds& b = bounds(other);
    for (int k = 0; k < 8; ++k) {
      const glm::dvec3 corner((k & 1) ? b.hi.x : b.lo.x, (k & 2) ? b.hi.y : b.lo.y,
                              (k & 4) ? b.hi.z : b.lo.z);
      if (glm::dot(p.normal, corner) - p.lowestOffset > p.tolerance) return false;
    }
    return true;
  };
  return !behind(r, s) && !behind(s, r);
}

template <class Sink>
void ClusterLinks::expand(const ClusterLink& l, Sink& sink) const {
  auto pairOrLink = [&](ClusterRef r, ClusterRef s) {
    if (!isCluster(r) && !isCluster(s)) {
      if (r != s) sink.pair(r, s);
    } else if (canExchange(r, s)) {
      sink.link(r, s);
    }
  };
  if (l.receiver == l.shooter) {  // a cluster's self-link: its children's pairs
    const std::vector<ClusterRef>& ch = tree_.node(clusterIndex(l.receiver)).children;
    for (ClusterRef a : ch)
      for (ClusterRef b : ch)
        if (a != b || isCluster(a)) pairOrLink(a, b);
    return;
  }
  // Split the larger cluster (a top-level patch end is split by the patch hierarchy).
  const bool splitReceiver =
      isCluster(l.receiver) &&
      (!isCluster(l.shooter) || bounds(l.receiver).radius() >= bounds(l.shooter).radius());
  const ClusterRef split = splitReceiver ? l.receiver : l.shooter;
  for (ClusterRef c : tree_.node(clusterIndex(split)).children)
    splitReceiver ? pairOrLink(c, l.shooter) : pairOrLink(l.receiver, c);
}

ClusterLinks::Fate ClusterLinks::fateOf(const ClusterLink& l, double epsAbs) const {
  const double emitted = emission(l.shooter);
  if (emitted > 0.0) {
    if (!(lightShare_ > 0.0)) return Fate::kRefine;
    epsAbs *= lightShare_;
  }
  const ClusterBounds& R = bounds(l.receiver);
  const ClusterBounds& S = bounds(l.shooter);
  // Near (the centres closer than `separation` times the radii's sum): the point approximation does
  // not hold, so such a link is refined, even one that carries little: accepted with its point
  // estimate, it moves the frames away from the all-pairs ones. One between a few members that
  // carries nothing (blocked) is dropped (the top of cluster_links.h).
  const double d = glm::length(S.centre() - R.centre());
  // A light's B before the first solve is its emission (the radiosity of the last gather is 0
  // then, and would keep every light link at the first round).
  const double bv = std::max(maxRadiosity(l.shooter), emitted) * l.visibility;
  if (near(l.receiver, l.shooter)) {
    if (emitted > 0.0) return Fate::kRefine;
    // Smits et al. §3's bound with F = 1, which holds however near the ends are: a near link
    // that cannot carry eps Phi is kept, as a far one is (the transfer's distance is at least
    // the shooter's radius, formFactor). Refining such links down to every pair of members
    // that face each other made, among packed small objects (binders on shelves, keyboards'
    // keys), links quadratic in the objects within the separation of each other (issue 58).
    // Without the shooters' radiosity (setRadiosity) the separation alone decides. Before the
    // first solve the shooter's B is taken as at least its estimate (estimateRadiosity), so
    // that the first round keeps only the links that its light will not make strong.
    // (keepWeakNearLinks, on by default.)
    const double weakBv = std::max(bv, estimatedRadiosity(l.shooter) * l.visibility);
    if (keepWeakNear_ && radiosityKnown_ && !(weakBv * std::min(R.area, S.area) > epsAbs))
      return Fate::kKeep;
    const size_t T = emission_.size();
    const uint8_t* known =
        reuse_ ? reuse_->blocked.find(clusterLinkEnd(l.receiver, T), clusterLinkEnd(l.shooter, T))
               : nullptr;
    const bool isBlocked = known ? *known != 0 : blocked(l.receiver, l.shooter);
    return isBlocked ? Fate::kDrop : Fate::kRefineNear;
  }
  const double gap = d - R.radius() - S.radius();
  const double f = std::min(1.0, S.area / (M_PI * gap * gap));
  return bv * std::min(R.area * f, S.area) > epsAbs ? Fate::kRefine : Fate::kKeep;
}

// One call of ClusterLinks::refine, level by level: `work_` holds one level's links, their
// children become the next level, `kept_` the links that stay. A refined link is dropped at
// once, so memory holds the links in use and one level's children, not every link refinement
// went through. The links keep the order they had that way (each level's survivors after the
// last's). The levels below the first hold new links, which have only their ends (LinkEnds,
// not whole links). The first level is compacted in place (a kept link goes to an index at or
// below its own), and the deeper levels' survivors are appended behind it, so no second array
// of the links is held beside the first. (Their memory: docs/results.md, "Figures moved out of
// the radiosity code's comments (issue 55)".)
class ClusterLinks::RefineRound {
 public:
  RefineRound(ClusterLinks& links, double epsAbs, bool refineAll, size_t budget,
              std::vector<std::pair<int, int>>& patchPairs, bool& overBudget)
      : c_(links),
        epsAbs_(epsAbs),
        refineAll_(refineAll),
        budget_(budget),
        patchPairs_(patchPairs),
        overBudget_(overBudget) {
    kept_.swap(c_.links_);
    kept_.reserve(std::max(kept_.size(), c_.expectedLinks_));
    firstSize_ = kept_.size();
    // Where each link of the first level goes (kGone: refined) and which receivers' links
    // change, so that the gather lists of the links before this round can be taken over for
    // the tops whose links did not change (buildReceiverLists).
    remap_ = c_.listsValid_;
    T_ = c_.emission_.size();
    moved_.assign(remap_ ? firstSize_ : 0, kGone);
    changed_.assign(remap_ ? T_ + size_t(c_.tree_.size()) : 0, 0);
  }

  // The first level (the links before this round), then the levels of new links until none is
  // made; returns the number of links refined.
  size_t run() {
    refineLevel(firstSize_, [&](size_t i) { return kept_[i]; });
    kept_.resize(written_);
    firstLevel_ = false;
    while (!work_.empty())
      refineLevel(work_.size(), [&](size_t i) {
        ClusterLink l;
        l.receiver = work_[i].receiver;
        l.shooter = work_[i].shooter;
        return l;
      });
    c_.links_.swap(kept_);
    // A round that refined nothing left every link where it was, and the gather lists hold.
    if (count_ > 0) {
      c_.listsValid_ = false;
      c_.movedTo_.swap(moved_);
      c_.changedReceiver_.swap(changed_);
    }
    return count_;
  }

 private:
  // Appends a refined link's children to `next` and `patchPairs` (the serial path).
  struct Appender {
    std::vector<LinkEnds>& next;
    std::vector<std::pair<int, int>>& pairs;
    size_t& made;
    void link(ClusterRef r, ClusterRef s) {
      next.push_back({r, s});
      ++made;
    }
    void pair(ClusterRef r, ClusterRef s) { pairs.emplace_back(r, s); }
  };
  // Counts them, then writes them where the counts put them (the parallel path).
  struct Counter {
    size_t links = 0, pairs = 0;
    void link(ClusterRef, ClusterRef) { ++links; }
    void pair(ClusterRef, ClusterRef) { ++pairs; }
  };
  struct Writer {
    LinkEnds* links;
    std::pair<int, int>* pairs;
    void link(ClusterRef r, ClusterRef s) { *links++ = {r, s}; }
    void pair(ClusterRef r, ClusterRef s) { *pairs++ = {r, s}; }
  };

  void changes(ClusterRef r) {
    if (remap_) changed_[clusterLinkEnd(r, T_)] = 1;
  }

  void keep(const ClusterLink& l) {
    if (firstLevel_) {
      if (remap_) moved_[current_] = uint32_t(written_);
      kept_[written_++] = l;
    } else {
      changes(l.receiver);
      kept_.push_back(l);
    }
  }

  bool refines(size_t i, const ClusterLink& l) const {
    return l.receiver == l.shooter || refineAll_ || fate_[i] == Fate::kRefine ||
           fate_[i] == Fate::kRefineNear;
  }
  bool drops(size_t i, const ClusterLink& l) const {
    return l.receiver != l.shooter && !refineAll_ && fate_[i] == Fate::kDrop;
  }

  // One level: the tests, the children (in parallel where the link bound allows), then the
  // decisions in link order; the children become the next level.
  template <class LinkAt>
  void refineLevel(size_t size, LinkAt&& linkAt) {
    testLevel(size, linkAt);
    std::vector<LinkEnds> next;
    const bool parallel = expandInParallel(size, linkAt, next);
    decideInOrder(size, linkAt, parallel, next);
    work_.swap(next);
  }

  // The refinement test of every link first, in parallel (a pure function of the link): the
  // serial loop of decideInOrder still decides in link order, so the links and their order are
  // the same.
  template <class LinkAt>
  void testLevel(size_t size, LinkAt& linkAt) {
    fate_.assign(refineAll_ ? 0 : size, Fate::kKeep);
    if (!refineAll_)
      tbb::parallel_for(size_t(0), size, [&](size_t i) {
        const ClusterLink l = linkAt(i);
        fate_[i] = l.receiver != l.shooter ? c_.fateOf(l, epsAbs_) : Fate::kRefine;
      });
  }

  // The children in parallel, in chunks of a fixed size (so the same whatever the thread
  // count): counted, then written at the offsets the counts give, in link order as the serial
  // loop would. Only where the link bound cannot be reached within the level, which the serial
  // loop checks link by link (a chunk's count bounds what its links add). Returns whether the
  // children were made here.
  template <class LinkAt>
  bool expandInParallel(size_t size, LinkAt& linkAt, std::vector<LinkEnds>& next) {
    constexpr size_t kChunk = 2048;
    const size_t chunks = (size + kChunk - 1) / kChunk;
    std::vector<Counter> counted(chunks);
    bool parallel = !overBudget_;
    if (parallel) {
      tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
        for (size_t i = c * kChunk; i < std::min(size, (c + 1) * kChunk); ++i) {
          const ClusterLink l = linkAt(i);
          if (refines(i, l)) c_.expand(l, counted[c]);
        }
      });
      size_t added = made_ + patchPairs_.size();
      for (const Counter& c : counted) {
        added += c.links + c.pairs;
        parallel = parallel && added <= budget_ + count_;
      }
    }
    if (parallel) {
      std::vector<size_t> linkAt0(chunks + 1, 0), pairAt0(chunks + 1, patchPairs_.size());
      for (size_t c = 0; c < chunks; ++c) {
        linkAt0[c + 1] = linkAt0[c] + counted[c].links;
        pairAt0[c + 1] = pairAt0[c] + counted[c].pairs;
      }
      next.resize(linkAt0[chunks]);
      patchPairs_.resize(pairAt0[chunks]);
      tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
        Writer w{next.data() + linkAt0[c], patchPairs_.data() + pairAt0[c]};
        for (size_t i = c * kChunk; i < std::min(size, (c + 1) * kChunk); ++i) {
          const ClusterLink l = linkAt(i);
          if (refines(i, l)) c_.expand(l, w);
        }
      });
      made_ += next.size();
    }
    return parallel;
  }

  // The decisions in link order (the children already made when `parallel`). Past the link
  // bound only the lights' links go on (as far as the light share asks): a light left inside a
  // cluster link reaches its receivers without shadows, so stopping wherever the bound fell
  // would lose the lights' bad pairs. A refined link is replaced by its children, so it no
  // longer counts (count_ of them this call).
  template <class LinkAt>
  void decideInOrder(size_t size, LinkAt& linkAt, bool parallel, std::vector<LinkEnds>& next) {
    Appender append{next, patchPairs_, made_};
    for (size_t i = 0; i < size; ++i) {
      const ClusterLink l = linkAt(i);
      current_ = i;
      if (!parallel && made_ + patchPairs_.size() > budget_ + count_) overBudget_ = true;
      if (drops(i, l)) {  // gone, as a refined link is, with no children
        c_.nearTests_.push_back({l.receiver, l.shooter, 1});
        if (firstLevel_) changes(l.receiver);
        ++count_;
        continue;
      }
      if (overBudget_ && !c_.emits(l.shooter)) {
        keep(l);
        continue;
      }
      if (!refines(i, l)) {
        keep(l);
        continue;
      }
      if (!parallel) c_.expand(l, append);
      if (!refineAll_ && l.receiver != l.shooter && fate_[i] == Fate::kRefineNear)
        c_.nearTests_.push_back({l.receiver, l.shooter, 0});
      if (firstLevel_) changes(l.receiver);
      ++count_;
    }
  }

  ClusterLinks& c_;
  const double epsAbs_;
  const bool refineAll_;
  const size_t budget_;
  std::vector<std::pair<int, int>>& patchPairs_;
  bool& overBudget_;
  std::vector<ClusterLink> kept_;
  size_t firstSize_ = 0, written_ = 0;
  bool firstLevel_ = true;
  bool remap_ = false;
  size_t T_ = 0;
  std::vector<uint32_t> moved_;
  std::vector<char> changed_;
  size_t current_ = 0;  // the first level's index of the link at hand
  std::vector<LinkEnds> work_;
  size_t made_ = 0, count_ = 0;
  std::vector<Fate> fate_;  // per link of the level: fateOf (empty: refineAll_)
};

size_t ClusterLinks::refine(double epsAbs, bool refineAll, size_t budget,
                            std::vector<std::pair<int, int>>& patchPairs, bool& overBudget) {
  return RefineRound(*this, epsAbs, refineAll, budget, patchPairs, overBudget).run();
}

void ClusterLinks::evaluate() {
  std::vector<uint32_t> fresh;  // the links not evaluated yet, in link order
  for (size_t i = 0; i < links_.size(); ++i)
    if (!links_[i].evaluated) fresh.push_back(uint32_t(i));
  if (fresh.empty()) return;
  // Their V at their cluster receivers' members: one byte a member, placed in link order (past
  // 4 GiB of them, which no scene here comes near, the members take their group's V).
  if (memberRays_ > 0) {
    size_t at = memberVisibility_.size();
    for (uint32_t i : fresh) {
      ClusterLink& l = links_[i];
      if (!isCluster(l.receiver)) continue;
      const size_t count = tree_.node(clusterIndex(l.receiver)).count;
      if (at + count >= size_t(ClusterLink::kNoMemberVisibility)) break;
      l.memberVisibility = uint32_t(at);
      at += count;
    }
    memberVisibility_.resize(at, 255);
  }
  tbb::parallel_for(size_t(0), fresh.size(), [&](size_t k) { evaluateLink(links_[fresh[k]]); });
  listsValid_ = false;
}

bool ClusterLinks::mayFace(uint32_t t, const ClusterBounds& box) const {
  const glm::dvec3& n = normal_[t];
  double farthest = 0.0;  // the largest n . x over the box
  for (int a = 0; a < 3; ++a) farthest += n[a] * (n[a] > 0.0 ? box.hi[a] : box.lo[a]);
  return farthest > glm::dot(n, centroid_[t]);
}

ClusterLinks::RayPair ClusterLinks::rayPair(ClusterRef r, ClusterRef s, int i, int k) const {
  const uint64_t seed = clusterLinkSeed(r, s);
  // A shooter holding lights is sampled by emitted power: its light comes from them, and the
  // visibility of its area (a ceiling's, the lights a small part of it) is not that of its light.
  const std::vector<double>& shooterPrefix = emits(s) ? memberPowerPrefix_ : memberAreaPrefix_;
  // Each end's member is drawn among those that may face the other end (its plane has some of
  // the other's bounding box in front): a pair with a member facing away has kernel 0 and
  // counts for nothing, and with a cluster's six facing groups most area-uniform pairs had
  // been such (two boxes: 1 of 36). Up to kFacingTries draws, by area (power) as before among
  // the members that face; V = open kernel / kernel is the same quantity over them, from more
  // pairs.
  auto pickFacing = [&](ClusterRef ref, ClusterRef other, int side,
                        const std::vector<double>& prefix) -> uint32_t {
    return drawFacingMember(ref, bounds(other), prefix, [&](int t) {
      return uniformOpen01(seed, t == 0 ? uint64_t(i) * 6 + uint64_t(side)
                                        : uint64_t(k) * 6 +
                                              (uint64_t(i) * kFacingTries + uint64_t(t)) * 2 +
                                              uint64_t(side));
    });
  };
  const uint64_t c = uint64_t(i) * 6;
  RayPair p;
  p.a = pickFacing(r, s, 0, memberAreaPrefix_);
  p.b = pickFacing(s, r, 1, shooterPrefix);
  p.x = pointOnPolygon(world_[p.a], uniformOpen01(seed, c + 2), uniformOpen01(seed, c + 3));
  p.y = pointOnPolygon(world_[p.b], uniformOpen01(seed, c + 4), uniformOpen01(seed, c + 5));
  const glm::dvec3 xy = p.y - p.x;
  const double len2 = glm::dot(xy, xy);
  p.kernel = len2 > 0.0 ? std::max(0.0, glm::dot(world_[p.a].normal(), xy)) *
                              std::max(0.0, -glm::dot(world_[p.b].normal(), xy)) / (len2 * len2)
                        : 0.0;
  return p;
}

bool ClusterLinks::near(ClusterRef r, ClusterRef s) const {
  const ClusterBounds& R = bounds(r);
  const ClusterBounds& S = bounds(s);
  return !(glm::length(S.centre() - R.centre()) > separation_ * (R.radius() + S.radius()));
}

void ClusterLinks::countInto(LinkCensus& census) const {
  auto sizeOf = [&](ClusterRef r, ClusterRef s) {
    return size_t(LinkCensus::sizeClass(std::max(memberCount(r), memberCount(s))));
  };
  for (const ClusterLink& l : links_) {
    LinkCensus::BySize& kind = emits(l.shooter)              ? census.clusterLight
                               : near(l.receiver, l.shooter) ? census.clusterNear
                                                             : census.clusterFar;
    ++kind[sizeOf(l.receiver, l.shooter)];
  }
  for (const NearLinkTest& t : nearTests_) {
    LinkCensus::BySize& kind = t.blocked ? census.nearDropped
                               : visibility_ && tooManyPairsToTest(t.receiver, t.shooter) &&
                                       !sampleTested(t.receiver, t.shooter)
                                   ? census.nearUntested
                                   : census.nearRefined;
    ++kind[sizeOf(t.receiver, t.shooter)];
  }
}

void ClusterLinks::evaluateLink(ClusterLink& l) {
  l.evaluated = true;
  if (reuse_) {  // the values recomputing would give (static ends, no moving object near)
    const size_t T = emission_.size();
    if (const CachedClusterLink* c =
            reuse_->find(clusterLinkEnd(l.receiver, T), clusterLinkEnd(l.shooter, T))) {
      l.direction = c->direction;
      l.visibility = c->visibility;
      l.groupVisibility = c->groupVisibility;
      if (l.memberVisibility != ClusterLink::kNoMemberVisibility &&
          c->memberVisibility != ClusterLink::kNoMemberVisibility) {
        const auto from = reuse_->memberVisibility.begin() + long(c->memberVisibility);
        std::copy(from, from + long(tree_.node(clusterIndex(l.receiver)).count),
                  memberVisibility_.begin() + long(l.memberVisibility));
      } else {
        l.memberVisibility = ClusterLink::kNoMemberVisibility;
      }
      ++reused_;
      return;
    }
  }
  const ClusterBounds& R = bounds(l.receiver);
  const ClusterBounds& S = bounds(l.shooter);
  const glm::dvec3 d = S.centre() - R.centre();
  const double r2 = glm::dot(d, d);
  if (!(r2 > 0.0)) return;
  l.direction = glm::vec3(d / std::sqrt(r2));
  // V: k ray pairs between area-uniform points of R's and S's patches, kernel-weighted.
  double v = 1.0;
  if (visibility_) {
    // The pairs first, then the rays: where some pair's kernel is positive, V = open kernel /
    // kernel, and the rays of pairs whose kernel is 0 (facing away: a chair's back, a desk's
    // underside) count for nothing, so they are not cast. Only when every kernel is 0 does V
    // fall back to the open rays' share, and then every ray is cast.
    const int k = rays_;
    std::array<RayPair, 64> onStack;
    std::vector<RayPair> onHeap(k > 64 ? size_t(k) : 0);
    RayPair* pairs = k > 64 ? onHeap.data() : onStack.data();
    double sumK = 0.0;
    for (int i = 0; i < k; ++i) {
      pairs[size_t(i)] = rayPair(l.receiver, l.shooter, i, k);
      sumK += pairs[size_t(i)].kernel;
    }
    // V per facing group of R's members, from the same pairs: one V for a receiver cluster
    // spreads the light its open members see over its occluded ones (a chair's seat under a
    // desk and its back in the open: the back, the one seen, came out dark).
    const bool perGroup = isCluster(l.receiver) && sumK > 0.0;
    std::array<double, 6> groupK{}, groupOpenK{};
    int positive = 0;  // the pairs with a kernel (the only ones cast when perGroup)
    double openK = 0.0;
    int open = 0;
    for (int i = 0; i < k; ++i) {
      const RayPair& p = pairs[size_t(i)];
      if (sumK > 0.0 && !(p.kernel > 0.0)) continue;
      const bool isOpen = !visibility_->occluded(p.x, p.y, p.a, p.b);
      open += isOpen ? 1 : 0;
      openK += isOpen ? p.kernel : 0.0;
      if (perGroup) {
        ++positive;
        const size_t g = size_t(facingGroupOf(normal_[p.a]));
        groupK[g] += p.kernel;
        groupOpenK[g] += isOpen ? p.kernel : 0.0;
      }
    }
    v = sumK > 0.0 ? openK / sumK : double(open) / double(k);
    if (perGroup) {
      const double prior = kGroupPrior * sumK / double(positive);
      for (size_t g = 0; g < 6; ++g)
        l.groupVisibility[g] =
            quantizedVisibility((groupOpenK[g] + prior * v) / (groupK[g] + prior));
    } else {
      l.groupVisibility.fill(quantizedVisibility(v));
    }
  }
  l.visibility = float(v);
  if (l.memberVisibility != ClusterLink::kNoMemberVisibility) {
    const ClusterNode& n = tree_.node(clusterIndex(l.receiver));
    for (uint32_t m = 0; m < n.count; ++m)
      memberVisibility_[size_t(l.memberVisibility) + m] =
          visibilityAtMember(l, tree_.members()[n.first + m]);
  }
}

uint8_t ClusterLinks::visibilityAtMember(const ClusterLink& l, uint32_t t) const {
  const uint8_t groupV = l.groupVisibility[size_t(facingGroupOf(normal_[t]))];
  if (!visibility_) return groupV;
  // A member with all of the shooter's box behind its plane sees none of it (F = 0 there).
  if (!mayFace(t, bounds(l.shooter))) return groupV;
  const glm::dvec3& n = normal_[t];
  const uint64_t seed = splitMix64(clusterLinkSeed(l.receiver, l.shooter) ^
                                   (0x6d656d626572ull + uint64_t(t) * 0x9e3779b97f4a7c15ull));
  const std::vector<double>& prefix = emits(l.shooter) ? memberPowerPrefix_ : memberAreaPrefix_;
  constexpr uint64_t kPerPair = 4 + kFacingTries;  // counters a pair draws from
  double kernel = 0.0, openKernel = 0.0;
  for (int i = 0; i < memberRays_; ++i) {
    const uint64_t c = uint64_t(i) * kPerPair;
    const uint32_t j = drawFacingMember(l.shooter, topBounds_[t], prefix, [&](int k) {
      return uniformOpen01(seed, c + 4 + uint64_t(k));
    });
    const glm::dvec3 x =
        pointOnPolygon(world_[t], uniformOpen01(seed, c), uniformOpen01(seed, c + 1));
    const glm::dvec3 y =
        pointOnPolygon(world_[j], uniformOpen01(seed, c + 2), uniformOpen01(seed, c + 3));
    const glm::dvec3 xy = y - x;
    const double len2 = glm::dot(xy, xy);
    if (!(len2 > 0.0)) continue;
    const double k =
        std::max(0.0, glm::dot(n, xy)) * std::max(0.0, -glm::dot(normal_[j], xy)) / (len2 * len2);
    if (!(k > 0.0)) continue;
    kernel += k;
    if (!visibility_->occluded(x, y, t, j)) openKernel += k;
  }
  return kernel > 0.0 ? quantizedVisibility(openKernel / kernel) : groupV;
}

// F(top t <- S) of a link at t's centroid: H_i / B_S of the transfer at the top of
// cluster_links.h, summed over S's facing cells (a top-level patch shooter is its own cell).
double ClusterLinks::formFactor(const ClusterLink& l, uint32_t t, double exposure) const {
  const double radius = isCluster(l.shooter) ? clusterRadius_[size_t(clusterIndex(l.shooter))]
                                             : topRadius_[size_t(l.shooter)];
  const glm::dvec3 x = centroid_[t], n = normal_[t];
  // One facing group: max(0, -N_g . d) max(0, n_i . d) / |d|^4. A link kept at the link bound
  // may have receivers within S's reach; S's patches are spread over its bounding sphere, so
  // the distance is taken as at least its radius.
  // Isotropic (see the top of this file): a shooter cluster's group shows A_g / 4 in every
  // direction, a receiver cluster's member takes 1/4 for its cosine.
  const bool isotropicShooter = isotropic_ && isCluster(l.shooter);
  const bool isotropicReceiver = isotropic_ && isCluster(l.receiver);
  auto group = [&](const glm::dvec3& normalArea, double area, const glm::dvec3& centre) {
    const glm::dvec3 d = centre - x;
    const double r2 = glm::dot(d, d);
    // |d| only where a cluster end is isotropic: the oriented gather (every entry of every key's
    // lists) takes no square root.
    const double length = isotropic_ ? std::sqrt(r2) : 0.0;
    const double shown = isotropicShooter ? 0.25 * area * length : -glm::dot(normalArea, d);
    const double seen = isotropicReceiver ? 0.25 * length : glm::dot(n, d);
    const double cosines = std::max(0.0, shown) * std::max(0.0, seen);
    if (!(cosines > 0.0)) return 0.0;
    const double rs2 = std::max(r2, radius * radius);
    return cosines / (r2 * rs2);
  };
  double sum = 0.0;
  if (isCluster(l.shooter)) {
    const size_t c = size_t(clusterIndex(l.shooter));
    for (uint32_t g = facingStart_[c]; g < facingStart_[c + 1]; ++g)
      sum += group(glm::dvec3(facingCells_[g].normalArea), double(facingCells_[g].area),
                   glm::dvec3(facingCells_[g].centre));
  } else {
    const size_t s = size_t(l.shooter);
    sum = group(area_[s] * normal_[s], area_[s], centroid_[s]);
  }
  // A receiver cluster's member takes its own V where it is wholly exposed, else the V of its
  // facing group (evaluateLink): its own rays start all over it, the covered part included,
  // while the gather takes a link at an ancestor cluster as the exposed part's (gather).
  double v = double(l.visibility);
  if (isCluster(l.receiver)) {
    const uint32_t first = tree_.node(clusterIndex(l.receiver)).first;
    v = (l.memberVisibility != ClusterLink::kNoMemberVisibility && exposure >= 1.0
             ? double(memberVisibility_[size_t(l.memberVisibility) + memberPosition_[t] - first])
             : double(l.groupVisibility[size_t(facingGroupOf(n))])) /
        255.0;
  }
  return v / M_PI * sum;
}

std::pair<const ClusterLinks::GatherEntry*, const ClusterLinks::GatherEntry*>
ClusterLinks::entriesOf(size_t t) const {
  const std::vector<GatherEntry>& entries = gatherBlocks_[t / kGatherBlockTops];
  const size_t end = (t + 1) % kGatherBlockTops != 0 && t + 1 < gatherStart_.size()
                         ? gatherStart_[t + 1]
                         : entries.size();
  return {entries.data() + gatherStart_[t], entries.data() + end};
}

template <class Sum, class Term>
Sum ClusterLinks::overExposedPart(size_t t, const std::vector<double>& exposure, Term term) const {
  const double e = exposure.empty() ? 1.0 : exposure[t];
  if (!(e > 0.0)) return Sum(0.0);
  const auto [b, end] = entriesOf(t);
  const GatherEntry* ownEnd = b + gatherOwn_[t];  // the links at t come first
  Sum own(0.0), above(0.0);
  for (const GatherEntry* i = b; i != ownEnd; ++i) own += term(*i);
  for (const GatherEntry* i = ownEnd; i != end; ++i) above += term(*i);
  return own / e + above;
}

void ClusterLinks::buildReceiverLists(const std::vector<double>& exposure) {
  if (listsValid_) return;
  const size_t T = emission_.size(), C = size_t(tree_.size());
  // The lists of the links before the last refinement round, where it left them (movedTo_): a top
  // none of whose receivers (itself, its ancestor clusters) gained or lost a link keeps its
  // entries, the links renumbered; the others are made anew. At the link bound a key takes many
  // rounds, each refining a few of the lights' links, and rebuilding every list each round would
  // redo the lists of the many tops whose links did not change.
  const bool remap = !movedTo_.empty() && gatherStart_.size() == T;
  if (!remap)  // the stale lists go before the new ones are made: never both held at once
    std::vector<std::vector<GatherEntry>>().swap(gatherBlocks_);
  // Per receiver (tops 0..T-1, then the clusters): its active links in link order (the links
  // not evaluated go to one more row, left unread).
  const RowOrder byReceiver = sortByRow(links_.size(), uint32_t(T + C + 1), [&](size_t i) {
    const ClusterLink& l = links_[i];
    if (!l.evaluated) return uint32_t(T + C);
    return uint32_t(isCluster(l.receiver) ? T + size_t(clusterIndex(l.receiver))
                                          : size_t(l.receiver));
  });
  // Top t's entries: the links at it, then at its ancestor clusters, where F > 0, written into its
  // block of tops. One array for all tops would need their counts first: the pairs held per top
  // until then would sit beside the lists themselves, and counting by computing F twice would
  // double the form factors' cost; a block of tops, filled as it is made, needs neither.
  const size_t blocks = (T + kGatherBlockTops - 1) / kGatherBlockTops;
  gatherBlocks_.resize(blocks);
  std::vector<uint32_t> start(T, 0), own(T, 0);
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
    std::vector<GatherEntry> entries;
    for (size_t t = b * kGatherBlockTops; t < std::min(T, (b + 1) * kGatherBlockTops); ++t) {
      start[t] = uint32_t(entries.size());
      bool keepOld = remap && !changedReceiver_[t];
      for (int c = tree_.parentOfTop(int(t)); keepOld && c >= 0; c = tree_.node(c).parent)
        keepOld = !changedReceiver_[T + size_t(c)];
      if (keepOld) {
        const auto [first, last] = entriesOf(t);
        for (const GatherEntry* e = first; e != last; ++e)
          entries.push_back({movedTo_[e->link], e->formFactor});
        own[t] = gatherOwn_[t];
        continue;
      }
      auto add = [&](size_t r) {
        for (uint32_t k = byReceiver.rowStart[r]; k < byReceiver.rowStart[r + 1]; ++k) {
          const uint32_t i = byReceiver.order[k];
          const double f = formFactor(links_[i], uint32_t(t), exposure.empty() ? 1.0 : exposure[t]);
          if (f > 0.0) entries.push_back({i, float(f)});
        }
      };
      add(t);
      own[t] = uint32_t(entries.size()) - start[t];
      for (int c = tree_.parentOfTop(int(t)); c >= 0; c = tree_.node(c).parent) add(T + size_t(c));
    }
    entries.shrink_to_fit();
    gatherBlocks_[b].swap(entries);
  });
  gatherStart_.swap(start);
  gatherOwn_.swap(own);
  std::vector<uint32_t>().swap(movedTo_);
  std::vector<char>().swap(changedReceiver_);
  listsValid_ = true;
}

// B_S as R sees it (the top of cluster_links.h). The area average of a cluster mixes what
// faces R with what does not (a table's lit top and dark underside, seen from a wall: neither),
// so each cluster keeps its radiosity per facing group, $P_g = \sum_{j \in g} A_j B_j$ and
// $A_g$, and a link weighs the groups' B_g = P_g / A_g by their projected areas towards R, as
// the transfer weighs their form factors: exact for a cluster of uniform B or of one flat
// patch. Six axis bins with squared direction weights (an estimate of the same projection that
// leaves out how each group's area is oriented) come out darker than the exact sums of B F V over
// the shooters' members with the links' V; the groups' projected areas come closer to them.
void ClusterLinks::maxOverMembers(const std::vector<glm::dvec3>& topB, std::vector<double>& top,
                                  std::vector<double>& cluster) const {
  top.resize(emission_.size());
  cluster.resize(size_t(tree_.size()));
  for (size_t t = 0; t < top.size(); ++t) top[t] = maxComponent(topB[t]);
  for (int c = tree_.size(); c-- > 0;) {  // sub-clusters (higher indices) first
    double maxB = 0.0;
    for (ClusterRef r : tree_.node(c).children)
      maxB = std::max(maxB, isCluster(r) ? cluster[size_t(clusterIndex(r))] : top[size_t(r)]);
    cluster[size_t(c)] = maxB;
  }
}

void ClusterLinks::setRadiosity(const std::vector<glm::dvec3>& topB) {
  maxOverMembers(topB, topMaxB_, clusterMaxB_);
  radiosityKnown_ = true;
}

void ClusterLinks::estimateRadiosity(const std::vector<glm::dvec3>& topB) {
  maxOverMembers(topB, topEstimateB_, clusterEstimateB_);
}

void ClusterLinks::gather(const std::vector<glm::dvec3>& topB, const std::vector<double>& exposure,
                          std::vector<glm::dvec3>& out) {
  buildReceiverLists(exposure);
  const size_t T = emission_.size();
  struct GroupRadiosity {
    std::array<glm::dvec3, 6> power;  // P_g by facingGroupOf
    std::array<double, 6> area;       // A_g
  };
  std::vector<GroupRadiosity> groups(size_t(tree_.size()));
  setRadiosity(topB);
  std::vector<double>().swap(topEstimateB_);  // the solved B from now on (estimateRadiosity)
  std::vector<double>().swap(clusterEstimateB_);
  for (int c = tree_.size(); c-- > 0;) {  // sub-clusters (higher indices) first
    GroupRadiosity& g = groups[size_t(c)];
    g.power.fill(glm::dvec3(0.0));
    g.area.fill(0.0);
    for (ClusterRef r : tree_.node(c).children) {
      if (isCluster(r)) {
        const GroupRadiosity& cg = groups[size_t(clusterIndex(r))];
        for (size_t k = 0; k < 6; ++k) g.power[k] += cg.power[k], g.area[k] += cg.area[k];
      } else {
        const size_t k = size_t(facingGroupOf(normal_[size_t(r)]));
        g.power[k] += area_[size_t(r)] * topB[size_t(r)];
        g.area[k] += area_[size_t(r)];
      }
    }
  }
  // Per link: its shooter's B towards its receiver.
  linkB_.assign(links_.size(), glm::vec3(0.0f));
  tbb::parallel_for(size_t(0), links_.size(), [&](size_t i) {
    const ClusterLink& l = links_[i];
    if (!l.evaluated) return;
    if (!isCluster(l.shooter)) {
      linkB_[i] = glm::vec3(topB[size_t(l.shooter)]);
      return;
    }
    const GroupRadiosity& g = groups[size_t(clusterIndex(l.shooter))];
    const size_t c = size_t(clusterIndex(l.shooter));
    glm::dvec3 num(0.0);
    double den = 0.0;
    for (uint32_t k = facingStart_[c]; k < facingStart_[c + 1]; ++k) {
      const FacingGroup& fg = facingCells_[k];
      const double w =
          isotropic_ ? double(fg.area)
                     : std::max(0.0, -glm::dot(glm::dvec3(fg.normalArea), glm::dvec3(l.direction)));
      const size_t a = size_t(fg.axisSign);
      if (!(w > 0.0 && g.area[a] > 0.0)) continue;
      num += w / g.area[a] * g.power[a];
      den += w;
    }
    linkB_[i] = den > 0.0 ? glm::vec3(num / den) : glm::vec3(0.0f);
  });
  out.assign(T, glm::dvec3(0.0));
  tbb::parallel_for(size_t(0), T, [&](size_t t) {
    out[t] = overExposedPart<glm::dvec3>(t, exposure, [&](const GatherEntry& i) {
      return double(i.formFactor) * glm::dvec3(linkB_[i.link]);
    });
  });
}

std::vector<double> ClusterLinks::rowSums(const std::vector<double>& exposure) {
  // From the gather's lists, so that the row sums are of the very form factors the gather
  // multiplies, and in parallel (a pass over every link and member top would be serial).
  buildReceiverLists(exposure);
  const size_t T = emission_.size();
  std::vector<double> out(T, 0.0);
  tbb::parallel_for(size_t(0), T, [&](size_t t) {
    out[t] = overExposedPart<double>(t, exposure,
                                     [](const GatherEntry& i) { return double(i.formFactor); });
  });
  return out;
}

}  // namespace rad
