// The receiver index of the gather and the cluster light at the tops' corners (contract in
// good_links_by_receiver.h).
#include "libcommon/movies/good_links_by_receiver.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "libcommon/scene/planar_surfaces.h"

namespace rad {
namespace {

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

}  // namespace

GoodLinksByReceiver::GoodLinksByReceiver(const GlobalSolution& s) {
  indexByReceiver(
      s, [](const GlobalLink& l) { return !(l.flags & (kLinkBad | kLinkRefined)); }, start, rows);
  smoothClusterIrradiance(s);
  surfaceOfTop = planarSurfaceOfTops(s.hierarchy.tops());
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
        // uncovered neighbours: streaks along every light of a tiled ceiling.
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
// and its patch links' correspondingly less. Smoothed, such a top loses what its neighbours'
// patch links carry (dark streaks beside the lights of a tiled ceiling). So the top's corners
// are shifted, times its exposure (a mostly covered top's own value is noisy, see above), by
//   shift(d) = 0 for |d| <= band, d - band^2 / d beyond it,
// d = own - mean of its corners, band = kClusterBand * max(own, mean) (the non-negative
// garrote of wavelet shrinkage). Within the band (the spread of the cluster links' visibility
// estimates across a wall) the light stays continuous across shared edges; the shift is
// continuous in d (0 at |d| = band) so that a top crossing the band from one key to the next
// does not jump; and far beyond it the top keeps its own mean but for band^2 / |d|, which
// vanishes as |d| grows. Subtracting the whole band (soft thresholding) had cost a top far from
// its neighbours a tenth of its light: a sliver lit through cluster links among large
// tops lit through bad pairs (cluster light 0), whose corners' mean lies halfway to 0. The mean
// of the bilinear or barycentric interpolation over the top's (u,v) is its corners' mean, so
// the shift moves the top's mean by exactly shift (paper §3.1: the energy of good links is
// rendered with linear interpolation; the cluster links are the good ones here).
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
        shift[ch] = std::abs(d) > band ? d - band * band / d : 0.0;
      }
      for (int c = 0; c < count; ++c) corner[c] += glm::vec3(e * shift);
    }
  }
}

}  // namespace rad
