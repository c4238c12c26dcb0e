// The gather's plan over texel tiles (GoodLinkGather in good_link_gather.h): which links a tile
// interpolates from its corners and which each texel evaluates, the corners' and texels' terms
// made once per movie, and which tiles a touching solid covers.
#include <algorithm>
#include <array>
#include <bitset>
#include <cmath>
#include <limits>
#include <map>
#include <unordered_map>

#include <tbb/parallel_for.h>

#include "libcommon/movies/good_link_gather.h"
#include "libcommon/movies/solid_contact.h"
#include "libcommon/radiosity/form_factor.h"

namespace rad {
namespace {

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

}  // namespace

// Per tile of kTile x kTile texels: the links of the nodes that hold the whole tile go to the
// tile when their shooter part is farther than kTileFarRatio times the tile's size (F evaluated
// at the tile's corners, which are texel centres shared with the neighbouring tiles, and
// interpolated bilinearly: the error falls as (size / distance)^2), the others to each texel.
// The per-texel form factors of links that do not move are kept when they fit in cacheBytes.
void GoodLinkGather::planTexels(double cacheBytes) {
  const PatchHierarchy& h = solution_.hierarchy;
  const double t0 = keyTimes_.front();
  const LinkRanges linksOf = linkRanges();
  const size_t T = texels_.topUv.size();
  std::vector<int> leaf(T);
  for (size_t x = 0; x < T; ++x) leaf[x] = leafAtTopUv(h, receiverTop_, texels_.topUv[x]);
  const TexelFrame frame = texelFrame(t0);
  const ShooterBounds shooters = shooterBounds(t0);
  makeTiles();
  const std::vector<char> covered = coveredTiles();
  std::vector<std::vector<uint32_t>> nearOfTile(tiles_.size());
  // Per tile, the near links of the nodes below its common one, with the texels they reach.
  std::vector<std::vector<std::pair<uint64_t, uint32_t>>> nearBelow(tiles_.size());
  tbb::parallel_for(size_t(0), tiles_.size(), [&](size_t ti) {
    sortTileLinks(ti, linksOf, leaf, frame, shooters, covered[ti] != 0, nearOfTile[ti],
                  nearBelow[ti]);
  });
  planCorners(frame, shooters.polygon);
  perTexelOnTiles(shooters.polygon, nearOfTile, nearBelow);
  for (const Tile& tile : tiles_) tileLinkCount_ += tile.links.size();
  listTexelLinks(nearOfTile, nearBelow);
  cacheTexelTerms(frame, shooters.polygon, cacheBytes);
}

// Receiver node -> its range of links_ (planLinks lists each node's links together).
GoodLinkGather::LinkRanges GoodLinkGather::linkRanges() const {
  LinkRanges linksOf;
  for (uint32_t j = 0; j < uint32_t(links_.size()); ++j) {
    auto [it, fresh] =
        linksOf.emplace(int(solution_.links[links_[j].row].receiver), std::make_pair(j, j + 1));
    if (!fresh) it->second.second = j + 1;
  }
  return linksOf;
}

GoodLinkGather::ShooterBounds GoodLinkGather::shooterBounds(double t) const {
  ShooterBounds s;
  s.polygon.resize(links_.size());
  s.centre.resize(links_.size());
  s.radius.assign(links_.size(), 0.0);
  for (size_t j = 0; j < links_.size(); ++j) {
    s.polygon[j] = linkWorld(links_[j], t);
    s.centre[j] = s.polygon[j].centroid();
    for (int k = 0; k < s.polygon[j].count; ++k)
      s.radius[j] = std::max(s.radius[j], glm::length(s.polygon[j].v[size_t(k)] - s.centre[j]));
  }
  return s;
}

void GoodLinkGather::makeTiles() {
  const int w = texels_.width, hgt = texels_.height;
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
}

// One tile's links: those of its common node's chain far enough go to the tile (all its
// texels), and those of the nodes below it far enough to the tile for the texels each node
// holds; the rest to nearOfTile (every texel) and nearBelow (the texels of the mask).
void GoodLinkGather::sortTileLinks(size_t ti, const LinkRanges& linksOf,
                                   const std::vector<int>& leaf, const TexelFrame& frame,
                                   const ShooterBounds& shooters, bool covered,
                                   std::vector<uint32_t>& nearOfTile,
                                   std::vector<std::pair<uint64_t, uint32_t>>& nearBelow) {
  const PatchHierarchy& h = solution_.hierarchy;
  const int w = texels_.width, hgt = texels_.height;
  auto linksAt = [&](int node, auto&& f) {
    auto it = linksOf.find(node);
    if (it != linksOf.end())
      for (uint32_t j = it->second.first; j < it->second.second; ++j) f(j);
  };
  Tile& tile = tiles_[ti];
  int common = leaf[size_t(tile.j0) * w + tile.i0];
  for (int j = tile.j0; j < std::min(tile.j0 + kTile, hgt); ++j)
    for (int i = tile.i0; i < std::min(tile.i0 + kTile, w); ++i)
      if (common >= 0) common = commonAncestor(h, common, leaf[size_t(j) * w + i]);
  tile.common = common;
  const std::array<size_t, 4> corner = tile.cornerTexels(w);
  glm::dvec3 p[4];
  double size = 0.0;
  for (int c = 0; c < 4; ++c) p[c] = frame.point(texels_.localPoint[corner[size_t(c)]]);
  for (int c = 0; c < 4; ++c) size = std::max(size, glm::length(p[c] - p[(c + 2) % 4]));
  // Far: the nearest corner farther from the shooter part than kTileFarRatio x size. Bounding
  // spheres decide most pairs without the four point-to-polygon distances.
  glm::dvec3 centre(0.0);
  for (int c = 0; c < 4; ++c) centre += 0.25 * p[c];
  double radius = 0.0;
  for (int c = 0; c < 4; ++c) radius = std::max(radius, glm::length(p[c] - centre));
  auto isFar = [&](uint32_t j, double ratio) {
    const double limit = ratio * size;
    const double dc = glm::length(centre - shooters.centre[j]);
    if (dc - radius - shooters.radius[j] > limit) return true;
    if (dc - radius <= limit) {  // some corner within limit of the shooter's centroid
      double nearest = std::numeric_limits<double>::infinity();
      for (int c = 0; c < 4; ++c)
        nearest = std::min(nearest, glm::length(p[c] - shooters.centre[j]));
      if (nearest <= limit) return false;
    }
    double d = std::numeric_limits<double>::infinity();
    for (int c = 0; c < 4; ++c) d = std::min(d, distanceToPolygon(p[c], shooters.polygon[j]));
    return d > limit;
  };
  // A covered corner sees nothing: interpolating its V would darken the exposed texels next
  // to a box's foot or around a lamp on the ceiling.
  auto toTile = [&](uint32_t j, double ratio) {
    return isFar(j, ratio) && !(links_[j].partial && covered);
  };
  forChain(h, common, -1, [&](int node) {
    linksAt(node, [&](uint32_t j) {
      if (toTile(j, kTileFarRatio))
        tile.links.push_back(j);
      else
        nearOfTile.push_back(j);
    });
  });
  if (!tile.links.empty()) tile.groups.emplace_back(~uint64_t(0), uint32_t(tile.links.size()));
  // The nodes below the common one, each with the tile's texels it holds: their far links
  // are interpolated over the tile too, for those texels (kTileFarRatioBelow). A texture
  // whose side is not a power of two has most tiles straddle two nodes, and per texel these
  // links cost most of its form factors.
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
        nearBelow.emplace_back(mask, j);
    });
  for (const auto& [mask, ids] : farByMask) {
    tile.links.insert(tile.links.end(), ids.begin(), ids.end());
    tile.groups.emplace_back(mask, uint32_t(tile.links.size()));
  }
}

