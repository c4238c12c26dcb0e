// The per-texel good-link gather (formula and sources in good_link_gather.h).
#include "libcommon/movies/good_link_gather.h"

#include <algorithm>
#include <array>
#include <bitset>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <tuple>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "libcommon/radiosity/form_factor.h"
#include "libcommon/radiosity/shaft.h"

namespace rad {

RayStart coveredBySolid(const VisibilityScene& blockers, const Scene& scene,
                        const PatchHierarchy& h, uint32_t top, const glm::dvec3& p,
                        const glm::dvec3& d, double t) {
  return rayStart(blockers, p, d, top, [&](uint32_t hit) {
    if (hit >= uint32_t(h.topCount())) return false;
    const InputPolygon& surface = h.top(int(hit));
    const int m = surface.material;
    if (m >= 0 && m < int(scene.materials.size()) && scene.materials[size_t(m)].doubleSided)
      return false;
    return glm::dot(surface.local.transformed(scene.worldTransform(surface.node, t)).normal(), d) >
           0.0;
  });
}

bool insideSolid(const VisibilityScene& blockers, const Scene& scene, const PatchHierarchy& h,
                 uint32_t top, const glm::dvec3& p, const glm::dvec3& n, double size, double t) {
  glm::dvec3 u = std::abs(n.x) > 0.5 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
  u = glm::normalize(glm::cross(u, n));
  const glm::dvec3 v = glm::cross(n, u);
  const double c = std::cos(88.0 * M_PI / 180.0), sn = std::sin(88.0 * M_PI / 180.0);
  const glm::dvec3 dirs[4] = {c * n + sn * u, c * n - sn * u, c * n + sn * v, c * n - sn * v};
  // Every ray inside or undecided (rayStart), one at least inside: a ray into a sheet of two
  // back-to-back patches is undecided, and the sheet's other side is outside.
  bool inside = false;
  for (const glm::dvec3& d : dirs) {
    const RayStart r = coveredBySolid(blockers, scene, h, top, p, d * size, t);
    if (r == RayStart::kOutside) return false;
    inside = inside || r == RayStart::kInside;
  }
  return inside;
}

namespace {

// The nearest of the receiver's centroid and corners to polygon p (the split rule's distance).
double distanceFromReceiver(const Polygon& receiver, const Polygon& p) {
  double d = distanceToPolygon(receiver.centroid(), p);
  for (int i = 0; i < receiver.count; ++i) d = std::min(d, distanceToPolygon(receiver.v[i], p));
  return d;
}

// The split rule's distance of a pair seen at several times (receiverAt[k] and p[k] at the
// same time): the nearest it comes.
double nearestDistance(const std::vector<Polygon>& receiverAt, const std::vector<Polygon>& p) {
  double d = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < p.size(); ++k) d = std::min(d, distanceFromReceiver(receiverAt[k], p[k]));
  return d;
}

// Per receiver node, the rows of solution.links that `gathers` keeps: rows[start[i] ..
// start[i + 1]).
template <class Keep>
void indexByReceiver(const GlobalSolution& s, Keep&& gathers, std::vector<uint32_t>& start,
                     std::vector<uint32_t>& rows) {
  const size_t N = size_t(s.hierarchy.size());
  start.assign(N + 1, 0);
  for (const GlobalLink& l : s.links)
    if (l.receiver < N && gathers(l)) ++start[l.receiver + 1];
  for (size_t i = 0; i < N; ++i) start[i + 1] += start[i];
  rows.resize(start[N]);
  std::vector<uint32_t> next(start.begin(), start.end() - 1);
  for (uint32_t r = 0; r < uint32_t(s.links.size()); ++r) {
    const GlobalLink& l = s.links[r];
    if (l.receiver < N && gathers(l)) rows[next[l.receiver]++] = r;
  }
}

int cellLevel(uint32_t cell) {
  return (31 - __builtin_clz(cell)) / 2;
}

// The 4^levels cells of polygon p in path order (subdividePolygon's children at each level).
std::vector<Polygon> cellsOf(const Polygon& p, int levels) {
  std::vector<Polygon> c{p};
  for (int d = 0; d < levels; ++d) {
    std::vector<Polygon> next;
    next.reserve(c.size() * 4);
    for (const Polygon& q : c)
      for (const Polygon& child : subdividePolygon(q)) next.push_back(child);
    c = std::move(next);
  }
  return c;
}

}  // namespace

GoodLinksByReceiver::GoodLinksByReceiver(const GlobalSolution& s) {
  indexByReceiver(
      s, [](const GlobalLink& l) { return !(l.flags & (kLinkBad | kLinkRefined)); }, start, rows);
  smoothClusterIrradiance(s);
}

void GoodLinksByReceiver::indexAllLinks(const GlobalSolution& s) {
  if (!allStart.empty()) return;
  const size_t N = size_t(s.hierarchy.size());
  indexByReceiver(
      s, [N](const GlobalLink& l) { return !(l.flags & kLinkRefined) && l.shooter < N; }, allStart,
      allRows);
}

void GoodLinksByReceiver::smoothClusterIrradiance(const GlobalSolution& s) {
  const std::vector<InputPolygon>& tops = s.hierarchy.tops();
  const size_t T = tops.size(), K = size_t(s.keyCount());
  if (s.topClusterIrradiance.size() != T * K || K == 0) return;
  // Corners by mesh node and exact local position (the tiles of one mesh share vertices).
  std::map<std::tuple<int, double, double, double>, std::vector<uint32_t>> atCorner;
  auto key = [&](size_t t, int c) {
    const glm::dvec3& v = tops[t].local.v[size_t(c)];
    return std::make_tuple(tops[t].node, v.x + 0.0, v.y + 0.0, v.z + 0.0);  // -0 as +0
  };
  std::vector<glm::dvec3> normal(T);
  std::vector<double> area(T);
  for (size_t t = 0; t < T; ++t) {
    normal[t] = tops[t].local.normal();
    area[t] = tops[t].local.area();
    for (int c = 0; c < tops[t].local.count; ++c) atCorner[key(t, c)].push_back(uint32_t(t));
  }
  const double sameFacing = std::cos(8.0 * M_PI / 180.0);
  clusterCorners.assign(T * K * 4, glm::vec3(0.0f));
  for (size_t t = 0; t < T; ++t)
    for (int c = 0; c < tops[t].local.count; ++c) {
      const std::vector<uint32_t>& shared = atCorner.at(key(t, c));
      for (size_t k = 0; k < K; ++k) {
        // Weighted by each top's exposed area: a top mostly covered by a touching surface (a
        // ceiling tile behind a light) takes its own cluster links' light from the few of their
        // rays that start uncovered, over its small exposure (a noisy value), and a wholly
        // covered one gathers none (0). Equal shares had carried both to the corners of their
        // uncovered neighbours: streaks along every light of the 10k-triangle hall.
        glm::dvec3 sum(0.0), plain(0.0);
        double weight = 0.0;
        int n = 0;
        for (uint32_t o : shared)
          if (glm::dot(normal[o], normal[t]) >= sameFacing) {
            const glm::dvec3 e(s.topClusterIrradiance[size_t(o) * K + k]);
            const double w = area[o] * s.exposureAtKey(int(o), int(k));
            sum += w * e;
            weight += w;
            plain += e;
            ++n;
          }
        clusterCorners[(t * K + k) * 4 + size_t(c)] =
            glm::vec3(weight > 0.0 ? sum / weight : plain / double(n));
      }
    }
  keepOwnClusterLight(s);
}

