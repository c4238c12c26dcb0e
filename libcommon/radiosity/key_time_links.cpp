// The key-time solver's link passes (HSA'91 §4): the cluster links' refinement into patch
// links, evaluate (F~ and V of each new link), refine (the oracle, the larger patch split), the
// accurate pass (the quadrature F of every visible leaf link) and the radiosity-weighted
// visibility before each solve. See key_time_solver.h.
// The figures behind the reasons given here: docs/results.md, "Figures moved out of the radiosity
// code's comments (issue 55)".
#include "libcommon/radiosity/key_time_solver.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "libcommon/core/error.h"
#include "libcommon/radiosity/global_solution.h"
#include "libcommon/radiosity/pair_table.h"
#include "libcommon/radiosity/visibility.h"

namespace rad {
namespace {

// The first round's estimate of each top's B (ClusterLinks::estimateRadiosity): its emission
// and its reflectance times the ambient irradiance of a closed room, the emitted power over
// the whole area's absorption, $E_{amb} = \Phi / (A (1 - \bar\rho))$ (Cohen, Chen, Wallace,
// Greenberg 1988, the ambient term; $\bar\rho$ the area-weighted mean of the largest channel),
// `power` being the share of Phi asked for (RadiosityOptions::weakNearAmbientShare). Not a
// bound: a top near a light is brighter, and the links judged weak by the estimate are judged
// again by the solved B at the next round (fateOf).
std::vector<glm::dvec3> ambientRadiosity(const std::vector<SurfaceProperties>& surfaces,
                                         const std::vector<double>& area, double power) {
  double absorbing = 0.0;
  for (size_t t = 0; t < surfaces.size(); ++t) {
    const glm::dvec3& rho = surfaces[t].reflectance;
    absorbing += area[t] * (1.0 - std::max(rho.x, std::max(rho.y, rho.z)));
  }
  const double ambient = absorbing > 0.0 ? power / absorbing : 0.0;
  std::vector<glm::dvec3> B(surfaces.size());
  for (size_t t = 0; t < surfaces.size(); ++t)
    B[t] = surfaces[t].emission + surfaces[t].reflectance * ambient;
  return B;
}

}  // namespace

// Cluster links (cluster_links.h): one round of their refinement with this round's B and
// threshold (all the way down to patch pairs when refinement is off: the all-pairs linking);
// the pairs of top-level patches reached become patch links, appended in the order reached.
size_t KeyTimeSolver::refineClusterLinks() {
  std::vector<std::pair<int, int>> pairs;
  const size_t held = s_.links.size() + clusters_->size();
  const size_t budget = opt_.maxLinks > held ? opt_.maxLinks - held : 0;
  bool overBudget = false;
  // The first round's B (the lights' emission, 0 elsewhere), so that near links are judged by
  // what they can carry from the start (cluster_links.h).
  if (!clusters_->radiosityKnown()) {
    clusters_->setRadiosity(B_);
    if (opt_.keepWeakNearLinks)
      clusters_->estimateRadiosity(
          ambientRadiosity(surfaces_, s_.area, opt_.weakNearAmbientShare * emittedPower_));
  }
  const size_t refined = clusters_->refine(epsAbs_, !refineOn_, budget, pairs, overBudget);
  if (overBudget || s_.links.size() + clusters_->size() + pairs.size() > opt_.maxLinks)
    s_.linkCapReached = true;
  if (topPlanes_.empty()) {  // the tops' planes at this key, once
    topPlanes_.resize(size_t(h_.topCount()));
    tbb::parallel_for(size_t(0), topPlanes_.size(),
                      [&](size_t t) { topPlanes_[t] = facingPlane(s_.world[t]); });
  }
  std::vector<char> facing(pairs.size());
  tbb::parallel_for(size_t(0), pairs.size(), [&](size_t i) {
    const size_t r = size_t(pairs[i].first), q = size_t(pairs[i].second);
    facing[i] = s_.area[r] > 0 && s_.area[q] > 0 &&
                mutuallyFacing(s_.world[r], topPlanes_[r], s_.world[q], topPlanes_[q]);
  });
  for (size_t i = 0; i < pairs.size(); ++i)
    if (facing[i]) {
      SolverLink l;
      l.receiver = pairs[i].first;
      l.shooter = pairs[i].second;
      s_.links.push_back(l);
    }
  clusters_->evaluate();
  // The previous key's cluster links go after the first round, for the peak (most links are
  // made at it). Not with keepWeakNearLinks: the first round keeps the near links that are
  // weak by the estimate of B (estimateRadiosity), some of which the solved B refines at the
  // later rounds, and the links below them would then be computed afresh at every key (paper
  // §4.2's coherence lost for them; docs/results.md, "Near cluster links kept"): the cache is
  // held to the key's end.
  if (input_.releaseClusterLinks && clusters_->reusing() && !opt_.keepWeakNearLinks) {
    clusters_->forgetReuse();
    input_.releaseClusterLinks();
  }
  return refined;
}

// Per node of this key's tree: the range (max - min over the colour channel of largest
// range) of B over the leaves below it, from the last solve; 0 for a leaf.
void KeyTimeSolver::measureShooterRanges() {
  const size_t N = size_t(h_.size());
  std::vector<glm::dvec3> lo(N), hi(N);
  shooterRange_.assign(N, 0.0);
  for (size_t i = N; i-- > 0;) {  // children (higher indices) before their parent
    if (!s_.inTree(int(i), h_)) continue;
    if (!s_.split[i]) {
      lo[i] = hi[i] = B_[i];
      continue;
    }
    const int first = h_.node(int(i)).firstChild;
    lo[i] = lo[size_t(first)], hi[i] = hi[size_t(first)];
    for (int c = 1; c < 4; ++c) {
      lo[i] = glm::min(lo[i], lo[size_t(first + c)]);
      hi[i] = glm::max(hi[i], hi[size_t(first + c)]);
    }
    shooterRange_[i] = maxComponent(hi[i] - lo[i]);
  }
}

// Evaluate: the oracle's estimate F~ (and spread) and the visibility V of every link made
// since the last call, in parallel (each link writes only itself).
void KeyTimeSolver::evaluateNewLinks() {
  size_t begin = evaluated_, end = s_.links.size();
  exposeReceivers(begin, end);  // their covered points' pairs count as blocked
  tbb::parallel_for(begin, end, [&](size_t li) { evaluateLink(s_.links[li]); });
  evaluated_ = end;
}

void KeyTimeSolver::evaluateLink(SolverLink& l) const {
  const PatchNode& r = h_.node(l.receiver);
  const PatchNode& q = h_.node(l.shooter);
  const Polygon& P = s_.world[size_t(l.receiver)];
  const Polygon& Q = s_.world[size_t(l.shooter)];
  auto shadowRays = [&] {
    l.openPairs = ~uint64_t(0);
    return input_.visibility ? input_.visibility->visibilityFrom(
                                   VisibilityScene::samplePoints(P, opt_.rays, receiverSeed(r.id)),
                                   P.normal(), Q, linkSeed(r.id, q.id), r.id.top, q.id.top,
                                   &l.openPairs, coveredPoints_[size_t(l.receiver)])
                             : 1.0;
  };
  if (input_.reuse) {
    const uint32_t known = input_.reuse->indexOf(uint32_t(l.receiver), uint32_t(l.shooter));
    if (known != LinkCache::kNotFound) {
      // The values, never a decision: F starts as the estimate as in a fresh evaluation,
      // and the accurate pass takes the known accurate F instead of integrating again.
      const CachedLink& c = input_.reuse->value(known);
      l.known = known;
      l.estimate = c.estimate;
      l.spreadArea = c.spreadArea;
      l.formFactor = l.estimate;
      const std::vector<uint64_t>* before = input_.reuseCoveredPoints;
      const bool sameCover =
          !before || (size_t(l.receiver) < before->size() &&
                      (*before)[size_t(l.receiver)] == coveredPoints_[size_t(l.receiver)]);
      if (c.visibilityValid && sameCover) {
        l.rayVisibility = c.visibility;
        l.openPairs = c.openPairs;
        l.reused = true;
      } else {
        l.rayVisibility = shadowRays();
        l.visibilityOnly = true;
      }
      l.visibility = l.rayVisibility;
      return;
    }
  }
  double ap = s_.area[size_t(l.receiver)], aq = s_.area[size_t(l.shooter)];
  // Both directions: the centroid estimate alone can miss a near-contact pair.
  const double fpq = formFactorEstimate(P, Q), fqp = formFactorEstimate(Q, P);
  l.estimate = float(std::min(1.0, std::max(fpq, fqp * aq / ap)));
  l.formFactor = l.estimate;
  if (opt_.oracle != RefinementOracle::kPower)
    l.spreadArea =
        float(std::max(ap * formFactorSpread(P, Q, fpq), aq * formFactorSpread(Q, P, fqp)));
  l.rayVisibility = shadowRays();
  l.visibility = l.rayVisibility;
}

// Radiosity-weighted visibility (before each solve): a link's shooter bright where the receiver
// cannot see it and dim where it can (the ceiling above a double-sided lamp 2 cm under it: the
// bright spot is hidden by the lamp) carries $\int B V$, not $\bar B \bar V$. The
// mean-B-times-mean-V product lets the spot's light out into the room (contact.py lamp-two-sided).
// A link whose shooter is split in this key's tree and whose rays are partly blocked weights each
// ray pair by the radiosity of the shooter's leaf at its end, from the last solve (the same pairs:
// no new rays). Fully visible or fully hidden links are unchanged, and so are links to a leaf
// shooter (constant B).
//
// The same pairs give the shooter's B as the receiver sees it, open or not: their kernel-weighted
// mean of the leaves' B over B_q (shooterShape), which the gather multiplies in. A coarse link
// (ceiling <- wall) would gather the wall's mean B, but the ceiling sees mostly the wall's upper
// part, which the lamp lights best: with the mean alone (--no-shooter-shape) a coarse ceiling comes
// out below its converged B.
void KeyTimeSolver::weightVisibilityByShooterRadiosity() {
  if (!input_.visibility) return;
  const int k = std::max(opt_.rays, 1);
  if (k > VisibilityScene::kMaxRecordedPairs) {  // open pairs not recorded: rays again
    tbb::parallel_for(size_t(0), s_.links.size(),
                      [&](size_t li) { weightLinkVisibility(s_.links[li]); });
    return;
  }
  // The links weighted for the first time in this key solve get their pairs (kernel, the shooter's
  // (u,v) at each pair's end): the previous key's for a link coherence took over (both ends static,
  // so the same values), else made here; every round after takes them over, as this key's geometry
  // and rays do not change between rounds, so a link's points, kernels and (u,v) are made once a
  // key, not at every round.
  const size_t L = s_.links.size();
  pairStart_.resize(L, kNoRayPairs);
  // The links without pairs yet, in link order (found in parallel parts).
  RowOrder withPairs = sortByRow(L, 2u, [&](size_t li) {
    return pairStart_[li] == kNoRayPairs && weighted(s_.links[li]) ? 0u : 1u;
  });
  std::vector<uint32_t> fresh = std::move(withPairs.order);
  fresh.resize(withPairs.rowStart[1]);
  // Pair starts are 32-bit (kNoRayPairs): 4 M links (the default --max-links) of 64 pairs
  // stay far below; a link bound raised past a billion pairs is refused, not wrapped.
  if (pairs_.size() + fresh.size() * size_t(k) >= size_t(kNoRayPairs))
    throw Error(ExitCode::kEnvironment, "",
                "more than 4 G shadow-ray pairs in one key time; lower --max-links or --rays");
  // Reserved at their first use, not when the solve starts: the cluster refinement before it holds
  // a level of links and its children at once, and the pairs reserved beside the two would raise
  // rad-global's peak.
  if (pairs_.capacity() == 0 && input_.expectedRayPairs > 0)
    pairs_.reserve(withMargin(input_.expectedRayPairs));
  const size_t firstFresh = pairs_.size();
  pairs_.resize(pairs_.size() + fresh.size() * size_t(k));
  tbb::parallel_for(size_t(0), fresh.size(), [&](size_t f) {
    pairStart_[fresh[f]] = uint32_t(firstFresh + f * size_t(k));
    const SolverLink& l = s_.links[fresh[f]];
    LinkRayPair* pair = &pairs_[pairStart_[fresh[f]]];
    const uint32_t knownPairs =
        l.known != SolverLink::kNotKnown ? input_.reuse->value(l.known).rayPairs : kNoRayPairs;
    if (knownPairs != kNoRayPairs && reuseRayPairs_) {
      std::copy_n(reuseRayPairs_->begin() + std::ptrdiff_t(knownPairs), k, pair);
    } else {
      const PatchNode& r = h_.node(l.receiver);
      const PatchNode& q = h_.node(l.shooter);
      const Polygon& P = s_.world[size_t(l.receiver)];
      const Polygon& Q = s_.world[size_t(l.shooter)];
      const bool triangle = Q.count == 3;
      std::vector<glm::dvec3> bPoints;
      std::vector<double> kernel;
      VisibilityScene::pairsFrom(VisibilityScene::samplePoints(P, opt_.rays, receiverSeed(r.id)),
                                 P.normal(), Q, linkSeed(r.id, q.id), bPoints, kernel);
      for (int i = 0; i < k; ++i)
        pair[i] = {glm::vec2(clampToParameterDomain(polygonUvAt(Q, bPoints[size_t(i)]), triangle)),
                   float(kernel[size_t(i)])};
    }
  });
  // The previous key's pairs are copied: they go before the pairs' leaves are made, so the two are
  // never held together.
  releaseRayPairs();
  tbb::parallel_for(size_t(0), L, [&](size_t li) {
    SolverLink& l = s_.links[li];
    l.visibility = l.rayVisibility;
    l.shooterShape = 1.0;
    if (!weighted(l)) return;
    const bool triangle = s_.world[size_t(l.shooter)].count == 3;
    const LinkRayPair* pair = &pairs_[pairStart_[li]];
    double kernel[VisibilityScene::kMaxRecordedPairs], weight[VisibilityScene::kMaxRecordedPairs];
    for (int i = 0; i < k; ++i) {
      // The leaf under the pair's end, found again at every round from the shooter (a few levels),
      // not kept per pair between rounds, which would hold 4 bytes a pair (24 with its (u,v))
      // through the key's sweeps.
      int node = l.shooter;
      glm::dvec2 uv(pair[i].uv);
      while (s_.split[size_t(node)]) node = h_.node(node).firstChild + descendToChild(uv, triangle);
      const glm::dvec3 b = B_[size_t(node)];
      kernel[i] = pair[i].kernel;
      weight[i] = b.x + b.y + b.z;
    }
    double seen = -1.0;
    const double v =
        VisibilityScene::weightedVisibilityOfPairs(k, kernel, l.openPairs, weight, nullptr, &seen);
    setWeightedVisibility(l, v, seen);
  });
}

// A link whose shooter is split in this key's tree and whose rays are not all blocked.
bool KeyTimeSolver::weighted(const SolverLink& l) const {
  return !l.refined && l.rayVisibility > 0.0 && s_.split[size_t(l.shooter)];
}

// The radiosity-weighted V, and the shooter's B as the receiver sees it (`seen`) over its
// mean, into l.
void KeyTimeSolver::setWeightedVisibility(SolverLink& l, double v, double seen) const {
  if (l.rayVisibility < 1.0) l.visibility = v;
  const glm::dvec3 mean = B_[size_t(l.shooter)];
  if (opt_.shooterShape && seen >= 0.0 && mean.x + mean.y + mean.z > 0.0)
    l.shooterShape = float(seen / (mean.x + mean.y + mean.z));
}

// weightVisibilityByShooterRadiosity for one link, its pairs made again (more rays than
// the open pairs record: cast again).
void KeyTimeSolver::weightLinkVisibility(SolverLink& l) const {
  l.visibility = l.rayVisibility;
  l.shooterShape = 1.0;
  if (!weighted(l)) return;
  const PatchNode& r = h_.node(l.receiver);
  const PatchNode& q = h_.node(l.shooter);
  const Polygon& P = s_.world[size_t(l.receiver)];
  const Polygon& Q = s_.world[size_t(l.shooter)];
  const bool triangle = Q.count == 3;
  auto radiosityAt = [&](const glm::dvec3& y) {
    int n = l.shooter;
    glm::dvec2 uv = clampToParameterDomain(polygonUvAt(Q, y), triangle);
    while (s_.split[size_t(n)]) n = h_.node(n).firstChild + descendToChild(uv, triangle);
    const glm::dvec3 b = B_[size_t(n)];
    return b.x + b.y + b.z;
  };
  double seen = -1.0;
  const double v = input_.visibility->weightedVisibilityFrom(
      VisibilityScene::samplePoints(P, opt_.rays, receiverSeed(r.id)), P.normal(), Q,
      linkSeed(r.id, q.id), r.id.top, q.id.top, &l.openPairs, radiosityAt, nullptr, &seen,
      coveredPoints_[size_t(l.receiver)]);
  setWeightedVisibility(l, v, seen);
}

// The refinement oracle (header): power max_c B_q F~ V A_p, error max_c B_q V spreadArea,
// either one, against eps * Phi.
bool KeyTimeSolver::oracleWantsRefinement(const SolverLink& l) const {
  double bv = maxComponent(B_[size_t(l.shooter)]) * l.visibility;
  // The shooter's B varies inside it (a shadow across the floor patch a box face gathers
  // from): the link's error is up to that range times F V A_p. Counted in the power oracle,
  // which otherwise sees only the shooter's mean.
  double range = size_t(l.shooter) < shooterRange_.size() ? shooterRange_[size_t(l.shooter)] : 0;
  bool power =
      std::max(bv, range * l.visibility) * l.estimate * s_.area[size_t(l.receiver)] > epsAbs_;
  // A partly visible link: a shadow boundary crosses its receiver, whose one B holds the mean
  // of its lit and shadowed parts, and rad-movies gathers that B wherever another surface sees
  // this one at close range (a box's face over the floor in the box's own shadow). What the
  // mean misplaces, B_q F~ min(V, 1 - V) A_p, is refined down to shadowEpsShare x eps.
  const double v = l.visibility;
  if (opt_.shadowEpsShare > 0.0 && v > 0.0 && v < 1.0)
    power = power || maxComponent(B_[size_t(l.shooter)]) * std::min(v, 1.0 - v) * l.estimate *
                             s_.area[size_t(l.receiver)] >
                         opt_.shadowEpsShare * epsAbs_;
  bool error = bv * l.spreadArea > epsAbs_;
  return opt_.oracle == RefinementOracle::kPower   ? power
         : opt_.oracle == RefinementOracle::kError ? error
                                                   : power || error;
}

// Which node a link would split, or -1 (HSA'91: the larger one, if above minArea).
int KeyTimeSolver::nodeToSplit(const SolverLink& l) const {
  int a = l.receiver, b = l.shooter;
  if (s_.area[size_t(b)] > s_.area[size_t(a)]) std::swap(a, b);
  for (int n : {a, b})
    if (s_.area[size_t(n)] > opt_.minArea && h_.node(n).id.level() < PatchId::kMaxLevel) return n;
  return -1;
}

// Subdivides `node` (one end of link li) and replaces the link by its four children's links,
// whose indices go to `next`.
void KeyTimeSolver::splitLink(LinkIndex li, int node, std::vector<LinkIndex>& next) {
  const SolverLink l = s_.links[li];  // a copy: push_back below may move the links
  bool fresh = !s_.split[size_t(node)];
  int first = h_.subdivide(node);
  addNewNodes();
  s_.split[size_t(node)] = 1;
  if (fresh)  // children enter this key's tree with their parent's radiosity
    for (int c = 0; c < 4; ++c) B_[size_t(first + c)] = B_[size_t(node)];
  s_.links[li].refined = true;
  for (int c = 0; c < 4; ++c) {
    SolverLink child;
    child.receiver = node == l.receiver ? first + c : l.receiver;
    child.shooter = node == l.receiver ? l.shooter : first + c;
    next.push_back(LinkIndex(s_.links.size()));
    s_.links.push_back(child);
  }
}

// Refine: the links of `work`, and the links that makes, until the oracle is satisfied
// (each generation evaluated first). Returns the number of links refined.
size_t KeyTimeSolver::refine(std::vector<LinkIndex> work) {
  size_t count = 0;
  while (!work.empty()) {
    evaluateNewLinks();
    // Per link, the node it splits (-1: none), in parallel first: the oracle and the choice are
    // pure functions of the link, of B and of the nodes' areas, which splitting other links of this
    // generation does not change (a new node's B is its parent's, and an existing node keeps its
    // own), so the decisions below are the same as if asked one link after the other.
    std::vector<int> splits(work.size());
    tbb::parallel_for(size_t(0), work.size(), [&](size_t j) {
      const SolverLink& l = s_.links[work[j]];
      splits[j] = !l.refined && oracleWantsRefinement(l) ? nodeToSplit(l) : -1;
    });
    std::vector<LinkIndex> next;
    for (size_t j = 0; j < work.size(); ++j) {
      const int node = splits[j];
      if (node < 0) continue;
      const LinkIndex li = work[j];
      // The memory bound, on the patch and the cluster links together (refineClusterLinks):
      // stop refining. The kept weak near links stay cluster links to the key's end.
      if (s_.links.size() + (clusters_ ? clusters_->size() : 0) + 4 > opt_.maxLinks) {
        s_.linkCapReached = true;
        evaluateNewLinks();  // this generation's links, made before the bound, get F~ and V
        return count;
      }
      splitLink(li, node, next);
      ++count;
    }
    work.swap(next);
  }
  return count;
}

std::vector<KeyTimeSolver::LinkIndex> KeyTimeSolver::unrefinedLinks() const {
  // A row order with the refined links last (one scan of the links in parallel parts).
  RowOrder order =
      sortByRow(s_.links.size(), 2u, [&](size_t i) { return s_.links[i].refined ? 1u : 0u; });
  order.order.resize(order.rowStart[1]);
  return std::move(order.order);
}

// Accurate pass: the quadrature F (linkFormFactor) of every visible leaf link not yet
// computed, or the accurate F the previous key time already computed (coherence).
void KeyTimeSolver::computeAccurateFormFactors() {
  std::vector<LinkIndex> fresh;  // the links whose F is integrated here
  for (size_t li = 0; li < s_.links.size(); ++li) {
    SolverLink& l = s_.links[li];
    if (l.refined || l.accurate) continue;
    l.accurate = true;
    if (!(l.rayVisibility > 0.0)) continue;
    l.integrated = true;
    const double knownFormFactor =
        l.known != SolverLink::kNotKnown ? input_.reuse->value(l.known).formFactor : -1.0;
    if (knownFormFactor >= 0.0) {
      l.formFactor = knownFormFactor;
      continue;
    }
    l.reused = false;  // computed here after all
    l.visibilityOnly = false;
    fresh.push_back(LinkIndex(li));
  }
  // Reciprocity: linkFormFactor integrates over the smaller patch of a pair, so a link and its
  // reverse (p <- q, q <- p; most links of a key have theirs) take one integral, bit for bit what
  // each would have computed. Pairs of equal area (the rule's tie keeps the receiver as the patch
  // integrated over) are computed per link.
  std::vector<std::pair<uint64_t, LinkIndex>> byPair(fresh.size());
  tbb::parallel_for(size_t(0), fresh.size(), [&](size_t i) {
    const SolverLink& l = s_.links[fresh[i]];
    const uint64_t a = uint32_t(std::min(l.receiver, l.shooter)),
                   b = uint32_t(std::max(l.receiver, l.shooter));
    byPair[i] = {(a << 32) | b, fresh[i]};
  });
  std::vector<LinkIndex>().swap(fresh);
  tbb::parallel_sort(byPair.begin(), byPair.end());  // distinct: deterministic
  std::vector<size_t> groupStart;
  for (size_t i = 0; i < byPair.size(); ++i)
    if (i == 0 || byPair[i].first != byPair[i - 1].first) groupStart.push_back(i);
  groupStart.push_back(byPair.size());
  const bool autoOrder = opt_.quadratureOrder == kAutoOrder;
  tbb::parallel_for(size_t(0), groupStart.size() - 1, [&](size_t g) {
    const size_t first = groupStart[g], count = groupStart[g + 1] - first;
    SolverLink& l = s_.links[byPair[first].second];
    const Polygon& p = s_.world[size_t(l.receiver)];
    const Polygon& q = s_.world[size_t(l.shooter)];
    SolverLink& next = s_.links[byPair[first + (count > 1 ? 1 : 0)].second];
    if (count == 2 && autoOrder && next.receiver == l.shooter && p.area() != q.area()) {
      const double f = linkFormFactorIntegral(p, q, opt_.formFactorTolerance);
      l.formFactor = linkFormFactorFrom(p, q, f);
      next.formFactor = linkFormFactorFrom(q, p, f);
      return;
    }
    for (size_t i = first; i < first + count; ++i) {
      SolverLink& li = s_.links[byPair[i].second];
      li.formFactor = linkFormFactor(s_.world[size_t(li.receiver)], s_.world[size_t(li.shooter)],
                                     opt_.quadratureOrder, opt_.formFactorTolerance);
    }
  });
}

}  // namespace rad
