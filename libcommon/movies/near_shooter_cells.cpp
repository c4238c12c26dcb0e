// The near-shooter re-gather (contract and formula in near_shooter_cells.h): the cells' radiosity,
// made once per run, and what a gathered link's cell takes of its leaf's.
#include "libcommon/movies/near_shooter_cells.h"

#include <algorithm>
#include <chrono>

#include <tbb/parallel_for.h>

#include "libcommon/movies/good_link_gather.h"
#include "libcommon/movies/solid_contact.h"
#include "libcommon/radiosity/form_factor.h"

namespace rad {

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

Polygon cellPolygon(const Polygon& leaf, uint32_t cell) {
  Polygon p = leaf;
  for (int i = cellLevel(cell) - 1; i >= 0; --i)
    p = subdividePolygon(p)[size_t((cell >> (2 * i)) & 3u)];
  return p;
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
      if (!byReceiver_.nearShooters.cells.count(q * K + uint64_t(k))) missing.push_back(q);
    if (missing.empty()) continue;
    const double t = solution_.keyTimes[size_t(k)];
    if (visibility_->dynamicNodeCount() > 0) visibility_->setTime(t);
    std::vector<std::vector<float>> made(missing.size());
    std::vector<NearShooterStore::FixedTerms> fresh(missing.size());
    std::vector<const NearShooterStore::FixedTerms*> fixed(missing.size(), nullptr);
    for (size_t i = 0; i < missing.size(); ++i) {
      auto it = byReceiver_.nearShooters.fixed.find(missing[i]);
      if (it != byReceiver_.nearShooters.fixed.end()) fixed[i] = &it->second;
    }
    tbb::parallel_for(size_t(0), missing.size(), [&](size_t i) {
      made[i] = regatherCells(missing[i], k, t, fixed[i], fixed[i] ? nullptr : &fresh[i]);
    });
    for (size_t i = 0; i < missing.size(); ++i) {
      byReceiver_.nearShooters.cells[missing[i] * K + uint64_t(k)] = std::move(made[i]);
      if (!fixed[i] && !fresh[i].rows.empty())
        byReceiver_.nearShooters.fixed[missing[i]] = std::move(fresh[i]);
    }
    stats.nearShooterLeaves += long(missing.size());
  }
  stats.nearShooterSeconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// B at each cell centre of leaf q at key k (formula in good_link_gather.h), as a ratio to the
// leaf's B (channel sums): the colour stays the leaf's.
std::vector<float> GoodLinkGather::regatherCells(uint32_t q, int k, double t,
                                                 const NearShooterStore::FixedTerms* fixed,
                                                 NearShooterStore::FixedTerms* fresh) const {
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
  const std::vector<float>& r = byReceiver_.nearShooters.cells.at(l.shooter * K + uint64_t(key));
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

}  // namespace rad