// The corners' means are a smooth field, and a top's own value may lie far from it: where the
// global pass linked the top's far surfaces through cluster links and its neighbours' through
// patch links (which their texels gather themselves), its cluster light is several times theirs
// and its patch links' correspondingly less. Smoothed, such a top lost what its neighbours'
// patch links carry: the 10k hall's ceiling tiles beside the lights (0.23 against 0.05 around
// them) came out in dark streaks 10 % below the Gouraud layer and the all-pairs frames. So the
// top's corners are shifted by what its own value lies beyond a band of kClusterBand around
// their mean, times its exposure (a mostly covered top's own value is noisy, see above):
// within the band (the spread of the cluster links' visibility estimates across a wall) the
// light stays continuous; beyond it the top keeps all but the band of its own mean (the mean of
// the bilinear or barycentric interpolation over the top's (u,v) is its corners' mean).
void GoodLinksByReceiver::keepOwnClusterLight(const GlobalSolution& s) {
  const std::vector<InputPolygon>& tops = s.hierarchy.tops();
  const size_t T = tops.size(), K = size_t(s.keyCount());
  for (size_t t = 0; t < T; ++t) {
    const int count = tops[t].local.count;
    for (size_t k = 0; k < K; ++k) {
      glm::vec3* corner = &clusterCorners[(t * K + k) * 4];
      glm::dvec3 mean(0.0);
      for (int c = 0; c < count; ++c) mean += glm::dvec3(corner[c]);
      mean /= double(count);
      const glm::dvec3 own(s.topClusterIrradiance[t * K + k]);
      const double e = std::clamp(s.exposureAtKey(int(t), int(k)), 0.0, 1.0);
      glm::dvec3 shift(0.0);
      for (int ch = 0; ch < 3; ++ch) {
        const double d = own[ch] - mean[ch], band = kClusterBand * std::max(own[ch], mean[ch]);
        shift[ch] = d > band ? d - band : d < -band ? d + band : 0.0;
      }
      for (int c = 0; c < count; ++c) corner[c] += glm::vec3(e * shift);
    }
  }
}

GoodLinkGather::GoodLinkGather(const Scene& scene, const GlobalSolution& solution,
                               GoodLinksByReceiver& byReceiver, const MovieExtent& request,
                               const MovieTexels& texels, const std::vector<double>& movieKeyTimes,
                               double shooterRatio, double cacheBytes, GoodLinkGatherStats& stats,
                               SceneVisibility* visibility, int visibilityRays,
                               int nearShooterLevels, double partialShare,
                               int clusterVisibilityRays)
    : scene_(scene),
      solution_(solution),
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
  // one that rests during the movie still blocks. Only the nodes moving during the movie had
  // been taken, and a one-frame movie (--no-coherence) saw no moving blocker at all: cubes-8's
  // scratch frame 0 was 1.4 % brighter than the coherent one.
  if (visibility_) {
    movingNodes_ = movingNodesOf(scene, solution.hierarchy.tops(), solution.keyTimes.front(),
                                 solution.keyTimes.back());
    for (int node : movingNodes_)
      swept_.push_back(scene.sweptBounds(node, keyTimes_.front(), keyTimes_.back()));
  }
  planLinks(byReceiver, request);
  // The global keys the movie's key times fall between.
  std::vector<char> needed(size_t(solution.keyCount()), 0);
  for (double t : keyTimes_) {
    int k0, k1;
    double w;
    solution.keyWeights(t, k0, k1, w);
    needed[size_t(k0)] = needed[size_t(k1)] = 1;
  }
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
    stats.partialLinksFewRays += l.partial && l.rays < visibilityRays_ && l.cell == 1 ? 1 : 0;
  }
  stats.partialTileLinksPerTexel += long(partialTileLinksPerTexel_);
}

