// The geometry of one movie as rad-movies' baker sees it (texture_movie_baker.cpp's MovieBake):
// the receiver and its texel points at every key, a bad pair's per-movie record (BadPair), its
// unoccluded form factors per texel, its shooter samples, shaft and blockers. Internal to the
// baker; one MovieGeometry per movie, used by one thread at a time (it caches each node's
// motion and world transform), while formFactorsAt runs its tiles in parallel.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <unordered_map>
#include <vector>

#include <tbb/parallel_for.h>
#include <glm/glm.hpp>

#include "libcommon/intervals/movie_extent.h"
#include "libcommon/movies/good_link_gather.h"
#include "libcommon/movies/transmittance.h"
#include "libcommon/radiosity/form_factor.h"
#include "libcommon/radiosity/hierarchical_radiosity.h"
#include "libcommon/radiosity/shaft.h"
#include "libcommon/scene/box_tree.h"
#include "libcommon/scene/scene.h"

namespace rad {

Polygon nodeWorldPolygon(const Scene& scene, const InputPolygon& top, PatchId node, double t);

// Grows b to hold polygon p's corners.
inline void growBoxTo(AxisBox& b, const Polygon& p) {
  for (int k = 0; k < p.count; ++k) growBox(b, p.v[k]);
}
inline AxisBox boxOf(const Polygon& p) {
  AxisBox b = emptyAxisBox();
  growBoxTo(b, p);
  return b;
}

inline void appendTriangles(const Polygon& p, std::vector<BlockerTriangle>& out) {
  for (int i = 1; i + 1 < p.count; ++i) out.push_back({p.v[0], p.v[i], p.v[i + 1]});
}

// Bad pairs' unoccluded form factors over tiles (MovieGeometry::formFactorsAt). At 4, twice
// the good layer's ratio for a tile's own links: these are mostly the lights' direct light.
inline constexpr int kFormFactorTile = 8;
inline constexpr double kFarFormFactorRatio = 4.0;

// A bad pair's per-movie data, computed before the first key (paper §5: what the coherence
// makes per-movie instead of per-key).
struct BadPair {
  uint32_t shooter = 0;
  bool coherent = false;
  std::vector<Polygon> shooterWorld;       // per key
  int samples = 0;                         // N
  std::vector<glm::dvec2> unitSamples;     // fixed in the shooter's frame
  std::vector<int> candidates;             // non-coherent: every possible blocker
  std::vector<int> dynamicList;            // coherent: moving blockers in the swept shaft
  std::vector<glm::dvec3> keyZeroSamples;  // coherent: the samples (the pair does not move)
  SampleMask valid = 0;                    // coherent
  std::vector<double> formFactor;          // coherent: F(x -> S), once per movie
  std::vector<SampleMask> staticMask;      // coherent: static blockers; empty = none (all 0)
  std::vector<long long> spilled;          // moving: key k's form factors in the spill, or -1
  double maxFormFactor = 0.0;              // over the texels and the keys scanned
  double share = 1.0;  // the largest share of a texel's direct light its light gives
                       // (directShares)
  // A subdivided shooter: the union leaf under each sample, whose radiosity over the shooter's
  // mean weights the sample (shapedTransmittance); empty: the shooter is one leaf.
  std::vector<int> sampleLeaf;
  std::vector<int> leaves;  // its union leaves (the near texels' exact shape)
};

// A subdivided bad shooter's radiosity over its mean at one key (MovieBake::shapeAt): per
// shadow sample, the union leaf's under it (shapedTransmittance), and for the texels nearer than
// the samples' spacing the leaves themselves, in the world at the key whose geometry the masks
// use. Empty: the shooter is taken as uniform.
struct ShooterShape {
  std::vector<glm::vec3> sample;  // per sample, per channel
  Polygon shooter;
  double nearDistance = 0.0;
  std::vector<Polygon> leafWorld;
  std::vector<glm::dvec3> leafShape;
  bool empty() const { return sample.empty(); }
};

// The receiver of one movie at its key times, and what the blocker tests ask of the scene
// over the movie (each node's answer computed once).
class MovieGeometry {
 public:
  MovieGeometry(const Scene& scene, const std::vector<InputPolygon>& tops, const MovieExtent& req,
                const std::vector<double>& keyTimes)
      : scene_(scene),
        tops_(tops),
        receiverTop_(tops[req.patch.top]),
        keyTimes_(keyTimes),
        w_(req.width),
        h_(req.height),
        t0_(keyTimes.front()),
        t1_(keyTimes.back()),
        nodeMoves_(scene.nodes.size(), -1) {
    texelPoints(req.patch);
    receiverDynamic_ = movesDuringMovie(receiverTop_.node);
    const size_t K = keyTimes_.size();
    receiverWorld_.resize(K);
    receiverTransform_.resize(K);
    receiverNormalMap_.resize(K);
    for (size_t k = 0; k < K; ++k) {
      receiverTransform_[k] = scene_.worldTransform(receiverTop_.node, keyTimes_[k]);
      receiverNormalMap_[k] = glm::transpose(glm::inverse(glm::dmat3(receiverTransform_[k])));
      receiverWorld_[k] = nodeWorldPolygon(scene_, receiverTop_, req.patch, keyTimes_[k]);
    }
  }

