// The per-texel good-link gather (formula and sources in good_link_gather.h): the links of a
// movie, their weights and which take their visibility per texel, and the gather at a time.
// The plan over texel tiles is in gather_tiles.cpp, the near shooters' cells in
// near_shooter_cells.cpp, the cluster light per texel in cluster_light_rays.cpp.
#include "libcommon/movies/good_link_gather.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>

#include <tbb/parallel_for.h>

#include "libcommon/radiosity/form_factor.h"
#include "libcommon/radiosity/shaft.h"

namespace rad {
namespace {

// The distance between segments [a0, a1] and [b0, b1] (Ericson 2005, "Real-Time Collision
// Detection" §5.1.9, the clamped closest points).
double segmentDistance(const glm::dvec3& a0, const glm::dvec3& a1, const glm::dvec3& b0,
                       const glm::dvec3& b1) {
  const glm::dvec3 d1 = a1 - a0, d2 = b1 - b0, r = a0 - b0;
  const double a = glm::dot(d1, d1), e = glm::dot(d2, d2), f = glm::dot(d2, r);
  double s = 0.0, t = 0.0;
  if (a <= 0.0 && e <= 0.0) return glm::length(r);
  if (a <= 0.0) {
    t = glm::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = glm::dot(d1, r);
    if (e <= 0.0) {
      s = glm::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = glm::dot(d1, d2), denom = a * e - b * b;
      s = denom > 0.0 ? glm::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = glm::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = glm::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return glm::length(a0 + s * d1 - (b0 + t * d2));
}

// The split rule's distance: from the receiver's nearest point to polygon p (convex polygons
// that do not cross: the nearest of each one's corners to the other and of their edges).
// Not from the receiver's centroid and corners only: a sliver of a fan (issue 56) whose long
// edge passes by a shooter part, but whose corners are far from it, kept the part whole while
// its small neighbour across that edge split it, and the two gathered the shooter's radiosity
// at different resolutions along their shared edge (a step there).
double distanceFromReceiver(const Polygon& receiver, const Polygon& p) {
  double d = std::numeric_limits<double>::infinity();
  const size_t m = size_t(receiver.count), n = size_t(p.count);
  for (size_t i = 0; i < m; ++i) d = std::min(d, distanceToPolygon(receiver.v[i], p));
  for (size_t j = 0; j < n; ++j) d = std::min(d, distanceToPolygon(p.v[j], receiver));
  for (size_t i = 0; i < m; ++i)
    for (size_t j = 0; j < n; ++j)
      d = std::min(
          d, segmentDistance(receiver.v[i], receiver.v[(i + 1) % m], p.v[j], p.v[(j + 1) % n]));
  return d;
}

// The split rule's distance of a pair seen at several times (receiverAt[k] and p[k] at the
// same time): the nearest it comes.
double nearestDistance(const std::vector<Polygon>& receiverAt, const std::vector<Polygon>& p) {
  double d = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < p.size(); ++k) d = std::min(d, distanceFromReceiver(receiverAt[k], p[k]));
  return d;
}

}  // namespace

GoodLinkGather::GoodLinkGather(const Scene& scene, const GlobalSolution& solution,
                               const SceneEmitters& emitters, GoodLinksByReceiver& byReceiver,
                               const MovieExtent& request, const MovieTexels& texels,
                               const std::vector<double>& movieKeyTimes, double shooterRatio,
                               double cacheBytes, GoodLinkGatherStats& stats,
                               SceneVisibility* visibility, int visibilityRays,
                               int nearShooterLevels, double partialShare,
                               int clusterVisibilityRays)
    : scene_(scene),
      solution_(solution),
      emitters_(emitters),
      clusterCorners_(byReceiver.clusterCorners),
      shooterRatio_(shooterRatio),
      texels_(texels),
      keyTimes_(movieKeyTimes),
      receiverTop_(int(request.patch.top)),
      visibility_(visibility),
      visibilityRays_(visibilityRays),
      byReceiver_(byReceiver),
      nearShooterLevels_(visibility && visibilityRays > 0 && shooterRatio > 0.0 ? nearShooterLevels
                                                                                : 0),
      partialShare_(partialShare),
      clusterVisibilityRays_(clusterVisibilityRays) {
  // The nodes in the moving part of the visibility scene, those that move anywhere in the
  // solution's time range (SceneVisibility's split), with their bounds swept over the movie:
  // one that rests during the movie still blocks. Were only the nodes moving during the movie
  // taken, a one-frame movie (--no-coherence) would see no moving blocker at all, and the
  // per-frame baseline would differ from the coherent frames.
  if (visibility_) {
    movingNodes_ = movingNodesOf(scene, solution.hierarchy.tops(), solution.keyTimes.front(),
                                 solution.keyTimes.back());
    for (int node : movingNodes_)
      swept_.push_back(scene.sweptBounds(node, keyTimes_.front(), keyTimes_.back()));
  }
  // The global keys the movie's key times fall between.
  std::vector<char> needed(size_t(solution.keyCount()), 0);
  for (double t : keyTimes_) {
    int k0, k1;
    double w;
    solution.keyWeights(t, k0, k1, w);
    needed[size_t(k0)] = needed[size_t(k1)] = 1;
  }
  planLinks(byReceiver, request, needed);
  planNearShooters(needed, stats);
  planWeights(needed);
  planTexels(cacheBytes);
  planClusterVisibility();
  stats.links += long(links_.size());
  stats.entries += long(texelLinks_.size());
  if (cached_) stats.cachedEntries += long(texelLinks_.size());
  stats.tileEntries += long(tileLinkCount_);
  for (const Link& l : links_) {
    stats.partialLinks += l.partial ? 1 : 0;
    stats.partialLinksMovingBlockers += l.partial && l.movingBlockers ? 1 : 0;
    stats.partialLinksFewRays += l.fewRays ? 1 : 0;
  }
  stats.partialTileLinksPerTexel += long(partialTileLinksPerTexel_);
}

Polygon GoodLinkGather::nodeWorld(uint32_t node, double t) const {
  const PatchNode& n = solution_.hierarchy.node(int(node));
  return n.local.transformed(scene_.worldTransform(solution_.hierarchy.topOf(int(node)).node, t));
}

// The links whose receiver is the movie's node, one of its ancestors or one of its descendants:
// every texel's chain is made of these.
void GoodLinkGather::planLinks(const GoodLinksByReceiver& byReceiver, const MovieExtent& request,
                               const std::vector<char>& neededKeys) {
  const PatchHierarchy& h = solution_.hierarchy;
  std::vector<int> receivers;
  int movieNode = h.find(request.patch);
  for (PatchId id = request.patch; movieNode < 0 && id.level() > 0;) {  // deepest existing
    id = id.parent();
    movieNode = h.find(id);
  }
  if (movieNode < 0) movieNode = receiverTop_;
  movieNode_ = movieNode;
  for (int a = h.node(movieNode).parent; a >= 0; a = h.node(a).parent) receivers.push_back(a);
  std::vector<int> stack{movieNode};
  while (!stack.empty()) {
    const int n = stack.back();
    stack.pop_back();
    receivers.push_back(n);
    if (!h.isLeaf(n))
      for (int c = 0; c < 4; ++c) stack.push_back(h.node(n).firstChild + c);
  }
  std::sort(receivers.begin(), receivers.end());
  const double t0 = keyTimes_.front(), t1 = keyTimes_.back();
  const bool receiverMoves = scene_.isDynamic(h.top(receiverTop_).node, t0, t1);
  // A pair that moves is split where it is near at any of the movie's keys, not only at its
  // first: a moving box's foot may meet the floor strip beside it only at later keys.
  const std::vector<double> firstKey{t0};
  std::vector<std::pair<uint32_t, int>> shooters;
  std::vector<uint32_t> cells{1u};
  std::vector<Polygon> receiverAt;
  for (int r : receivers) {
    for (uint32_t k = byReceiver.start[size_t(r)]; k < byReceiver.start[size_t(r) + 1]; ++k) {
      const uint32_t row = byReceiver.rows[k];
      const uint32_t shooter = solution_.links[row].shooter;
      const bool moves = receiverMoves || scene_.isDynamic(h.topOf(int(shooter)).node, t0, t1);
      const std::vector<double>& times = moves ? keyTimes_ : firstKey;
      receiverAt.clear();
      for (double t : times) receiverAt.push_back(nodeWorld(uint32_t(r), t));
      shooterParts(receiverAt, times, neededKeys, shooter, shooters);
      for (const auto& [q, shared] : shooters) {
        const bool emitter = emitters_.topEmits(int(h.node(int(q)).id.top));
        if (nearShooterLevels_ > 0 && h.isLeaf(int(q)) && !emitter)
          nearCells(receiverAt, times, q, cells);
        else
          cells.assign(1, 1u);
        for (uint32_t cell : cells) {
          Link l;
          l.row = row;
          l.shooter = q;
          l.cell = cell;
          l.rays = std::max(1, visibilityRays_ >> (2 * (cellLevel(cell) + shared)));
          l.moves = moves;
          links_.push_back(std::move(l));
        }
      }
    }
  }
}

// The parts of a link's shooter a texel gathers from: the shooter's union sub-tree, descended
// while a node is larger than shooterRatio times its distance to the receiver. The point form
// factor weights the near part of a shooter most, and the shooter's B is constant over a node:
// near parts take their own B; far ones, over which F hardly varies, keep the link's node.
void GoodLinkGather::shooterParts(const std::vector<Polygon>& receiverAt,
                                  const std::vector<double>& times,
                                  const std::vector<char>& neededKeys, uint32_t shooter,
                                  std::vector<std::pair<uint32_t, int>>& out) const {
  const PatchHierarchy& h = solution_.hierarchy;
  out.clear();
  std::vector<std::pair<uint32_t, int>> stack{{shooter, 0}};
  std::vector<Polygon> world(times.size());
  while (!stack.empty()) {
    const auto [q, shared] = stack.back();
    stack.pop_back();
    // With near cells a leaf's cells carry B of their own that its mean does not show, so a
    // node whose children's means agree is split all the same.
    bool split = !h.isLeaf(int(q)) && shooterRatio_ > 0.0 &&
                 (nearShooterLevels_ > 0 || childrenDiffer(q, neededKeys));
    bool near = false;  // larger than kRaysRatio times the ratio: its parts take their own rays
    if (split) {
      for (size_t k = 0; k < times.size(); ++k) world[k] = nodeWorld(q, times[k]);
      const double size = polygonSize(world[0]), d = nearestDistance(receiverAt, world);
      split = size > shooterRatio_ * d;
      near = size > kRaysRatio * shooterRatio_ * d;
    }
    if (!split) {
      out.emplace_back(q, shared);
      continue;
    }
    for (int c = 3; c >= 0; --c)
      stack.emplace_back(uint32_t(h.node(int(q)).firstChild + c), shared + (near ? 0 : 1));
  }
}

// Whether a child of interior node q has a radiosity more than kPartSpread of q's (channel sums)
// at a needed key. Where none has, the children's terms sum to q's own within that share of it
// (\sum_i B_i F_i against B_q \sum_i F_i), and splitting q would only cost.
bool GoodLinkGather::childrenDiffer(uint32_t q, const std::vector<char>& neededKeys) const {
  const int first = solution_.hierarchy.node(int(q)).firstChild;
  auto sum = [](const glm::dvec3& b) { return b.x + b.y + b.z; };
  for (int k = 0; k < solution_.keyCount(); ++k) {
    if (!neededKeys[size_t(k)]) continue;
    const double bq = sum(solution_.radiosityAtKey(int(q), k));
    for (int c = 0; c < 4; ++c)
      if (std::abs(sum(solution_.radiosityAtKey(first + c, k)) - bq) > kPartSpread * bq)
        return true;
  }
  return false;
}

Polygon GoodLinkGather::linkWorld(const Link& l, double t) const {
  return cellPolygon(nodeWorld(l.shooter, t), l.cell);
}

// The cells of a near leaf shooter a texel gathers from: its virtual quadtree descended while a
// cell is larger than kRaysRatio times shooterRatio times its distance to the receiver, down to
// nearShooterLevels_. Not at shooterRatio, as shooterParts: at that ratio the cells followed
// the floor's shadow at a box's foot less well (NearShooterCellsFollowTheFloorsShadowAtAFoot);
// a cell's rays are its leaf's shared by level, and why finer cells did worse is not settled.
void GoodLinkGather::nearCells(const std::vector<Polygon>& receiverAt,
                               const std::vector<double>& times, uint32_t leaf,
                               std::vector<uint32_t>& out) const {
  out.clear();
  std::vector<Polygon> leafAt;  // the leaf at each of times
  for (double t : times) leafAt.push_back(nodeWorld(leaf, t));
  std::vector<std::pair<uint32_t, std::vector<Polygon>>> stack{{1u, std::move(leafAt)}};
  while (!stack.empty()) {
    auto [cell, poly] = std::move(stack.back());
    stack.pop_back();
    bool split = cellLevel(cell) < nearShooterLevels_;
    if (split)
      split = polygonSize(poly[0]) > kRaysRatio * shooterRatio_ * nearestDistance(receiverAt, poly);
    if (!split) {
      out.push_back(cell);
      continue;
    }
    std::array<std::vector<Polygon>, 4> c;
    for (const Polygon& p : poly) {
      const std::array<Polygon, 4> q = subdividePolygon(p);
      for (size_t k = 0; k < 4; ++k) c[k].push_back(q[k]);
    }
    for (int k = 3; k >= 0; --k)
      stack.push_back({(cell << 2) | uint32_t(k), std::move(c[size_t(k)])});
  }
}

// Per link and needed global key: B_q(k) \bar V(k), with \bar V = V / e clamped to [0, 1] (a
// file before linkhier 1.2 has no V: F·V / (\bar F e), \bar F once for a link that does not
// move).
void GoodLinkGather::planWeights(const std::vector<char>& needed) {
  const int K = solution_.keyCount();
  const bool storedVisibility = !solution_.linkSampleVisibility.empty();
  // Per link, over the needed keys: the irradiance it carries (channel sum of B_q F V) and, when
  // partly occluded, its risk B_q F (1 - V): what it would carry unoccluded, less the share its
  // V already gives. Not B_q F V (1 - V), what one V over the receiver can misplace: the factor V
  // is the link's own noisy estimate (16 ray pairs), so the links whose V came out low by chance
  // weighed little and kept it while those whose V came out high were corrected per texel. A
  // receiver that sees most of its room through openings, where V is small, gathered too
  // little (a door jamb's texels summed to less than 1 in a closed furnace).
  std::vector<double> carried(links_.size(), 0.0), risk(links_.size(), -1.0);
  // The hidden links' F that this baker's earlier movies integrated are read here (no writes
  // while the loop runs); the new ones are added after it.
  // Cached only for links whose ends do not move over the whole solution, so that every movie
  // sees them where they are in this one.
  const auto& knownHidden = byReceiver_.hiddenFormFactor;
  std::vector<double> newHidden(links_.size(), -1.0);
  const double first = solution_.keyTimes.front(), last = solution_.keyTimes.back();
  const PatchHierarchy& hierarchy = solution_.hierarchy;
  const bool receiverFixed = !scene_.isDynamic(hierarchy.top(receiverTop_).node, first, last);
  auto fixedEnds = [&](const Link& l) {
    return receiverFixed && !scene_.isDynamic(hierarchy.topOf(int(l.shooter)).node, first, last);
  };
  tbb::parallel_for(size_t(0), links_.size(), [&](size_t j) {
    Link& l = links_[j];
    const GlobalLink& g = solution_.links[l.row];
    l.weight.assign(size_t(K), glm::dvec3(0.0));
    double fixedF = -1.0, hiddenF = -1.0;
    int cacheable = -1;  // whether fixedEnds(l), once asked
    for (int k = 0; k < K; ++k) {
      if (!needed[size_t(k)]) continue;
      const double fv = solution_.linkFvAtKey(g, k);
      const glm::dvec3 b = solution_.exposedRadiosityAtKey(int(l.shooter), k) * cellRatio(l, k);
      if (!(fv > 0.0)) {
        // Active, but no ray pair got through (V = 0): the link may still be partly visible (a
        // wall partly visible through a doorway may have all its ray pairs blocked). Kept at 0
        // it is lost from every texel, while the links whose V came out above 0 are corrected
        // per texel, and a closed furnace's texels sum to less than 1. Its risk is what it would
        // carry unoccluded, B_q F.
        if (visibility_ && storedVisibility && GlobalSolution::linkActiveAtKey(g, k)) {
          double f = hiddenF;
          if (f < 0.0 && cacheable < 0) {
            cacheable = fixedEnds(l) ? 1 : 0;
            auto it = cacheable ? knownHidden.find({l.row, l.shooter, l.cell}) : knownHidden.end();
            if (it != knownHidden.end()) f = hiddenF = it->second;
          }
          if (f < 0.0) {
            const double t = solution_.keyTimes[size_t(k)];
            f = areaAverageFormFactor(nodeWorld(g.receiver, t), linkWorld(l, t), 1e-3);
            if (!l.moves) hiddenF = f;
            if (cacheable == 1) newHidden[j] = f;
          }
          if (f > 0.0) risk[j] = std::max(risk[j], (b.x + b.y + b.z) * f);
        }
        continue;
      }
      double v = 1.0;
      if (storedVisibility) {
        v = solution_.linkVisibilityAtKey(g, k);
      } else {
        double f = fixedF;
        if (f < 0.0) {
          const double t = solution_.keyTimes[size_t(k)];
          f = areaAverageFormFactor(nodeWorld(g.receiver, t), nodeWorld(g.shooter, t), 1e-4);
          if (!l.moves) fixedF = f;
        }
        v = f > 0.0 ? fv / f : 0.0;
      }
      carried[j] = std::max(carried[j], (b.x + b.y + b.z) * fv);
      if (visibility_ && storedVisibility && v > 0.0 && v < 1.0)
        risk[j] = std::max(risk[j], (b.x + b.y + b.z) * fv / v * (1.0 - v));
      // A receiver partly covered by a touching solid: V counts the covered sample points as
      // occluded towards shooters outside the solid; the texel is exposed.
      const double e = solution_.exposureAtKey(int(g.receiver), k);
      v = e > 0.0 ? std::clamp(v / e, 0.0, 1.0) : 0.0;
      l.weight[size_t(k)] = b * v;
    }
  });
  for (size_t j = 0; j < links_.size(); ++j)
    if (newHidden[j] >= 0.0)
      byReceiver_.hiddenFormFactor.emplace(
          HiddenLink{links_[j].row, links_[j].shooter, links_[j].cell}, newHidden[j]);
  if (!visibility_) return;
  selectPartialLinks(risk, carried);
  tbb::parallel_for(size_t(0), links_.size(), [&](size_t j) {
    if (links_[j].partial) planVisibility(links_[j], needed);
  });
}

// Per texel visibility where it matters, per receiver node (what the node and its ancestors
// carry, `total`, a texel gathers at least that), share s = --gather-partial-share:
// - a partial link whose risk alone is at least s x total: from visibilityRays_ rays;
// - the smaller ones keep the link's one V while their risks, smallest first, sum to at most
//   kPartialSumShares x s x total; the rest take V per texel from a quarter of the rays (each
//   misplaces little, and its points are the same for every texel: no noise from texel to
//   texel). Were each small link to keep its V, a receiver with many of them (a floor under
//   desks' front edges, seeing the ceiling's leaves past the desk tops) would come out too
//   bright in a strip ("Scale, at `e3297e9`: which gathered links take their visibility per
//   texel, again" in docs/results.md).
void GoodLinkGather::selectPartialLinks(const std::vector<double>& risk,
                                        const std::vector<double>& carried) {
  const PatchHierarchy& h = solution_.hierarchy;
  std::map<int, double> chain;  // receiver node -> what it and its ancestors carry
  for (size_t j = 0; j < links_.size(); ++j)
    chain[int(solution_.links[links_[j].row].receiver)] += carried[j];
  std::map<int, double> total;
  for (const auto& [node, own] : chain) {
    double sum = 0.0;
    for (int a = node; a >= 0; a = h.node(a).parent) {
      auto it = chain.find(a);
      if (it != chain.end()) sum += it->second;
    }
    total[node] = sum;
  }
  std::map<int, std::vector<uint32_t>> small;  // receiver node -> its small partial links
  linkGather_.assign(links_.size(), 0.0);
  for (uint32_t j = 0; j < uint32_t(links_.size()); ++j) {
    if (risk[j] < 0.0) continue;
    const int r = int(solution_.links[links_[j].row].receiver);
    linkGather_[j] = total.at(r);
    if (risk[j] >= partialShare_ * total.at(r))
      links_[j].partial = true;
    else
      small[r].push_back(j);
  }
  for (auto& [node, ids] : small) {
    std::sort(ids.begin(), ids.end(), [&](uint32_t a, uint32_t b) {
      return risk[a] != risk[b] ? risk[a] < risk[b] : a < b;
    });
    const double budget = kPartialSumShares * partialShare_ * total.at(node);
    double kept = 0.0;
    for (uint32_t j : ids) {
      if (kept + risk[j] <= budget) {
        kept += risk[j];
        continue;
      }
      links_[j].partial = true;
      links_[j].fewRays = true;
      links_[j].rays = std::max(1, links_[j].rays / 4);
    }
  }
}

GoodLinkGather::TexelFrame GoodLinkGather::texelFrame(double t) const {
  const InputPolygon& top = solution_.hierarchy.top(receiverTop_);
  TexelFrame f;
  f.m = scene_.worldTransform(top.node, t);
  f.normalMap = glm::transpose(glm::inverse(glm::dmat3(f.m)));
  return f;
}

// A partly occluded link part: V per texel (pointVisibility) from visibilityRays_ points on the
// shooter part, the same for every texel (one shadow per point, as the bad layer's samples: no
// noise from texel to texel), each weighted by the radiosity of the union leaf under it. The
// weights keep the light of a shooter bright where the receiver cannot see it (the ceiling
// above a double-sided lamp) from coming out through its visible part, as rad-global's
// radiosity-weighted link visibility does. Its weight is then B_q alone (no V, no exposure:
// a texel's own rays say what it sees).
void GoodLinkGather::planVisibility(Link& l, const std::vector<char>& needed) const {
  const PatchHierarchy& h = solution_.hierarchy;
  const GlobalLink& g = solution_.links[l.row];
  const int K = solution_.keyCount(), k = l.rays;
  for (int key = 0; key < K; ++key)
    if (needed[size_t(key)] && GlobalSolution::linkActiveAtKey(g, key))
      l.weight[size_t(key)] =
          solution_.exposedRadiosityAtKey(int(l.shooter), key) * cellRatio(l, key);
  // Seeded by the receiver's planar surface and the shooter part, not the link's receiver node:
  // two coplanar receivers that meet at an edge (a wall's triangles, a node and its neighbour)
  // cast their rays to the same points and their visibilities agree where they meet (issue 56:
  // each receiver node's own points made two estimates of one shadow, which stepped there).
  l.seed = linkSeed(PatchId{byReceiver_.surfaceOfTop[size_t(receiverTop_)], 1u},
                    h.node(int(l.shooter)).id);
  const double t0 = keyTimes_.front();
  const Polygon shooter = linkWorld(l, t0);
  const std::vector<glm::dvec3> points = pointsInFront(shooter, t0, k, l.seed);
  const bool triangle = h.topOf(int(l.shooter)).local.count == 3;
  const int top = int(h.node(int(l.shooter)).id.top);
  l.pointLeaf.resize(size_t(k));
  for (int i = 0; i < k; ++i) {
    const glm::dvec2 uv = clampToParameterDomain(polygonUvAt(shooter, points[size_t(i)]), triangle);
    l.pointLeaf[size_t(i)] =
        leafAtTopUv(h, top, topUvFromNodeUv(h.node(int(l.shooter)).id, uv, triangle));
  }
  l.pointWeight.assign(size_t(K) * size_t(k), 0.0);
  for (int key = 0; key < K; ++key)
    if (needed[size_t(key)])
      for (int i = 0; i < k; ++i) {
        const glm::dvec3 b = solution_.radiosityAtKey(l.pointLeaf[size_t(i)], key);
        l.pointWeight[size_t(key) * k + i] = b.x + b.y + b.z;
      }
  l.movingBlockers = l.moves;
  if (!l.moves) {
    const Polygon receiver = nodeWorld(uint32_t(movieNode_), t0);
    for (const auto& box : swept_)
      if (shaftMeetsBox(receiver, shooter, box[0], box[1])) l.movingBlockers = true;
    l.points = points;
  }
}

// A partial link's shooter points: over the part of its shooter in front of the movie node's
// plane at time t. A shooter that crosses the receiver's plane (a car's deck seen from the back
// face of its cabin, a floor from a table leg's faces) had most of its points behind it, and a
// texel's V rested on the one or two rays left (a wedge of the cabin's back face, decided by one
// ray, came out far too dark). Where the two ends move against each other (a floor seen from a
// moving box)
// the part in front changes with t, and the points' radiosity weights (pointWeight) stay those
// of the leaves under them at the movie's first key.
std::vector<glm::dvec3> GoodLinkGather::pointsInFront(const Polygon& shooter, double t, int k,
                                                      uint64_t seed) const {
  const Polygon receiver = nodeWorld(uint32_t(movieNode_), t);
  return VisibilityScene::samplePointsInFront(shooter, receiver.v[0], receiver.normal(), k, seed);
}

uint64_t GoodLinkGather::openRays(const VisibilityScene& blockers, const glm::dvec3& x,
                                  const Link& l, const std::vector<glm::dvec3>& points,
                                  uint64_t candidates) const {
  return blockers.openFrom(x, points, uint32_t(receiverTop_),
                           uint32_t(solution_.hierarchy.node(int(l.shooter)).id.top), candidates);
}

double GoodLinkGather::visibilityAt(const glm::dvec3& x, const glm::dvec3& n, const Link& l,
                                    const std::vector<glm::dvec3>& points,
                                    const glm::dvec3& shooterNormal, const uint64_t* open,
                                    const double* weight, bool movingNow,
                                    const double* kernels) const {
  uint64_t bits = open ? *open : openRays(visibility_->staticPart(), x, l, points);
  if (movingNow && bits != 0 && visibility_->dynamicNodeCount() > 0)
    bits = openRays(visibility_->movingPart(), x, l, points, bits);
  if (kernels)
    return pointVisibilityOfKernels(
        kernels, std::min(int(points.size()), VisibilityScene::kMaxRecordedPairs), bits, weight);
  return pointVisibility(x, n, points, shooterNormal, bits, weight);
}

void GoodLinkGather::gather(double t, std::vector<glm::dvec3>& acc) const {
  const KeyTerms key = keyTerms(t);
  const std::array<glm::dvec3, 4> cluster = clusterCornersAt(t);
  const TexelFrame frame = texelFrame(t);
  const std::vector<double> cornerValue = farLinksAtCorners(key, frame);
  tbb::parallel_for(size_t(0), tiles_.size(), [&](size_t ti) {
    gatherTile(tiles_[ti], key, cluster, frame, cornerValue, acc);
  });
}

// The links' terms at time t that every texel shares: weights, shooter parts, and of the
// partial links their points, their points' weights and whether moving blockers are near now.
GoodLinkGather::KeyTerms GoodLinkGather::keyTerms(double t) const {
  int k0, k1;
  double w;
  solution_.keyWeights(t, k0, k1, w);
  KeyTerms key;
  key.weight.resize(links_.size());
  key.shooter.resize(links_.size());
  key.shooterNormal.resize(links_.size());  // partial links: once per key
  // Partial links: the shooter points (moving ones where they are at t) and their weights at t.
  const int rays = visibilityRays_;
  key.points.resize(links_.size());
  key.pointWeight.resize(links_.size() * size_t(rays));
  bool castNow = false;
  for (size_t j = 0; j < links_.size(); ++j) {
    const Link& l = links_[j];
    key.weight[j] = (1.0 - w) * l.weight[size_t(k0)] + w * l.weight[size_t(k1)];
    if (l.moves || !cached_ || l.partial) key.shooter[j] = linkWorld(l, t);
    if (!l.partial) continue;
    key.shooterNormal[j] = key.shooter[j].normal();
    for (int i = 0; i < l.rays; ++i)
      key.pointWeight[j * rays + i] = (1.0 - w) * l.pointWeight[size_t(k0) * l.rays + i] +
                                      w * l.pointWeight[size_t(k1) * l.rays + i];
    if (l.moves) key.points[j] = pointsInFront(key.shooter[j], t, l.rays, l.seed);
    castNow = castNow || l.movingBlockers;
  }
  // Rays cast now see the moving nodes where they are at t (not thread-safe: before the loop).
  if (castNow && visibility_->dynamicNodeCount() > 0) visibility_->setTime(t);
  // Per partial link with moving blockers: whether a moving node, where it is at t, meets the
  // shaft (the convex hull of the movie's node and the shooter part, which holds every ray):
  // the swept bounds over the whole movie say only that it may, at some key.
  key.movingNow.assign(links_.size(), 0);
  if (castNow) {
    std::vector<std::array<glm::dvec3, 2>> now;
    for (int node : movingNodes_) now.push_back(scene_.sweptBounds(node, t, t));
    const Polygon receiver = nodeWorld(uint32_t(movieNode_), t);
    tbb::parallel_for(size_t(0), links_.size(), [&](size_t j) {
      if (!links_[j].partial || !links_[j].movingBlockers) return;
      for (const auto& box : now)
        if (shaftMeetsBox(receiver, key.shooter[j], box[0], box[1])) {
          key.movingNow[j] = 1;
          return;
        }
    });
  }
  return key;
}

const std::vector<glm::dvec3>& GoodLinkGather::pointsOf(const KeyTerms& key, uint32_t j) const {
  return links_[j].moves ? key.points[j] : links_[j].points;
}

// The receiver top's cluster light at its corners, linear in t between the keys as the links'
// weights (0 without cluster links).
std::array<glm::dvec3, 4> GoodLinkGather::clusterCornersAt(double t) const {
  std::array<glm::dvec3, 4> clusterCorner = {glm::dvec3(0.0), glm::dvec3(0.0), glm::dvec3(0.0),
                                             glm::dvec3(0.0)};
  if (!clusterCorners_.empty()) {
    int k0, k1;
    double w;
    solution_.keyWeights(t, k0, k1, w);
    const size_t K = size_t(solution_.keyCount());
    for (size_t c = 0; c < 4; ++c)
      clusterCorner[c] =
          (1.0 - w) * glm::dvec3(clusterCorners_[(size_t(receiverTop_) * K + size_t(k0)) * 4 + c]) +
          w * glm::dvec3(clusterCorners_[(size_t(receiverTop_) * K + size_t(k1)) * 4 + c]);
  }
  return clusterCorner;
}

// The cluster light at texel x: the corners' values interpolated over the top by the texel's
// (u,v) (bilinear on a quad, barycentric on a triangle).
glm::dvec3 GoodLinkGather::clusterAt(const std::array<glm::dvec3, 4>& clusterCorner,
                                     size_t x) const {
  const bool triangleTop = solution_.hierarchy.top(receiverTop_).local.count == 3;
  const double u = texels_.topUv[x].x, v = texels_.topUv[x].y;
  if (triangleTop)
    return (1.0 - u - v) * clusterCorner[0] + u * clusterCorner[1] + v * clusterCorner[2];
  return (1.0 - u) * (1.0 - v) * clusterCorner[0] + u * (1.0 - v) * clusterCorner[1] +
         u * v * clusterCorner[2] + (1.0 - u) * v * clusterCorner[3];
}

// The far links' F V at the corner texels, once per corner and link (the tiles sharing a
// corner read it), per cornerLink_ entry.
std::vector<double> GoodLinkGather::farLinksAtCorners(const KeyTerms& key,
                                                      const TexelFrame& frame) const {
  const int rays = visibilityRays_;
  std::vector<double> cornerValue(cornerLink_.size(), 0.0);
  tbb::parallel_for(size_t(0), corners_.empty() ? 0 : corners_.size() - 1, [&](size_t i) {
    const size_t x = corners_[i].texel;
    const glm::dvec3 p = frame.point(texels_.localPoint[x]);
    const glm::dvec3 nx = frame.normal(texels_.localNormal[x]);
    for (uint32_t e = corners_[i].first; e < corners_[i + 1].first; ++e) {
      const uint32_t j = cornerLink_[e];
      const Link& l = links_[j];
      if (key.weight[j] == glm::dvec3(0.0)) continue;
      double f = l.moves ? pointToPolygonFormFactor(p, nx, key.shooter[j]) : cornerFormFactor_[e];
      if (l.partial && f > 0.0)
        f *= visibilityAt(p, nx, l, pointsOf(key, j), key.shooterNormal[j],
                          l.moves ? nullptr : &cornerOpen_[e], &key.pointWeight[j * rays],
                          key.movingNow[j] != 0);
      cornerValue[e] = f;
    }
  });
  return cornerValue;
}

// One tile's texels: the far links interpolated from the corners, group by group, plus each
// texel's own links and the cluster light.
void GoodLinkGather::gatherTile(const Tile& tile, const KeyTerms& key,
                                const std::array<glm::dvec3, 4>& cluster, const TexelFrame& frame,
                                const std::vector<double>& cornerValue,
                                std::vector<glm::dvec3>& acc) const {
  const int width = texels_.width, height = texels_.height;
  const int rays = visibilityRays_;
  const int iEnd = std::min(tile.i0 + kTile, width), jEnd = std::min(tile.j0 + kTile, height);
  // The tile's far links at its corners (corner c: (i0,j0), (i1,j0), (i1,j1), (i0,j1)), group
  // by group, interpolated to the texels each group reaches (on the stack: this runs per tile
  // and key).
  std::array<glm::dvec3, size_t(kTile * kTile)> far;
  far.fill(glm::dvec3(0.0));
  for (size_t g = 0, k = 0; g < tile.groups.size(); ++g) {
    glm::dvec3 corner[4] = {glm::dvec3(0.0), glm::dvec3(0.0), glm::dvec3(0.0), glm::dvec3(0.0)};
    for (; k < tile.groups[g].second; ++k) {
      const uint32_t j = tile.links[k];
      if (key.weight[j] == glm::dvec3(0.0)) continue;
      for (int c = 0; c < 4; ++c)
        corner[c] += cornerValue[tile.cornerEntry[k * 4 + size_t(c)]] * key.weight[j];
    }
    for (int j = tile.j0; j < jEnd; ++j)
      for (int i = tile.i0; i < iEnd; ++i)
        if (tile.groups[g].first & Tile::bit(i, j, tile)) {
          far[size_t((j - tile.j0) * kTile + (i - tile.i0))] += tile.bilinear(i, j, corner);
        }
  }
  for (int j = tile.j0; j < jEnd; ++j)
    for (int i = tile.i0; i < iEnd; ++i) {
      const size_t x = size_t(j) * width + i;
      glm::dvec3 H = far[size_t((j - tile.j0) * kTile + (i - tile.i0))];
      const glm::dvec3 p = frame.point(texels_.localPoint[x]);
      const glm::dvec3 nx = frame.normal(texels_.localNormal[x]);
      for (uint32_t e = texelStart_[x]; e < texelStart_[x + 1]; ++e) {
        const uint32_t l = texelLinks_[e];
        const Link& link = links_[l];
        if (key.weight[l] == glm::dvec3(0.0)) continue;
        double f = cached_ && !link.moves ? double(texelFormFactor_[e])
                                          : pointToPolygonFormFactor(p, nx, key.shooter[l]);
        if (link.partial && f > 0.0)
          f *= visibilityAt(p, nx, link, pointsOf(key, l), key.shooterNormal[l],
                            cached_ && !link.moves ? &texelOpen_[e] : nullptr,
                            &key.pointWeight[l * rays], key.movingNow[l] != 0,
                            !texelKernelAt_.empty() && texelKernelAt_[e] != kNoKernels
                                ? &texelKernel_[texelKernelAt_[e]]
                                : nullptr);
        H += f * key.weight[l];
      }
      acc[x] =
          H + (clusterVisibility_.empty() ? clusterAt(cluster, x)
                                          : double(clusterVisibility_[x]) * clusterAt(cluster, x));
    }
}

}  // namespace rad