const GoodLinksByReceiver::ClusterLightRays& GoodLinkGather::clusterLightRays(int key) {
  const PatchHierarchy& h = solution_.hierarchy;
  const uint32_t R = uint32_t(receiverTop_), T = uint32_t(h.topCount());
  auto [at, fresh] = byReceiver_.clusterLightRays.try_emplace(
      uint64_t(R) * uint64_t(solution_.keyCount()) + uint64_t(key));
  GoodLinksByReceiver::ClusterLightRays& out = at->second;
  if (!fresh) return out;
  const std::vector<Polygon>& world = byReceiver_.staticTopWorld;
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
  std::vector<GoodLinksByReceiver::FarCandidate>& candidates = byReceiver_.farCandidates[key];
  if (candidates.empty()) {
    std::vector<double> cumulative(T, 0.0);
    double total = 0.0;
    for (uint32_t s = 0; s < T; ++s) {
      if (!byReceiver_.topMoves[s]) {
        const glm::dvec3 B = solution_.exposedRadiosityAtKey(int(s), key);
        total += std::max(0.0, B.x + B.y + B.z) * world[s].area();
      }
      cumulative[s] = total;
    }
    if (!(total > 0.0)) return out;
    const uint64_t seed = splitMix64(0x66617263616e64ull ^ uint64_t(key));
    const int m = GoodLinksByReceiver::kFarCandidates;
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
  }
  // The top's far points: the candidates it does not gather itself, drawn again by its kernel
  // cos cos / d^4 from its centroid (the candidates carry B A already), stratified.
  const Polygon& receiver = world[R];
  const glm::dvec3 centre = receiver.centroid(), n = receiver.normal();
  std::vector<double> cumulative(candidates.size(), 0.0);
  double total = 0.0;
  for (size_t c = 0; c < candidates.size(); ++c) {
    const GoodLinksByReceiver::FarCandidate& f = candidates[c];
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
  // A moving receiver's rays would hold only at its first key.
  if (byReceiver_.topMoves.empty()) {  // the static tops' world polygons, once per worker
    const uint32_t T = uint32_t(h.topCount());
    byReceiver_.staticTopWorld.resize(T);
    byReceiver_.topMoves.assign(T, 0);
    for (uint32_t s = 0; s < T; ++s) {
      byReceiver_.topMoves[s] = std::find(movingNodes_.begin(), movingNodes_.end(),
                                          h.top(int(s)).node) != movingNodes_.end();
      if (!byReceiver_.topMoves[s]) byReceiver_.staticTopWorld[s] = nodeWorld(s, t0);
    }
  }
  if (byReceiver_.topMoves[R]) return;
  int k0, k1;
  double w;
  solution_.keyWeights(t0, k0, k1, w);
  const glm::dvec3 own = solution_.clusterIrradianceAtKey(int(R), k0);
  if (!(own.x + own.y + own.z > 0.0)) return;
  const GoodLinksByReceiver::ClusterLightRays& rays = clusterLightRays(k0);
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

Polygon GoodLinkGather::nodeWorld(uint32_t node, double t) const {
  const PatchNode& n = solution_.hierarchy.node(int(node));
  return n.local.transformed(scene_.worldTransform(solution_.hierarchy.topOf(int(node)).node, t));
}

// The links whose receiver is the movie's node, one of its ancestors or one of its descendants:
// every texel's chain is made of these.
void GoodLinkGather::planLinks(const GoodLinksByReceiver& byReceiver, const MovieExtent& request) {
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
  // first: the bundled scene's moving box's foot, 27 % too bright, met the floor strip beside
  // it only at later keys.
  const std::vector<double> firstKey{t0};
  std::vector<uint32_t> shooters, cells{1u};
  std::vector<Polygon> receiverAt;
  for (int r : receivers) {
    for (uint32_t k = byReceiver.start[size_t(r)]; k < byReceiver.start[size_t(r) + 1]; ++k) {
      const uint32_t row = byReceiver.rows[k];
      const uint32_t shooter = solution_.links[row].shooter;
      const bool moves = receiverMoves || scene_.isDynamic(h.topOf(int(shooter)).node, t0, t1);
      const std::vector<double>& times = moves ? keyTimes_ : firstKey;
      receiverAt.clear();
      for (double t : times) receiverAt.push_back(nodeWorld(uint32_t(r), t));
      shooterParts(receiverAt, times, shooter, shooters);
      for (uint32_t q : shooters) {
        const bool emitter = scene_.emits(h.topOf(int(q)));
        if (nearShooterLevels_ > 0 && h.isLeaf(int(q)) && !emitter)
          nearCells(receiverAt, times, q, cells);
        else
          cells.assign(1, 1u);
        for (uint32_t cell : cells) {
          Link l;
          l.row = row;
          l.shooter = q;
          l.cell = cell;
          l.rays = std::max(1, visibilityRays_ >> (2 * cellLevel(cell)));
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
// near parts take their own B (the bundled scene: 8.7 % RMSE / mean without the split, 7.5 %
// with it); far ones, over which F hardly varies, keep the link's node.
void GoodLinkGather::shooterParts(const std::vector<Polygon>& receiverAt,
                                  const std::vector<double>& times, uint32_t shooter,
                                  std::vector<uint32_t>& out) const {
  const PatchHierarchy& h = solution_.hierarchy;
  out.clear();
  std::vector<uint32_t> stack{shooter};
  std::vector<Polygon> world(times.size());
  while (!stack.empty()) {
    const uint32_t q = stack.back();
    stack.pop_back();
    bool split = !h.isLeaf(int(q)) && shooterRatio_ > 0.0;
    if (split) {
      for (size_t k = 0; k < times.size(); ++k) world[k] = nodeWorld(q, times[k]);
      split = polygonSize(world[0]) > shooterRatio_ * nearestDistance(receiverAt, world);
    }
    if (!split) {
      out.push_back(q);
      continue;
    }
    for (int c = 3; c >= 0; --c) stack.push_back(uint32_t(h.node(int(q)).firstChild + c));
  }
}

Polygon GoodLinkGather::linkWorld(const Link& l, double t) const {
  Polygon p = nodeWorld(l.shooter, t);
  for (int i = cellLevel(l.cell) - 1; i >= 0; --i)
    p = subdividePolygon(p)[size_t((l.cell >> (2 * i)) & 3u)];
  return p;
}

// The cells of a near leaf shooter a texel gathers from: its virtual quadtree descended, as
// shooterParts descends the union tree, while a cell is larger than shooterRatio times its
// distance to the receiver, down to nearShooterLevels_.
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
    if (split) split = polygonSize(poly[0]) > shooterRatio_ * nearestDistance(receiverAt, poly);
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

// The re-gathered radiosity of the near leaf shooters' cells at the needed keys, made for the
// leaves not yet in byReceiver_'s store (the moving nodes placed at each key's time first).
void GoodLinkGather::planNearShooters(const std::vector<char>& needed, GoodLinkGatherStats& stats) {
  if (nearShooterLevels_ == 0) return;
  const auto start = std::chrono::steady_clock::now();
  std::vector<uint32_t> leaves;
  for (const Link& l : links_)
    if (l.cell != 1) leaves.push_back(l.shooter);
  if (leaves.empty()) return;
  std::sort(leaves.begin(), leaves.end());
  leaves.erase(std::unique(leaves.begin(), leaves.end()), leaves.end());
  byReceiver_.indexAllLinks(solution_);
  for (uint32_t q : leaves) {
    std::vector<double>& area = cellAreas_[q];
    for (const Polygon& c : cellsOf(solution_.hierarchy.node(int(q)).local, nearShooterLevels_))
      area.push_back(c.area());
  }
  const uint64_t K = uint64_t(solution_.keyCount());
  for (int k = 0; k < int(K); ++k) {
    if (!needed[size_t(k)]) continue;
    std::vector<uint32_t> missing;
    for (uint32_t q : leaves)
      if (!byReceiver_.nearShooterCells.count(q * K + uint64_t(k))) missing.push_back(q);
    if (missing.empty()) continue;
    const double t = solution_.keyTimes[size_t(k)];
    if (visibility_->dynamicNodeCount() > 0) visibility_->setTime(t);
    std::vector<std::vector<float>> made(missing.size());
    std::vector<GoodLinksByReceiver::FixedTerms> fresh(missing.size());
    std::vector<const GoodLinksByReceiver::FixedTerms*> fixed(missing.size(), nullptr);
    for (size_t i = 0; i < missing.size(); ++i) {
      auto it = byReceiver_.nearShooterFixed.find(missing[i]);
      if (it != byReceiver_.nearShooterFixed.end()) fixed[i] = &it->second;
    }
    tbb::parallel_for(size_t(0), missing.size(), [&](size_t i) {
      made[i] = regatherCells(missing[i], k, t, fixed[i], fixed[i] ? nullptr : &fresh[i]);
    });
    for (size_t i = 0; i < missing.size(); ++i) {
      byReceiver_.nearShooterCells[missing[i] * K + uint64_t(k)] = std::move(made[i]);
      if (!fixed[i] && !fresh[i].rows.empty())
        byReceiver_.nearShooterFixed[missing[i]] = std::move(fresh[i]);
    }
    stats.nearShooterLeaves += long(missing.size());
  }
  stats.nearShooterSeconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// B at each cell centre of leaf q at key k (formula in good_link_gather.h), as a ratio to the
// leaf's B (channel sums): the colour stays the leaf's.
std::vector<float> GoodLinkGather::regatherCells(uint32_t q, int k, double t,
                                                 const GoodLinksByReceiver::FixedTerms* fixed,
                                                 GoodLinksByReceiver::FixedTerms* fresh) const {
  const PatchHierarchy& h = solution_.hierarchy;
  const int levels = nearShooterLevels_;
  const std::vector<Polygon> cells = cellsOf(nodeWorld(q, t), levels);
  std::vector<float> ratio(cells.size(), 1.0f);
  const glm::dvec3 bq = solution_.exposedRadiosityAtKey(int(q), k);
  const double bqSum = bq.x + bq.y + bq.z;
  if (!(bqSum > 0.0)) return ratio;
  const uint32_t top = h.node(int(q)).id.top;
  const int m = h.top(int(top)).material;
  if (m < 0 || m >= int(scene_.materials.size())) return ratio;
  const Material& mat = scene_.materials[size_t(m)];
  const bool storedVisibility = !solution_.linkSampleVisibility.empty();
  const glm::dvec3 cluster = solution_.clusterIrradianceAtKey(int(top), k);
  const double size = polygonSize(cells[0]);
  std::vector<glm::dvec3> y(cells.size()), n(cells.size()), H(cells.size(), cluster);
  std::vector<char> open(cells.size(), 0);
  for (size_t i = 0; i < cells.size(); ++i) {
    y[i] = cells[i].centroid();
    n[i] = cells[i].normal();
    open[i] = !(insideSolid(visibility_->staticPart(), scene_, h, top, y[i], n[i], size, t) ||
                (visibility_->dynamicNodeCount() > 0 &&
                 insideSolid(visibility_->movingPart(), scene_, h, top, y[i], n[i], size, t)));
  }
  // The terms of one link at every cell: F(y_i -> s) times, where the link is partly occluded,
  // V from rays (against the moving nodes too unless `fixedOnly`).
  auto terms = [&](uint32_t row, bool fixedOnly, auto&& add) {
    const GlobalLink& g = solution_.links[row];
    const Polygon s = nodeWorld(g.shooter, t);
    // A kept link's one sample, whatever the key (one outside its activity reads 0).
    const double v = !storedVisibility ? 1.0
                     : fixedOnly       ? double(solution_.linkSampleVisibility[g.sampleOffset])
                                       : solution_.linkVisibilityAtKey(g, k);
    const bool partial = v < 1.0;
    const bool moving = !fixedOnly && visibility_->dynamicNodeCount() > 0;
    std::vector<glm::dvec3> points;
    const uint32_t sTop = h.node(int(g.shooter)).id.top;
    for (size_t i = 0; i < cells.size(); ++i) {
      if (!open[i] && !fixedOnly) continue;
      double f = pointToPolygonFormFactor(y[i], n[i], s);
      if (!(f > 0.0)) continue;
      if (partial) {
        if (points.empty())
          points = VisibilityScene::samplePoints(s, visibilityRays_, splitMix64(row));
        uint64_t bits = visibility_->staticPart().openFrom(y[i], points, top, sTop);
        if (bits != 0 && moving)
          bits = visibility_->movingPart().openFrom(y[i], points, top, sTop, bits);
        f *= pointVisibility(y[i], n[i], points, s.normal(), bits, nullptr);
      }
      add(i, f);
    }
  };
  // A static leaf's links that do not change (both ends static, one F·V sample: no moving node
  // crossed their shaft) take the same terms at every key: made once (against the static
  // blockers), kept, and summed first, so that a key's sum does not depend on which key came
  // first (movies in any order, any shard split: bit-identical).
  const double t0 = solution_.keyTimes.front(), t1 = solution_.keyTimes.back();
  const bool leafStatic = !scene_.isDynamic(int(h.top(int(top)).node), t0, t1);
  auto isFixed = [&](const GlobalLink& g) {
    return leafStatic && g.sampleCount == 1 &&
           !scene_.isDynamic(int(h.topOf(int(g.shooter)).node), t0, t1);
  };
  if (leafStatic && !fixed && fresh) {
    for (int a = int(q); a >= 0; a = h.node(a).parent)
      for (uint32_t e = byReceiver_.allStart[size_t(a)]; e < byReceiver_.allStart[size_t(a) + 1];
           ++e) {
        const uint32_t row = byReceiver_.allRows[e];
        if (!isFixed(solution_.links[row])) continue;
        fresh->rows.push_back(row);
        fresh->factor.resize(fresh->rows.size() * cells.size(), 0.0f);
        float* f = &fresh->factor[(fresh->rows.size() - 1) * cells.size()];
        terms(row, true, [&](size_t i, double v) { f[i] = float(v); });
      }
    fixed = fresh;
  }
  if (fixed)
    for (size_t r = 0; r < fixed->rows.size(); ++r) {
      const GlobalLink& g = solution_.links[fixed->rows[r]];
      if (!(solution_.linkFvAtKey(g, k) > 0.0)) continue;
      const glm::dvec3 b = solution_.exposedRadiosityAtKey(int(g.shooter), k);
      for (size_t i = 0; i < cells.size(); ++i)
        H[i] += double(fixed->factor[r * cells.size() + i]) * b;
    }
  // The other links, link by link (its shooter's polygon and ray ends made once).
  for (int a = int(q); a >= 0; a = h.node(a).parent)
    for (uint32_t e = byReceiver_.allStart[size_t(a)]; e < byReceiver_.allStart[size_t(a) + 1];
         ++e) {
      const uint32_t row = byReceiver_.allRows[e];
      const GlobalLink& g = solution_.links[row];
      if (isFixed(g) || !(solution_.linkFvAtKey(g, k) > 0.0)) continue;
      const glm::dvec3 b = solution_.exposedRadiosityAtKey(int(g.shooter), k);
      if (!(b.x + b.y + b.z > 0.0)) continue;
      terms(row, false, [&](size_t i, double f) { H[i] += f * b; });
    }
  for (size_t i = 0; i < cells.size(); ++i) {
    const glm::dvec3 bi = mat.emission + mat.reflectance * H[i];
    ratio[i] = open[i] ? float((bi.x + bi.y + bi.z) / bqSum) : 0.0f;
  }
  return ratio;
}

// A cell's ratio: the area-weighted mean of its leaf's finest cells under it.
double GoodLinkGather::cellRatio(const Link& l, int key) const {
  if (l.cell == 1) return 1.0;
  const uint64_t K = uint64_t(solution_.keyCount());
  const std::vector<float>& r = byReceiver_.nearShooterCells.at(l.shooter * K + uint64_t(key));
  const std::vector<double>& cellArea = cellAreas_.at(l.shooter);
  const int level = cellLevel(l.cell), span = 1 << (2 * (nearShooterLevels_ - level));
  const uint32_t first = (l.cell & ((1u << (2 * level)) - 1u)) * uint32_t(span);
  double sum = 0.0, area = 0.0;
  for (uint32_t i = first; i < first + uint32_t(span); ++i) {
    sum += cellArea[i] * double(r[i]);
    area += cellArea[i];
  }
  return area > 0.0 ? sum / area : 1.0;
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
  // little: the cubic scene's door jambs 3.4 % too dark (in a closed furnace the sum of F V over
  // a jamb texel's links 0.98-0.99, with every partial link per texel 1.000).
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
        // wall 20 % visible through a doorway has all 16 pairs blocked 3 % of the time). Kept at
        // 0 it is lost from every texel, while the links whose V came out above 0 are corrected
        // per texel: the sum of F V over the cubic scene's walls' texels 0.98-0.99 in a closed
        // furnace, 0.99-1.00 with these. Its risk is what it would carry unoccluded, B_q F.
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
          GoodLinksByReceiver::HiddenLink{links_[j].row, links_[j].shooter, links_[j].cell},
          newHidden[j]);
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
//   texel). Each small link had kept its V, and a receiver with many of them (the 10k hall's
//   floor under the desks' front edges, seeing the ceiling's leaves past the desk tops) came
//   out 9.4 % too bright in a strip (README, "At `e3297e9`").
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
      links_[j].rays = std::max(1, links_[j].rays / 4);
    }
  }
}

// A texel's leaf chain, deepest first, as far up as (not including) `stop` (-1: to the top).
template <class F>
void forChain(const PatchHierarchy& h, int leaf, int stop, F&& f) {
  for (int a = leaf; a >= 0 && a != stop; a = h.node(a).parent) f(a);
}

// The deepest node whose domain holds both a and b.
int commonAncestor(const PatchHierarchy& h, int a, int b) {
  while (a != b) {
    if (h.node(a).id.level() >= h.node(b).id.level())
      a = h.node(a).parent;
    else
      b = h.node(b).parent;
    if (a < 0 || b < 0) return -1;
  }
  return a;
}

// Per tile of kTile x kTile texels: the links of the nodes that hold the whole tile go to the
// tile when their shooter part is farther than kTileFarRatio times the tile's size (F evaluated
// at the tile's corners, which are texel centres shared with the neighbouring tiles, and
// interpolated bilinearly: the error falls as (size / distance)^2), the others to each texel.
// The per-texel form factors of links that do not move are kept when they fit in cacheBytes.
void GoodLinkGather::planTexels(double cacheBytes) {
  const PatchHierarchy& h = solution_.hierarchy;
  const double t0 = keyTimes_.front();
  std::map<int, std::pair<uint32_t, uint32_t>> linksOf;  // receiver node -> links_ range
  for (uint32_t j = 0; j < uint32_t(links_.size()); ++j) {
    auto [it, fresh] =
        linksOf.emplace(int(solution_.links[links_[j].row].receiver), std::make_pair(j, j + 1));
    if (!fresh) it->second.second = j + 1;
  }
  auto linksAt = [&](int node, auto&& f) {
    auto it = linksOf.find(node);
    if (it != linksOf.end())
      for (uint32_t j = it->second.first; j < it->second.second; ++j) f(j);
  };
  const int w = texels_.width, hgt = texels_.height;
  const size_t T = texels_.topUv.size();
  std::vector<int> leaf(T);
  for (size_t x = 0; x < T; ++x) leaf[x] = leafAtTopUv(h, receiverTop_, texels_.topUv[x]);
  const TexelFrame frame = texelFrame(t0);
  auto world = [&](size_t x) { return frame.point(texels_.localPoint[x]); };
  auto normal = [&](size_t x) { return frame.normal(texels_.localNormal[x]); };
  std::vector<Polygon> shooter(links_.size());
  std::vector<glm::dvec3> shooterCentre(links_.size());
  std::vector<double> shooterRadius(links_.size(), 0.0);
  for (size_t j = 0; j < links_.size(); ++j) {
    shooter[j] = linkWorld(links_[j], t0);
    shooterCentre[j] = shooter[j].centroid();
    for (int k = 0; k < shooter[j].count; ++k)
      shooterRadius[j] =
          std::max(shooterRadius[j], glm::length(shooter[j].v[size_t(k)] - shooterCentre[j]));
  }

  tilesX_ = (w + kTile - 1) / kTile;
  const int tilesY = (hgt + kTile - 1) / kTile;
  tiles_.assign(size_t(tilesX_) * size_t(tilesY), Tile());
  for (size_t ti = 0; ti < tiles_.size(); ++ti) {
    Tile& tile = tiles_[ti];
    tile.i0 = int(ti % size_t(tilesX_)) * kTile;
    tile.j0 = int(ti / size_t(tilesX_)) * kTile;
    tile.i1 = std::min(tile.i0 + kTile, w - 1);  // corner columns and rows: texel centres
    tile.j1 = std::min(tile.j0 + kTile, hgt - 1);
  }
  const std::vector<char> covered = coveredTiles();
  std::vector<std::vector<uint32_t>> nearOfTile(tiles_.size());
  // Per tile, the near links of the nodes below its common one, with the texels they reach.
  std::vector<std::vector<std::pair<uint64_t, uint32_t>>> nearBelow(tiles_.size());
  tbb::parallel_for(size_t(0), tiles_.size(), [&](size_t ti) {
    Tile& tile = tiles_[ti];
    int common = leaf[size_t(tile.j0) * w + tile.i0];
    for (int j = tile.j0; j < std::min(tile.j0 + kTile, hgt); ++j)
      for (int i = tile.i0; i < std::min(tile.i0 + kTile, w); ++i)
        if (common >= 0) common = commonAncestor(h, common, leaf[size_t(j) * w + i]);
    tile.common = common;
    const std::array<size_t, 4> corner = tile.cornerTexels(w);
    glm::dvec3 p[4];
    double size = 0.0;
    for (int c = 0; c < 4; ++c) p[c] = world(corner[size_t(c)]);
    for (int c = 0; c < 4; ++c) size = std::max(size, glm::length(p[c] - p[(c + 2) % 4]));
    // Far: the nearest corner farther from the shooter part than kTileFarRatio x size. Bounding
    // spheres decide most pairs without the four point-to-polygon distances.
    glm::dvec3 centre(0.0);
    for (int c = 0; c < 4; ++c) centre += 0.25 * p[c];
    double radius = 0.0;
    for (int c = 0; c < 4; ++c) radius = std::max(radius, glm::length(p[c] - centre));
    auto isFar = [&](uint32_t j, double ratio) {
      const double limit = ratio * size;
      const double dc = glm::length(centre - shooterCentre[j]);
      if (dc - radius - shooterRadius[j] > limit) return true;
      if (dc - radius <= limit) {  // some corner within limit of the shooter's centroid
        double nearest = std::numeric_limits<double>::infinity();
        for (int c = 0; c < 4; ++c)
          nearest = std::min(nearest, glm::length(p[c] - shooterCentre[j]));
        if (nearest <= limit) return false;
      }
      double d = std::numeric_limits<double>::infinity();
      for (int c = 0; c < 4; ++c) d = std::min(d, distanceToPolygon(p[c], shooter[j]));
      return d > limit;
    };
    // A covered corner sees nothing: interpolating its V would darken the exposed texels next
    // to a box's foot or around a lamp on the ceiling (-23 % on the Cornell box's ceiling next
    // to its lamp).
    auto toTile = [&](uint32_t j, double ratio) {
      return isFar(j, ratio) && !(links_[j].partial && covered[ti]);
    };
    forChain(h, common, -1, [&](int node) {
      linksAt(node, [&](uint32_t j) {
        if (toTile(j, kTileFarRatio))
          tile.links.push_back(j);
        else
          nearOfTile[ti].push_back(j);
      });
    });
    if (!tile.links.empty()) tile.groups.emplace_back(~uint64_t(0), uint32_t(tile.links.size()));
    // The nodes below the common one, each with the tile's texels it holds: their far links
    // are interpolated over the tile too, for those texels (kTileFarRatioBelow). Per texel,
    // they had made the bundled scene's 96 frames take 6.84 M per-texel form factors instead
    // of 5.04 M once its textures were sized on the sqrt 2 ladder, whose tiles mostly
    // straddle two nodes (rad-movies 13.2 -> 11.1 s).
    std::map<int, uint64_t> below;
    for (int j = tile.j0; j < std::min(tile.j0 + kTile, hgt); ++j)
      for (int i = tile.i0; i < std::min(tile.i0 + kTile, w); ++i)
        forChain(h, leaf[size_t(j) * w + i], common,
                 [&](int node) { below[node] |= Tile::bit(i, j, tile); });
    std::map<uint64_t, std::vector<uint32_t>> farByMask;
    for (const auto& [node, mask] : below)
      linksAt(node, [&](uint32_t j) {
        if (toTile(j, kTileFarRatioBelow))
          farByMask[mask].push_back(j);
        else
          nearBelow[ti].emplace_back(mask, j);
      });
    for (const auto& [mask, ids] : farByMask) {
      tile.links.insert(tile.links.end(), ids.begin(), ids.end());
      tile.groups.emplace_back(mask, uint32_t(tile.links.size()));
    }
  });
  // The far links at the tiles' corners, once per corner texel and link: a corner is shared by
  // up to four tiles, which mostly interpolate the same links. Their form factors (links that
  // do not move) and open rays past the static blockers are made here, the rest per key
  // (gather), each once per corner and link: per tile it had been up to four times, 85 M of
  // rad-movies' 155 M visibilityAt calls on the table scene.
  std::map<size_t, std::vector<uint32_t>> cornerLinks;  // corner texel -> its links, sorted
  for (const Tile& tile : tiles_)
    for (size_t corner : tile.cornerTexels(w)) {
      std::vector<uint32_t>& ids = cornerLinks[corner];
      ids.insert(ids.end(), tile.links.begin(), tile.links.end());
    }
  corners_.clear();
  cornerLink_.clear();
  for (auto& [corner, ids] : cornerLinks) {
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    corners_.push_back({corner, uint32_t(cornerLink_.size())});
    cornerLink_.insert(cornerLink_.end(), ids.begin(), ids.end());
  }
  corners_.push_back({0, uint32_t(cornerLink_.size())});  // the end of the last corner's links
  cornerFormFactor_.assign(cornerLink_.size(), 0.0);
  cornerOpen_.assign(cornerLink_.size(), 0);
  tbb::parallel_for(size_t(0), corners_.size() - 1, [&](size_t i) {
    const size_t x = corners_[i].texel;
    const glm::dvec3 p = world(x), nx = normal(x);
    for (uint32_t e = corners_[i].first; e < corners_[i + 1].first; ++e) {
      const Link& l = links_[cornerLink_[e]];
      if (l.moves) continue;
      cornerFormFactor_[e] = pointToPolygonFormFactor(p, nx, shooter[cornerLink_[e]]);
      if (l.partial) cornerOpen_[e] = openRays(visibility_->staticPart(), p, l, l.points);
    }
  });
  std::unordered_map<size_t, size_t> cornerIndex;  // corner texel -> its corners_ index
  for (size_t i = 0; i + 1 < corners_.size(); ++i) cornerIndex[corners_[i].texel] = i;
  tbb::parallel_for(size_t(0), tiles_.size(), [&](size_t ti) {
    Tile& tile = tiles_[ti];
    const std::array<size_t, 4> c4 = tile.cornerTexels(w);
    tile.cornerEntry.assign(tile.links.size() * 4, 0);
    for (int c = 0; c < 4; ++c) {
      const size_t i = cornerIndex.at(c4[size_t(c)]);
      const auto first = cornerLink_.begin() + corners_[i].first;
      const auto last = cornerLink_.begin() + corners_[i + 1].first;
      for (size_t k = 0; k < tile.links.size(); ++k)
        tile.cornerEntry[k * 4 + size_t(c)] =
            uint32_t(std::lower_bound(first, last, tile.links[k]) - cornerLink_.begin());
    }
  });
  perTexelOnTiles(shooter, nearOfTile, nearBelow);
  for (const Tile& tile : tiles_) tileLinkCount_ += tile.links.size();
  // Per texel, in texel order: the near links of its chain below its tile's common node, then
  // the tile's near links.
  texelStart_.assign(T + 1, 0);
  for (int j = 0; j < hgt; ++j)
    for (int i = 0; i < w; ++i) {
      const size_t x = size_t(j) * w + i;
      const size_t ti = size_t(j / kTile) * size_t(tilesX_) + size_t(i / kTile);
      const uint64_t b = Tile::bit(i, j, tiles_[ti]);
      for (const auto& [mask, l] : nearBelow[ti])
        if (mask & b) texelLinks_.push_back(l);
      texelLinks_.insert(texelLinks_.end(), nearOfTile[ti].begin(), nearOfTile[ti].end());
      texelStart_[x + 1] = uint32_t(texelLinks_.size());
    }
  bool anyFixed = false;  // partial links whose ends do not move: static rays cached
  for (const Link& l : links_) anyFixed = anyFixed || (l.partial && !l.moves);
  const double entryBytes = sizeof(float) + (anyFixed ? sizeof(uint64_t) : 0);
  cached_ = double(texelLinks_.size()) * entryBytes <= cacheBytes;
  if (!cached_) return;
  texelFormFactor_.resize(texelLinks_.size());
  if (anyFixed) texelOpen_.assign(texelLinks_.size(), 0);
  tbb::parallel_for(size_t(0), T, [&](size_t x) {
    const glm::dvec3 p = world(x), nx = normal(x);
    for (uint32_t e = texelStart_[x]; e < texelStart_[x + 1]; ++e) {
      const uint32_t j = texelLinks_[e];
      texelFormFactor_[e] =
          links_[j].moves ? 0.0f : float(pointToPolygonFormFactor(p, nx, shooter[j]));
      const Link& l = links_[j];
      if (l.partial && !l.moves)
        texelOpen_[e] = openRays(visibility_->staticPart(), p, l, l.points);
    }
  });
  if (!anyFixed) return;
  // The kernels of the entries whose V is made per key (rays not all open, or moving blockers
  // that may close them), within what is left of the budget.
  std::vector<uint32_t> at(texelLinks_.size(), kNoKernels);
  size_t kernels = 0;
  for (size_t e = 0; e < texelLinks_.size(); ++e) {
    const Link& l = links_[texelLinks_[e]];
    if (!l.partial || l.moves) continue;
    const int k = std::min(l.rays, VisibilityScene::kMaxRecordedPairs);
    const uint64_t all = allRaysOpen(k);
    if ((texelOpen_[e] & all) == all && !l.movingBlockers) continue;
    at[e] = uint32_t(kernels);
    kernels += size_t(k);
  }
  const double left = cacheBytes - double(texelLinks_.size()) * entryBytes;
  if (double(kernels) * sizeof(double) + double(at.size()) * sizeof(uint32_t) > left ||
      kernels >= size_t(kNoKernels))
    return;
  texelKernelAt_.swap(at);
  texelKernel_.resize(kernels);
  tbb::parallel_for(size_t(0), T, [&](size_t x) {
    const glm::dvec3 p = world(x), nx = normal(x);
    for (uint32_t e = texelStart_[x]; e < texelStart_[x + 1]; ++e) {
      if (texelKernelAt_[e] == kNoKernels) continue;
      const Link& l = links_[texelLinks_[e]];
      pointKernels(p, nx, l.points, shooter[texelLinks_[e]].normal(),
                   std::min(l.rays, VisibilityScene::kMaxRecordedPairs),
                   &texelKernel_[texelKernelAt_[e]]);
    }
  });
}

// A partial link's V interpolated over a tile from its corners misses what changes inside:
// near a concave edge V drops steeply only close to it (a chair's back above its seat, the floor
// along a wall), so the straight line between a tile's corners, which lie on the texture's
// border on a small texture, is too dark inside (the 10k hall's chairs -4.1 %, its frame's
// bias -0.97 %, against -3.1 % and -0.83 % with every partial link per texel). So its rays are
// also cast from the tile's middle texel, and where B_q F(x -> q) |V(x) - interpolated V| there
// is at least --gather-partial-share of what the receiver gathers, the link goes per texel on
// that tile. Links whose ends do not move (their corner rays are cast once per movie); a moving
// one keeps the corners.
void GoodLinkGather::perTexelOnTiles(
    const std::vector<Polygon>& shooter, std::vector<std::vector<uint32_t>>& nearOfTile,
    std::vector<std::vector<std::pair<uint64_t, uint32_t>>>& nearBelow) {
  if (!visibility_) return;
  const int w = texels_.width;
  const TexelFrame frame = texelFrame(keyTimes_.front());
  std::vector<double> brightest(links_.size(), 0.0);  // a partial link's largest B_q (channel sum)
  for (size_t j = 0; j < links_.size(); ++j)
    if (links_[j].partial)
      for (const glm::dvec3& b : links_[j].weight)
        brightest[j] = std::max(brightest[j], b.x + b.y + b.z);
  std::vector<long> moved(tiles_.size(), 0);
  tbb::parallel_for(size_t(0), tiles_.size(), [&](size_t ti) {
    Tile& tile = tiles_[ti];
    const size_t mid =
        size_t((tile.j0 + tile.j1) / 2) * size_t(w) + size_t((tile.i0 + tile.i1) / 2);
    const glm::dvec3 p = frame.point(texels_.localPoint[mid]);
    const glm::dvec3 n = frame.normal(texels_.localNormal[mid]);
    auto interpolates = [&](size_t k) {
      const uint32_t j = tile.links[k];
      const Link& l = links_[j];
      if (!l.partial || l.moves) return true;
      double interpolated = 0.0;
      for (size_t c = 0; c < 4; ++c)
        interpolated +=
            0.25 * double(std::bitset<64>(cornerOpen_[tile.cornerEntry[k * 4 + c]]).count());
      const uint64_t open = openRays(visibility_->staticPart(), p, l, l.points);
      const double dv =
          std::abs(double(std::bitset<64>(open).count()) - interpolated) / double(l.rays);
      return brightest[j] * pointToPolygonFormFactor(p, n, shooter[j]) * dv <
             partialShare_ * linkGather_[j];
    };
    std::vector<uint32_t> kept, keptEntry;
    std::vector<std::pair<uint64_t, uint32_t>> groups;
    for (size_t g = 0, k = 0; g < tile.groups.size(); ++g) {
      const uint64_t mask = tile.groups[g].first;
      for (; k < tile.groups[g].second; ++k) {
        if (interpolates(k)) {
          kept.push_back(tile.links[k]);
          keptEntry.insert(keptEntry.end(), tile.cornerEntry.begin() + std::ptrdiff_t(k * 4),
                           tile.cornerEntry.begin() + std::ptrdiff_t(k * 4 + 4));
          continue;
        }
        ++moved[ti];
        if (mask == ~uint64_t(0))
          nearOfTile[ti].push_back(tile.links[k]);
        else
          nearBelow[ti].emplace_back(mask, tile.links[k]);
      }
      if (groups.empty() ? !kept.empty() : groups.back().second != uint32_t(kept.size()))
        groups.emplace_back(mask, uint32_t(kept.size()));
    }
    tile.links.swap(kept);
    tile.cornerEntry.swap(keptEntry);
    tile.groups.swap(groups);
  });
  for (long m : moved) partialTileLinksPerTexel_ += size_t(m);
}

// Per tile: a corner texel is covered, at some key time of the movie, by a touching solid (its
// normal ray first meets the back of a one-sided surface, as rad-global's exposure decides).
// The moving nodes are tested at every key time, the static ones once.
std::vector<char> GoodLinkGather::coveredTiles() const {
  std::vector<char> covered(tiles_.size(), 0);
  if (!visibility_) return covered;
  const PatchHierarchy& h = solution_.hierarchy;
  const int w = texels_.width;
  auto test = [&](const VisibilityScene& blockers, double t) {
    const TexelFrame frame = texelFrame(t);
    const double size = polygonSize(nodeWorld(uint32_t(movieNode_), t));
    tbb::parallel_for(size_t(0), tiles_.size(), [&](size_t ti) {
      if (covered[ti]) return;
      for (size_t x : tiles_[ti].cornerTexels(w)) {
        const glm::dvec3 p = frame.point(texels_.localPoint[x]);
        const glm::dvec3 d = frame.normal(texels_.localNormal[x]) * size;
        // Undecided counts as covered here: the tile then gathers its partial links per
        // texel, which is right either way.
        if (coveredBySolid(blockers, scene_, h, uint32_t(receiverTop_), p, d, t) !=
            RayStart::kOutside) {
          covered[ti] = 1;
          return;
        }
      }
    });
  };
  test(visibility_->staticPart(), keyTimes_.front());
  if (visibility_->dynamicNodeCount() > 0)
    for (double t : keyTimes_) {
      visibility_->setTime(t);
      test(visibility_->movingPart(), t);
    }
  return covered;
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
  l.seed = linkSeed(h.node(int(g.receiver)).id, h.node(int(l.shooter)).id);
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
// texel's V rested on the one or two rays left: on the 10k hall's all-pairs run one ray of four
// decided a wedge of the cabin's back face, blocked by the fin, which came out 25 % darker than
// the references. Where the two ends move against each other (a floor seen from a moving box)
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
  int k0, k1;
  double w;
  solution_.keyWeights(t, k0, k1, w);
  std::vector<glm::dvec3> weight(links_.size());
  std::vector<Polygon> shooter(links_.size());
  std::vector<glm::dvec3> shooterNormal(links_.size());  // partial links: once per key
  // Partial links: the shooter points (moving ones where they are at t) and their weights at t.
  const int rays = visibilityRays_;
  std::vector<std::vector<glm::dvec3>> points(links_.size());
  std::vector<double> pointWeight(links_.size() * size_t(rays));
  bool castNow = false;
  for (size_t j = 0; j < links_.size(); ++j) {
    const Link& l = links_[j];
    weight[j] = (1.0 - w) * l.weight[size_t(k0)] + w * l.weight[size_t(k1)];
    if (l.moves || !cached_ || l.partial) shooter[j] = linkWorld(l, t);
    if (!l.partial) continue;
    shooterNormal[j] = shooter[j].normal();
    for (int i = 0; i < l.rays; ++i)
      pointWeight[j * rays + i] = (1.0 - w) * l.pointWeight[size_t(k0) * l.rays + i] +
                                  w * l.pointWeight[size_t(k1) * l.rays + i];
    if (l.moves) points[j] = pointsInFront(shooter[j], t, l.rays, l.seed);
    castNow = castNow || l.movingBlockers;
  }
  // Rays cast now see the moving nodes where they are at t (not thread-safe: before the loop).
  if (castNow && visibility_->dynamicNodeCount() > 0) visibility_->setTime(t);
  auto pointsOf = [&](uint32_t j) -> const std::vector<glm::dvec3>& {
    return links_[j].moves ? points[j] : links_[j].points;
  };
  // Per partial link with moving blockers: whether a moving node, where it is at t, meets the
  // shaft (the convex hull of the movie's node and the shooter part, which holds every ray):
  // the swept bounds over the whole movie say only that it may, at some key.
  std::vector<char> movingNow(links_.size(), 0);
  if (castNow) {
    std::vector<std::array<glm::dvec3, 2>> now;
    for (int node : movingNodes_) now.push_back(scene_.sweptBounds(node, t, t));
    const Polygon receiver = nodeWorld(uint32_t(movieNode_), t);
    tbb::parallel_for(size_t(0), links_.size(), [&](size_t j) {
      if (!links_[j].partial || !links_[j].movingBlockers) return;
      for (const auto& box : now)
        if (shaftMeetsBox(receiver, shooter[j], box[0], box[1])) {
          movingNow[j] = 1;
          return;
        }
    });
  }
  // The receiver top's cluster light at its corners, linear in t between the keys as `weight`,
  // interpolated over the top by the texels' (u,v) (bilinear on a quad, barycentric on a
  // triangle).
  glm::dvec3 clusterCorner[4] = {glm::dvec3(0.0), glm::dvec3(0.0), glm::dvec3(0.0),
                                 glm::dvec3(0.0)};
  const bool triangleTop = solution_.hierarchy.top(receiverTop_).local.count == 3;
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
  auto cluster = [&](size_t x) {
    const double u = texels_.topUv[x].x, v = texels_.topUv[x].y;
    if (triangleTop)
      return (1.0 - u - v) * clusterCorner[0] + u * clusterCorner[1] + v * clusterCorner[2];
    return (1.0 - u) * (1.0 - v) * clusterCorner[0] + u * (1.0 - v) * clusterCorner[1] +
           u * v * clusterCorner[2] + (1.0 - u) * v * clusterCorner[3];
  };
  const TexelFrame frame = texelFrame(t);
  const int width = texels_.width, height = texels_.height;
  auto world = [&](size_t x) { return frame.point(texels_.localPoint[x]); };
  auto normal = [&](size_t x) { return frame.normal(texels_.localNormal[x]); };
  // The far links' F V at the corner texels, once per corner and link (the tiles sharing a
  // corner read it).
  std::vector<double> cornerValue(cornerLink_.size(), 0.0);
  tbb::parallel_for(size_t(0), corners_.empty() ? 0 : corners_.size() - 1, [&](size_t i) {
    const size_t x = corners_[i].texel;
    const glm::dvec3 p = world(x), nx = normal(x);
    for (uint32_t e = corners_[i].first; e < corners_[i + 1].first; ++e) {
      const uint32_t j = cornerLink_[e];
      const Link& l = links_[j];
      if (weight[j] == glm::dvec3(0.0)) continue;
      double f = l.moves ? pointToPolygonFormFactor(p, nx, shooter[j]) : cornerFormFactor_[e];
      if (l.partial && f > 0.0)
        f *= visibilityAt(p, nx, l, pointsOf(j), shooterNormal[j],
                          l.moves ? nullptr : &cornerOpen_[e], &pointWeight[j * rays],
                          movingNow[j] != 0);
      cornerValue[e] = f;
    }
  });
  tbb::parallel_for(size_t(0), tiles_.size(), [&](size_t ti) {
    const Tile& tile = tiles_[ti];
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
        if (weight[j] == glm::dvec3(0.0)) continue;
        for (int c = 0; c < 4; ++c)
          corner[c] += cornerValue[tile.cornerEntry[k * 4 + size_t(c)]] * weight[j];
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
        const glm::dvec3 p = world(x), nx = normal(x);
        for (uint32_t e = texelStart_[x]; e < texelStart_[x + 1]; ++e) {
          const uint32_t l = texelLinks_[e];
          const Link& link = links_[l];
          if (weight[l] == glm::dvec3(0.0)) continue;
          double f = cached_ && !link.moves ? double(texelFormFactor_[e])
                                            : pointToPolygonFormFactor(p, nx, shooter[l]);
          if (link.partial && f > 0.0)
            f *= visibilityAt(p, nx, link, pointsOf(l), shooterNormal[l],
                              cached_ && !link.moves ? &texelOpen_[e] : nullptr,
                              &pointWeight[l * rays], movingNow[l] != 0,
                              !texelKernelAt_.empty() && texelKernelAt_[e] != kNoKernels
                                  ? &texelKernel_[texelKernelAt_[e]]
                                  : nullptr);
          H += f * weight[l];
        }
        acc[x] = H + (clusterVisibility_.empty() ? cluster(x)
                                                 : double(clusterVisibility_[x]) * cluster(x));
      }
  });
}

}  // namespace rad