  int width() const { return w_; }
  int height() const { return h_; }
  size_t texels() const { return size_t(w_) * h_; }
  int keys() const { return int(keyTimes_.size()); }
  double keyTime(int k) const { return keyTimes_[size_t(k)]; }
  const Scene& scene() const { return scene_; }
  const glm::dvec2& topUv(size_t x) const { return topUv_[x]; }
  MovieTexels texelPoints() const { return {topUv_, localPoint_, localNormal_, w_, h_}; }
  const Polygon& receiverWorld(int k) const { return receiverWorld_[size_t(k)]; }
  bool receiverDynamic() const { return receiverDynamic_; }

  // Whether a node moves during the movie, and its swept bounds, are asked for every blocker
  // candidate of every bad pair, with the same answers for a scene of many moving nodes; each
  // node's answer over [t0, t1] is computed once.
  bool movesDuringMovie(int node) {
    if (node < 0 || node >= int(nodeMoves_.size())) return scene_.isDynamic(node, t0_, t1_);
    signed char& m = nodeMoves_[size_t(node)];
    if (m < 0) m = scene_.isDynamic(node, t0_, t1_) ? 1 : 0;
    return m == 1;
  }
  const std::array<glm::dvec3, 2>& sweptDuringMovie(int node) {
    auto it = nodeSwept_.find(node);
    if (it == nodeSwept_.end())
      it = nodeSwept_.emplace(node, scene_.sweptBounds(node, t0_, t1_)).first;
    return it->second;
  }