// The far links at the tiles' corners, once per corner texel and link: a corner is shared by
// up to four tiles, which mostly interpolate the same links. Their form factors (links that
// do not move) and open rays past the static blockers are made here, the rest per key
// (gather), each once per corner and link, not once per tile.
void GoodLinkGather::planCorners(const TexelFrame& frame, const std::vector<Polygon>& shooter) {
  const int w = texels_.width;
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
    const glm::dvec3 p = frame.point(texels_.localPoint[x]);
    const glm::dvec3 nx = frame.normal(texels_.localNormal[x]);
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
}

// Per texel, in texel order: the near links of its chain below its tile's common node, then
// the tile's near links.
void GoodLinkGather::listTexelLinks(
    const std::vector<std::vector<uint32_t>>& nearOfTile,
    const std::vector<std::vector<std::pair<uint64_t, uint32_t>>>& nearBelow) {
  const int w = texels_.width, hgt = texels_.height;
  texelStart_.assign(texels_.topUv.size() + 1, 0);
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
}

// The texels' terms that do not change over the movie, when they fit in cacheBytes: the form
// factors of the links that do not move and, of the partial ones, the rays open past the
// static blockers; then, within what is left, their kernels (cacheTexelKernels).
void GoodLinkGather::cacheTexelTerms(const TexelFrame& frame, const std::vector<Polygon>& shooter,
                                     double cacheBytes) {
  const size_t T = texels_.topUv.size();
  bool anyFixed = false;  // partial links whose ends do not move: static rays cached
  for (const Link& l : links_) anyFixed = anyFixed || (l.partial && !l.moves);
  const double entryBytes = sizeof(float) + (anyFixed ? sizeof(uint64_t) : 0);
  cached_ = double(texelLinks_.size()) * entryBytes <= cacheBytes;
  if (!cached_) return;
  texelFormFactor_.resize(texelLinks_.size());
  if (anyFixed) texelOpen_.assign(texelLinks_.size(), 0);
  tbb::parallel_for(size_t(0), T, [&](size_t x) {
    const glm::dvec3 p = frame.point(texels_.localPoint[x]);
    const glm::dvec3 nx = frame.normal(texels_.localNormal[x]);
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
  cacheTexelKernels(frame, shooter, cacheBytes - double(texelLinks_.size()) * entryBytes);
}

// The kernels of the entries whose V is made per key (rays not all open, or moving blockers
// that may close them), when they fit in `left` bytes.
void GoodLinkGather::cacheTexelKernels(const TexelFrame& frame, const std::vector<Polygon>& shooter,
                                       double left) {
  const size_t T = texels_.topUv.size();
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
  if (double(kernels) * sizeof(double) + double(at.size()) * sizeof(uint32_t) > left ||
      kernels >= size_t(kNoKernels))
    return;
  texelKernelAt_.swap(at);
  texelKernel_.resize(kernels);
  tbb::parallel_for(size_t(0), T, [&](size_t x) {
    const glm::dvec3 p = frame.point(texels_.localPoint[x]);
    const glm::dvec3 nx = frame.normal(texels_.localNormal[x]);
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
// border on a small texture, is too dark inside. So its rays are
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

}  // namespace rad
