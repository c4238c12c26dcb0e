// The key-time solver's closure (each leaf's own row sum, exact in closed rooms). See
// key_time_solver.h.
// The figures behind the reasons given here: docs/results.md, "Figures moved out of the radiosity
// code's comments (issue 55)".
#include "libcommon/radiosity/key_time_solver.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "libcommon/core/error.h"
#include "libcommon/radiosity/cosine_rays.h"
#include "libcommon/radiosity/pair_table.h"
#include "libcommon/radiosity/visibility.h"

namespace rad {

namespace {

struct TopShare {  // one top-level shooter's links in a leaf's chain
  uint32_t top = 0;
  double fv = 0;
  bool unoccluded = true;
  bool fromAncestor = false;  // some of them are at an ancestor (else F is the leaf's own)
};

}  // namespace

// Closure (energy conservation whatever the refinement): a leaf r gathers through a link (a <- b)
// at an ancestor a the area average F(a -> b), not its own F(r -> b), so its row sum $\sum_k F(a_k
// \to b_k) V_k$ over the links of r and its ancestors is not its own (in a refined furnace it
// strays to both sides of 1, while the area average is 1), and B amplifies that error by 1 / (1 -
// rho). The shooters b_k of a leaf's links tile the top-level patches it is linked with, so for a
// top-level patch q that every one of those links sees unoccluded (V = 1), the links to q carry
// exactly $F(r \to q)$ at the leaf's own resolution; the leaf's links to such a q are scaled by
//   $c_{rq} = G_q / \sum_{k \in q} F(a_k \to b_k) V_k$,  $G_q = F(r \to q)$
// (topExcess_ holds c_rq - 1 per link), the links to a q any of whose links is occluded are kept:
// row sums exact in a closed empty room at any refinement, and the averaging error of unoccluded
// pairs (a wall meeting the floor) removed in any scene, while the occluded pairs keep hierarchical
// radiosity's estimate (scaling them by an unoccluded ratio would brighten what an occluder
// darkens). Per top, not one ratio for the row, which would scale a floor leaf's light by the ratio
// of a dim wall beside it. The good-link share (shooters that do not emit: the default bad-link
// rule's good links) also gets one factor, goodClosure, which rad-global's merge applies to the
// good-link irradiance the Gouraud layer interpolates.
void KeyTimeSolver::computeClosure() {
  buildGatherLists();
  const size_t N = size_t(h_.size());
  s_.closure.assign(N, 1.0);
  s_.goodClosure.assign(N, 1.0);
  goodFactor_.assign(N, 1.0);
  closed_.resize(N, -1);  // kept from the rounds before: a node's rays do not change
  // The previous key's values (coherence) start each node's list: closeLeaf finds them as
  // its own, and they are kept for the next key (all of them static pairs, valid at every key).
  if (leafTopFormFactor_.empty() && input_.reuseLeafFormFactors)
    leafTopFormFactor_ = std::move(*input_.reuseLeafFormFactors);
  leafTopFormFactor_.resize(N);
  topExcess_.assign(N, {});
  std::vector<int> leaves;
  for (size_t i = 0; i < N; ++i)
    if (s_.inTree(int(i), h_) && !s_.split[i]) leaves.push_back(int(i));
  if (opt_.closedRooms) testClosedRooms(leaves);
  tbb::parallel_for(size_t(0), leaves.size(), [&](size_t li) { closeLeaf(leaves[li]); });
}

// A node is in a closed room when none of its escape rays leaves the scene and its parent is in
// one: the rays of a leaf and of all its ancestors are pooled, so that a leaf seeing an opening
// of form factor f goes unnoticed with probability (1 - f)^(64 (depth + 1)), not (1 - f)^64 (an
// open room's far end, f of a few per cent, counted most of its floor leaves closed, and the
// closure filled their rows to 1 as if no light left through the opening; issue 58). Each
// chain is tested from its top-level patch down, one level at a time, and below an open node
// no ray is cast. Once per node and key: the refinement rounds ask again for the nodes they
// keep. A static node's answer is the same at every key (the static geometry alone decides
// it, its ancestors' rays included), so it is also taken over from the keys before
// (coherence).
void KeyTimeSolver::testClosedRooms(const std::vector<int>& leaves) {
  std::vector<std::vector<int>> byLevel;
  for (int leaf : leaves)
    for (int a = leaf; a >= 0 && closed_[size_t(a)] < 0; a = h_.node(a).parent) {
      closed_[size_t(a)] = 2;  // collected; set below
      const size_t level = size_t(h_.node(a).id.level());
      if (byLevel.size() <= level) byLevel.resize(level + 1);
      byLevel[level].push_back(a);
    }
  for (std::vector<int>& nodes : byLevel) {
    std::sort(nodes.begin(), nodes.end());  // the order does not change the answers
    tbb::parallel_for(size_t(0), nodes.size(), [&](size_t i) {
      const int r = nodes[i];
      const int parent = h_.node(r).parent;
      bool closed = false;
      if (parent < 0 || closed_[size_t(parent)] == 1) {
        const ClosedNodeCache* before = moves(h_.node(r).id.top) ? nullptr : input_.reuseClosed;
        const auto known =
            before ? before->find(h_.node(r).id.packed()) : ClosedNodeCache::const_iterator();
        closed = before && known != before->end() ? known->second : castEscapeRays(r);
      }
      closed_[size_t(r)] = closed ? 1 : 0;
    });
  }
}

bool KeyTimeSolver::closedAt(int r) const {
  return closed_[size_t(r)] == 1;
}

bool KeyTimeSolver::castEscapeRays(int r) const {
  if (!input_.visibility) return false;
  const PatchNode& n = h_.node(r);
  const Polygon& P = s_.world[size_t(r)];
  const glm::dvec3 normal = P.normal();
  if (normal == glm::dvec3(0.0)) return false;
  const CosineRays direction(normal);
  const uint64_t seed = splitMix64(receiverSeed(n.id) ^ 0x636c6f736564ull);  // "closed"
  const std::vector<glm::dvec3> points = VisibilityScene::samplePoints(P, kEscapeRays, seed);
  const double size = polygonSize(P);
  const glm::dvec3 centroid = P.centroid();
  for (size_t k = 0; k < points.size(); ++k) {
    const glm::dvec3 d = direction(seed, k);
    // A ray that escapes is cast again from 1 % of the way to the leaf's centroid and 1e-3 of
    // its size above it: a point 2e-5 m from the wall that the leaf's edge meets, whose ray
    // into that wall started within the ray's tnear of it, passed through (a floor leaf of a
    // closed cube); from there it meets the wall.
    if (input_.visibility->firstStaticHit(points[k], d * size, n.id.top) ==
            VisibilityScene::kNoSurface &&
        input_.visibility->firstStaticHit(
            points[k] + 0.01 * (centroid - points[k]) + normal * (1e-3 * size), d * size,
            n.id.top) == VisibilityScene::kNoSurface)
      return false;
  }
  return true;
}

// F(leaf r -> top q), integrated (closeLeaf looks in leafTopFormFactor_ first, which holds
// the previous key's values under coherence: the same value recomputing gives).
double KeyTimeSolver::leafToTop(int r, uint32_t q) const {
  if (opt_.quadratureOrder != kAutoOrder)
    return polygonToPolygonFormFactor(s_.world[size_t(r)], s_.world[q], opt_.quadratureOrder);
  return areaAverageFormFactor(s_.world[size_t(r)], s_.world[q],
                               std::max(opt_.formFactorTolerance, 1e-4));
}

void KeyTimeSolver::closeLeaf(int r) {
  std::vector<TopShare> shares;
  // Per top, its index in `shares` (first-seen order, so the sums below do not depend on
  // it), -1 elsewhere; one per thread, reset after each leaf.
  thread_local std::vector<int> slot;
  slot.resize(size_t(h_.topCount()), -1);
  for (int a = r; a >= 0; a = h_.node(a).parent)
    for (size_t k = adjStart_[size_t(a)]; k < adjStart_[size_t(a) + 1]; ++k) {
      const SolverLink& l = s_.links[adj_[k]];
      const uint32_t q = h_.node(l.shooter).id.top;
      if (slot[q] < 0) {
        slot[q] = int(shares.size());
        shares.push_back(TopShare{q, 0.0, true, false});
      }
      TopShare& t = shares[size_t(slot[q])];
      t.fv += l.fv();
      t.unoccluded = t.unoccluded && l.rayVisibility >= 1.0;
      t.fromAncestor = t.fromAncestor || a != r;
    }
  for (const TopShare& t : shares) slot[t.top] = -1;
  std::vector<std::pair<uint32_t, double>>& known = leafTopFormFactor_[size_t(r)];
  // Per top, its index in `known` (the slots reused), not a linear search per share.
  for (size_t i = 0; i < known.size(); ++i) slot[known[i].first] = int(i);
  glm::dvec2 own(0.0), averaged(0.0);  // (all, good)
  // Per top whose share is replaced, G_q / sum_k F V - 1 (0: kept), indexed like `slot`.
  thread_local std::vector<double> excess;
  excess.resize(size_t(h_.topCount()), 0.0);
  bool anyExcess = false;
  for (const TopShare& t : shares) {
    double g = t.fv;
    if (t.unoccluded && t.fromAncestor && !moves(t.top) && !moves(h_.node(r).id.top)) {
      int& at = slot[t.top];
      if (at < 0) {
        at = int(known.size());
        known.push_back({t.top, leafToTop(r, t.top)});
      }
      g = known[size_t(at)].second;
      if (t.fv > 0.0 && g != t.fv) {
        excess[t.top] = g / t.fv - 1.0;
        anyExcess = true;
      }
    }
    const double good = surfaces_[t.top].isEmitter() ? 0.0 : 1.0;
    own += glm::dvec2(g, good * g);
    averaged += glm::dvec2(t.fv, good * t.fv);
  }
  for (const std::pair<uint32_t, double>& k : known) slot[k.first] = -1;
  // Each replaced top's links are scaled by their own top's ratio, the others kept: a leaf beside a
  // wall sees much more of that dim wall than its ancestor's links say, and one ratio for the whole
  // row would scale the light by the wall's share too (a floor strip in front of a box, and the
  // box's foot on the frames with it, too bright).
  std::vector<std::pair<size_t, double>>& extra = topExcess_[size_t(r)];
  extra.clear();
  if (anyExcess)
    for (int a = r; a >= 0; a = h_.node(a).parent) {
      const double e = exposure_[size_t(a)];
      if (!(e > 0.0)) continue;
      for (size_t k = adjStart_[size_t(a)]; k < adjStart_[size_t(a) + 1]; ++k) {
        const double x = excess[h_.node(s_.links[adj_[k]].shooter).id.top];
        if (x != 0.0) extra.emplace_back(adj_[k], x / e);
      }
    }
  for (const TopShare& t : shares) excess[t.top] = 0.0;
  // The good-link irradiance rad-movies interpolates (Gouraud layer) takes the good share's
  // ratio as one factor.
  if (averaged.y > 0.0) s_.goodClosure[size_t(r)] = own.y / averaged.y;
  closeRow(r);
}

// A leaf's replaced tops' excess irradiance (topExcess_), (emitting shooters, the others).
std::pair<glm::dvec3, glm::dvec3> KeyTimeSolver::excessIrradiance(int r) const {
  std::pair<glm::dvec3, glm::dvec3> H{glm::dvec3(0.0), glm::dvec3(0.0)};
  if (size_t(r) >= topExcess_.size()) return H;
  for (const auto& [k, c] : topExcess_[size_t(r)]) {
    const SolverLink& l = s_.links[k];
    (shooterEmits_[k] ? H.first : H.second) +=
        c * double(l.fv()) * l.shooterShape * B_[size_t(l.shooter)];
  }
  return H;
}

// A leaf's row sum, the sum of the form factors it gathers through, is at most 1: what it sees is
// at most its whole hemisphere. The estimates exceed that: by the hierarchy's averaging (a leaf
// gathers through its ancestors' links their view, and their visibility), which the solve has
// always carried, and far more where geometry is wrong for the estimates (surfaces in contact, a
// cluster link kept at the link bound with its point form factor where its ends are near). A row
// at or above 1 / rho makes the solve diverge (issue 58: --no-closed-rooms on the RenderPark
// office), so such a row is brought down to 1, in an open scene too.
//
// A leaf inside a closed room sees the scene's surfaces and nothing else, so the row sum of its
// exposed part is exactly 1, occluded links included. An occluded link's visibility is a ratio
// estimate from a few ray pairs, and its error does not cancel within one receiver: a closed
// furnace with a slab in it (make_furnace.py --partition) comes out too bright with the slab
// standing and too dark with it floating, and more rays do not cure it. The links to emitting
// shooters keep the closure above (mostly unoccluded, and recomputed per texel by the second pass);
// the others' factor fills the row to 1, each node's links counted over its exposure as the gather
// divides them. Where every shooter emits (the furnace), or the others' share cannot take the
// difference, the whole row is scaled, but raised at most kMaxRowFill times: a row far below 1
// lacks links (those the link bound cut off, those whose rays all missed), and filling it from the
// few it has would gather their shooters many times over (a cubby's side gathered its lamp 130
// times, a floor patch at the link bound its few shooters 2.5e6 times: frames up to 7 times too
// bright, issue 58); it stays darker than 1 instead.
void KeyTimeSolver::closeRow(int r) {
  if (!(exposure_[size_t(r)] > 0.0)) return;
  glm::dvec2 coef(0.0);  // (emitting shooters, the others), the replaced tops' excess included
  for (int a = r; a >= 0; a = h_.node(a).parent) {
    const double e = exposure_[size_t(a)];
    if (!(e > 0.0)) continue;
    for (size_t k = adjStart_[size_t(a)]; k < adjStart_[size_t(a) + 1]; ++k)
      (shooterEmits_[adj_[k]] ? coef.x : coef.y) += s_.links[adj_[k]].fv() / e;
  }
  for (const auto& [k, c] : topExcess_[size_t(r)])
    (shooterEmits_[k] ? coef.x : coef.y) += c * s_.links[k].fv();
  if (!(coef.x + coef.y > 0.0)) return;
  // The cluster links' share (gathered at the top, over its exposure, at most 1:
  // gatherClusterLight) is taken as it is.
  const uint32_t top = h_.node(r).id.top;
  const double cluster = clusterRow_.empty() ? 0.0 : std::min(clusterRow_[top], 1.0);
  const double patches = s_.closure[size_t(r)] * coef.x + goodFactor_[size_t(r)] * coef.y;
  const bool closed = opt_.closedRooms && closedAt(r);
  const double rho = maxComponent(surfaces_[top].reflectance);
  if (!closed && (!((cluster + patches) * rho >= 1.0))) return;
  const double good =
      coef.y > 0.0 ? (1.0 - cluster - s_.closure[size_t(r)] * coef.x) / coef.y : 0.0;
  // The others' factor fills the row (closed) or brings it down (open): the emitting shooters'
  // links, whose light the second pass recomputes per texel, keep theirs (a ceiling leaf above
  // a lamp gathers its ancestors' view of the room beside the lamp's own light; scaling the lamp
  // down with it darkened the ceiling the room is lit from).
  if (closed ? good > 0.5 && good < 2.0 : coef.y > 0.0 && good >= 0.0) {
    goodFactor_[size_t(r)] = good;
    s_.goodClosure[size_t(r)] = closed ? good : s_.goodClosure[size_t(r)] * good;
    return;
  }
  double scale = (1.0 - cluster) / patches;
  if (closed) scale = std::min(scale, kMaxRowFill);
  s_.closure[size_t(r)] *= scale;
  goodFactor_[size_t(r)] *= scale;
  s_.goodClosure[size_t(r)] = closed ? goodFactor_[size_t(r)] : s_.goodClosure[size_t(r)] * scale;
}

}  // namespace rad