  // Unoccluded form factors F(x -> S) per texel at key k, about the texel's shading normal.
  // Texels in tiles of kFormFactorTile x kFormFactorTile: where every corner of a tile is farther
  // from the shooter than kFarFormFactorRatio times the tile's diagonal, F is evaluated at the
  // corners (texel centres shared with the neighbouring tiles) and interpolated bilinearly over
  // the tile, as the good layer's far links are (GoodLinkGather::planTexels), but as its ratio
  // to the point kernel (below), which varies far more slowly than F itself
  // (TextureMovieBaker.AFarLightsFormFactorIsInterpolatedOverTilesOfTexels). The shadow stays
  // per texel: only the smooth unoccluded factor is interpolated. Why: most movies of a large
  // scene are small textures under lights metres away, where F per texel costs much and varies
  // little. Returns how many texels were interpolated.
  size_t formFactorsAt(const BadPair& p, int k, std::vector<double>& f) const {
    f.resize(texels());
    const Polygon& sw = p.shooterWorld[size_t(k)];
    auto exact = [&](size_t x) {
      return pointToPolygonFormFactor(texelPoint(k, x), texelNormal(k, x), sw);
    };
    const int tilesX = (w_ + kFormFactorTile - 1) / kFormFactorTile;
    const int tilesY = (h_ + kFormFactorTile - 1) / kFormFactorTile;
    std::atomic<size_t> interpolated{0};
    tbb::parallel_for(0, tilesX * tilesY, [&](int ti) {
      const int i0 = (ti % tilesX) * kFormFactorTile, j0 = (ti / tilesX) * kFormFactorTile;
      const int iEnd = std::min(i0 + kFormFactorTile, w_),
                jEnd = std::min(j0 + kFormFactorTile, h_);
      const int i1 = std::min(i0 + kFormFactorTile, w_ - 1),
                j1 = std::min(j0 + kFormFactorTile, h_ - 1);
      const std::array<size_t, 4> corner = {size_t(j0) * w_ + i0, size_t(j0) * w_ + i1,
                                            size_t(j1) * w_ + i0, size_t(j1) * w_ + i1};
      bool far = i1 > i0 && j1 > j0;
      if (far) {
        std::array<glm::dvec3, 4> c;
        for (int q = 0; q < 4; ++q) c[size_t(q)] = texelPoint(k, corner[size_t(q)]);
        const double size = std::max(glm::length(c[3] - c[0]), glm::length(c[2] - c[1]));
        for (int q = 0; q < 4 && far; ++q)
          far = distanceToPolygon(c[size_t(q)], sw) > kFarFormFactorRatio * size;
      }
      if (!far) {
        for (int j = j0; j < jEnd; ++j)
          for (int i = i0; i < iEnd; ++i) f[size_t(j) * w_ + i] = exact(size_t(j) * w_ + i);
        return;
      }
      // What is interpolated is F over the point kernel max(0, n.d) max(0, -n_S.d) / |d|^4
      // (d from the texel to the shooter's centroid), which varies far more slowly than F: F's
      // fall-off and both cosines are the kernel's, evaluated per texel. Where the kernel is 0
      // at a corner (the shooter across a horizon), F itself.
      const glm::dvec3 centre = sw.centroid(), shooterNormal = sw.normal();
      auto kernel = [&](size_t x) {
        const glm::dvec3 d = centre - texelPoint(k, x);
        const double r2 = glm::dot(d, d);
        return std::max(0.0, glm::dot(texelNormal(k, x), d)) *
               std::max(0.0, -glm::dot(shooterNormal, d)) / (r2 * r2);
      };
      std::array<double, 4> fc, kc;
      bool ratio = true;
      for (int q = 0; q < 4; ++q) {
        fc[size_t(q)] = exact(corner[size_t(q)]);
        kc[size_t(q)] = kernel(corner[size_t(q)]);
        ratio = ratio && kc[size_t(q)] > 0.0;
      }
      if (ratio)
        for (int q = 0; q < 4; ++q) fc[size_t(q)] /= kc[size_t(q)];
      interpolated += size_t(jEnd - j0) * size_t(iEnd - i0);
      for (int j = j0; j < jEnd; ++j) {
        const double v = double(j - j0) / double(j1 - j0);
        for (int i = i0; i < iEnd; ++i) {
          const double u = double(i - i0) / double(i1 - i0);
          const size_t x = size_t(j) * w_ + i;
          const double b =
              (1.0 - v) * ((1.0 - u) * fc[0] + u * fc[1]) + v * ((1.0 - u) * fc[2] + u * fc[3]);
          f[x] = ratio ? b * kernel(x) : b;
        }
      }
    });
    return interpolated;
  }
  glm::dvec3 texelPoint(int k, size_t x) const {
    return glm::dvec3(receiverTransform_[size_t(k)] * glm::dvec4(localPoint_[x], 1.0));
  }
  glm::dvec3 texelNormal(int k, size_t x) const {
    return glm::normalize(receiverNormalMap_[size_t(k)] * localNormal_[x]);
  }
  // The texel's transmittance at key k from its occluded samples (kernelWeightedTransmittance).
  double texelTransmittance(int k, size_t x, const std::vector<glm::dvec3>& samples,
                            const glm::dvec3& shooterNormal, SampleMask occluded,
                            SampleMask valid) const {
    const SampleMask open = valid & ~occluded;
    if (open == valid) return 1.0;  // most texels: no point or normal needed
    if (open == 0) return 0.0;
    return kernelWeightedTransmittance(texelPoint(k, x), texelNormal(k, x), samples, shooterNormal,
                                       occluded, valid);
  }
  // A subdivided shooter's shaped transmittance at texel x (shapedTransmittance). Near the shooter
  // (nearer than its samples' spacing) the samples' kernel peaks within one of them, and their
  // quadrature of the shooter's radiosity does not hold (a Cornell-box wall's leaves beside the
  // corner it shares with the receiver): there the shape is the leaves' own point form factors,
  //   sum_l beta_l F(x -> l) / F(x -> S),
  // times the kernel-weighted transmittance.
  glm::dvec3 shapedTransmittanceAt(int k, size_t x, const std::vector<glm::dvec3>& samples,
                                   const glm::dvec3& shooterNormal, SampleMask occluded,
                                   SampleMask valid, const ShooterShape& shape) const {
    const glm::dvec3 pt = texelPoint(k, x), n = texelNormal(k, x);
    if (!shape.leafWorld.empty() && distanceToPolygon(pt, shape.shooter) < shape.nearDistance) {
      const double T = kernelWeightedTransmittance(pt, n, samples, shooterNormal, occluded, valid);
      const double whole = pointToPolygonFormFactor(pt, n, shape.shooter);
      if (T == 0.0 || !(whole > 0.0)) return glm::dvec3(T);
      glm::dvec3 shaped(0.0);
      for (size_t l = 0; l < shape.leafWorld.size(); ++l)
        shaped += shape.leafShape[l] * pointToPolygonFormFactor(pt, n, shape.leafWorld[l]);
      return T * shaped / whole;
    }
    return shapedTransmittance(pt, n, samples, shooterNormal, occluded, valid, shape.sample);
  }

  std::vector<glm::dvec3> samplesAt(const BadPair& p, int k) const {
    std::vector<glm::dvec3> s(static_cast<size_t>(p.samples));
    for (int i = 0; i < p.samples; ++i)
      s[size_t(i)] = samplePointOnPolygon(p.shooterWorld[size_t(k)], p.unitSamples[size_t(i)]);
    return s;
  }
  AxisBox shaftAt(const BadPair& p, int k) const {
    AxisBox box = emptyAxisBox();
    growBoxTo(box, receiverWorld_[size_t(k)]);
    growBoxTo(box, p.shooterWorld[size_t(k)]);
    return box;
  }
  // The convex hull of the shooter and the receiver's texture domain (a triangle's (u,v) square
  // is the parallelogram v0, v1, v1 + v2 - v0, v2): every segment from a shooter sample to a
  // texel centre lies in it, so a blocker whose box misses it covers no texel, and culling it
  // changes no mask. The box shaft alone kept, on the 10k-triangle hall, every table and chair
  // in the box spanned by a floor patch and a ceiling light.
  Shaft hullAt(const BadPair& p, int k) const {
    Polygon domain = receiverWorld_[size_t(k)];
    if (domain.count == 3) {
      domain.v[3] = domain.v[2];
      domain.v[2] = domain.v[1] + domain.v[3] - domain.v[0];
      domain.count = 4;
    }
    return Shaft(domain, p.shooterWorld[size_t(k)]);
  }
  // World polygon of top-level patch b at key k. The node's world transform is computed once
  // per movie and key: the blockers of every pair at every key are placed with it, several
  // polygons per node.
  Polygon worldPolygon(int b, int k) {
    const int node = tops_[size_t(b)].node;
    const long long key = (long long)k * (long long)(scene_.nodes.size() + 1) + (node + 1);
    auto it = nodeWorldAtKey_.find(key);
    if (it == nodeWorldAtKey_.end())
      it = nodeWorldAtKey_.emplace(key, scene_.worldTransform(node, keyTimes_[size_t(k)])).first;
    return tops_[size_t(b)].local.transformed(it->second);
  }
  // Blockers of candidate list `list` in the pair's shaft at key k, as world triangles.
  std::vector<BlockerTriangle> blockersAt(const BadPair& p, const std::vector<int>& list, int k) {
    const AxisBox shaft = shaftAt(p, k);
    const Shaft hull = hullAt(p, k);
    std::vector<BlockerTriangle> tris;
    for (int b : list) {
      Polygon poly = worldPolygon(b, k);
      const AxisBox pb = boxOf(poly);
      if (boxesMeet(pb, shaft) && hull.meets(pb[0], pb[1])) appendTriangles(poly, tris);
    }
    return tris;
  }

 private:
  // Texel centres: node (u,v) -> top (u,v) -> local point.
  void texelPoints(PatchId patch) {
    const bool triangle = receiverTop_.local.count == 3;
    topUv_.resize(texels());
    localPoint_.resize(texels());
    localNormal_.resize(texels());
    for (int j = 0; j < h_; ++j)
      for (int i = 0; i < w_; ++i) {
        size_t x = size_t(j) * w_ + i;
        topUv_[x] = topUvFromNodeUv(patch, {(i + 0.5) / w_, (j + 0.5) / h_}, triangle);
        localPoint_[x] = polygonPointAt(receiverTop_.local, topUv_[x]);
        localNormal_[x] = shadingNormalAt(receiverTop_, topUv_[x]);
      }
  }

  const Scene& scene_;
  const std::vector<InputPolygon>& tops_;
  const InputPolygon& receiverTop_;
  const std::vector<double>& keyTimes_;
  const int w_, h_;
  const double t0_, t1_;
  std::vector<glm::dvec2> topUv_;
  std::vector<glm::dvec3> localPoint_, localNormal_;  // texel centres and shading normals
  std::vector<signed char> nodeMoves_;
  std::unordered_map<int, std::array<glm::dvec3, 2>> nodeSwept_;
  bool receiverDynamic_ = false;
  std::vector<Polygon> receiverWorld_;
  std::vector<glm::dmat4> receiverTransform_;
  std::vector<glm::dmat3> receiverNormalMap_;  // of the shading normals, per key
  std::unordered_map<long long, glm::dmat4> nodeWorldAtKey_;
};

}  // namespace rad
