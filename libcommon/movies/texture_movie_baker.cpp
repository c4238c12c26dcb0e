// Texture-movie baking (paper §3.1 and §5). Sources and the formula in texture_movie_baker.h.
//
// One movie is baked in two parts (MovieBake below):
//  * planning, once per movie (MovieBake::plan): the texel points and the receiver at every
//    key (MovieGeometry), then per bad pair its shooter, its form factors (once for a static
//    pair; a moving pair's are scanned for their largest value and spilled), its samples and
//    its blockers: a static pair's static blockers are rendered once into a sample mask, its
//    dynamic ones listed for the keys (§5);
//  * baking, key by key (MovieBake::bakeKey): the good layer, then per pair in badShooters
//    order the key's occlusion mask (OcclusionMaskRenderer), merged with the static mask
//    (mergeOcclusion), times B_S F added to the irradiance (combine), and the clamped key
//    texture handed to the sink.
#include "libcommon/movies/texture_movie_baker.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "libcommon/core/error.h"
#include "libcommon/core/stopwatch.h"
#include "libcommon/movies/good_layer_keys.h"
#include "libcommon/movies/lamp_direct_term.h"
#include "libcommon/movies/movie_geometry.h"
#include "libcommon/movies/ray_cast_masks.h"
#include "libcommon/movies/solid_contact.h"
#include "libcommon/movies/triangle_texels.h"
#include "libcommon/radiosity/form_factor.h"
#include "libcommon/radiosity/shaft.h"
#include "libcommon/scene/box_tree.h"
#include "libcommon/scene/frame_range.h"
#include "libcommon/scene/planar_surfaces.h"

namespace rad {
namespace {

// The reversed copy a doubleSided material adds is the same surface: never its own blocker.
bool sameSurface(const InputPolygon& a, const InputPolygon& b) {
  if (a.node != b.node || a.local.count != b.local.count) return false;
  for (int i = 0; i < a.local.count; ++i) {
    bool found = false;
    for (int j = 0; j < b.local.count && !found; ++j) found = a.local.v[i] == b.local.v[j];
    if (!found) return false;
  }
  return true;
}

uint32_t mix32(uint64_t x) {
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdull;
  x ^= x >> 33;
  x *= 0xc4ceb9fe1a85ec53ull;
  x ^= x >> 33;
  return uint32_t(x);
}

template <class F>
void parallelRows(int height, F&& body) {
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& r) {
    for (int j = r.begin(); j != r.end(); ++j) body(j);
  });
}

// Merge (paper §5): a coherent pair's transmittance at one key from its static-blocker mask
// (empty: no static blocker) and the key's dynamic-blocker mask. kExact ORs the masks (the
// same bits as rendering all blockers together) and weights the open samples by the texel's
// kernel (`exact(x, occluded)`, kernelWeightedTransmittance); the others merge the two
// popcount transmittances.
template <class Exact>
void mergeOcclusion(MergeMode merge, const std::vector<SampleMask>& staticMask,
                    const std::vector<SampleMask>& keyMask, SampleMask valid, Exact&& exact,
                    std::vector<float>& transmittance) {
  const size_t texels = transmittance.size();
  const bool noStatic = staticMask.empty();
  if (merge == MergeMode::kExact) {
    tbb::parallel_for(size_t(0), texels, [&](size_t x) {
      transmittance[x] = float(exact(x, (noStatic ? SampleMask(0) : staticMask[x]) | keyMask[x]));
    });
  } else {
    for (size_t x = 0; x < texels; ++x)
      transmittance[x] = float(mergeTransmittance(
          merge, transmittanceFromMask(noStatic ? SampleMask(0) : staticMask[x], valid),
          transmittanceFromMask(keyMask[x], valid)));
  }
}

}  // namespace

// Where a pair's blocker candidates come from: the top-level patches of nodes that never move,
// in a box tree of their world bounds, and the few of nodes that move somewhere in the
// animation, in a list. Why: scanning every top for every pair costs pairs x tops placements
// and shaft tests, which grows as the square of the scene.
struct BlockerIndex {
  BoxTree fixedTops;
  std::vector<int> movableTops;  // ascending

  BlockerIndex(const Scene& scene, const std::vector<InputPolygon>& tops) {
    std::vector<AxisBox> boxes(tops.size(), AxisBox{glm::dvec3(1.0), glm::dvec3(-1.0)});
    std::unordered_map<int, glm::dmat4> world;
    for (size_t b = 0; b < tops.size(); ++b) {
      const int node = tops[b].node;
      if (scene.isDynamic(node, scene.startTime(), scene.endTime())) {
        movableTops.push_back(int(b));
        continue;
      }
      auto it = world.find(node);
      if (it == world.end())
        it = world.emplace(node, scene.worldTransform(node, scene.startTime())).first;
      boxes[b] = boxOf(tops[b].local.transformed(it->second));
    }
    fixedTops = BoxTree(boxes);
  }

  // Every top whose box may meet [lo, hi], ascending.
  std::vector<int> near(const glm::dvec3& lo, const glm::dvec3& hi) const {
    std::vector<int> out;
    fixedTops.query(lo, hi, out);
    const size_t fixed = out.size();
    out.insert(out.end(), movableTops.begin(), movableTops.end());
    std::inplace_merge(out.begin(), out.begin() + long(fixed), out.end());
    return out;
  }
};

namespace {

// One movie's bake: plan() once, then bakeKey(k) for k = 0 .. K-1.
class MovieBake {
 public:
  MovieBake(const GlobalSolution& solution, const std::vector<InputPolygon>& tops,
            const SceneEmitters& emitters, const TextureMovieBakerOptions& options,
            TextureMovieBakerStats& stats, const std::function<OcclusionMaskRenderer&()>& renderer,
            FormFactorSpill& spill, const MovieExtent& req, MovieGeometry& geometry,
            GoodLayerKeys* gather, SceneVisibility* visibility, const BlockerIndex& blockers,
            uint32_t surface)
      : solution_(solution),
        tops_(tops),
        emitters_(emitters),
        blockers_(blockers),
        options_(options),
        stats_(stats),
        renderer_(renderer),
        spill_(spill),
        req_(req),
        geo_(geometry),
        gather_(gather),
        visibility_(visibility),
        surface_(surface),
        texels_(geometry.texels()),
        acc_(texels_),
        transmittance_(texels_),
        texture_(texels_ * 3) {
    if (tops_[req_.patch.top].local.count == 3) {
      const int w = geo_.width(), h = geo_.height();
      beyond_.resize(texels_);
      for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) beyond_[size_t(j) * w + i] = texelBeyondTriangle(i, j, w, h);
    }
    if (!emitters.lamps().empty() && visibility)
      lamps_ = std::make_unique<LampDirectTerm>(emitters, geometry, *visibility, req.patch.top);
  }

  // Texels under a touching solid at key k (a box's foot on the floor, solid_contact.h) are
  // never seen, and gather nothing: ~0. A pixel between such a texel's centre and an exposed
  // one's (the floor just beside the box) interpolates the two and comes out far too dark. Each
  // covered texel next to an exposed one takes the mean of its exposed 8-neighbours, twice
  // outwards (lightmap dilation), so that the bilinear lookup meets exposed values only. Static
  // blockers are tested once per movie, moving ones at each key where their swept bounds meet
  // the receiver.
  void fillCoveredTexels(int k, double t) {
    auto clock = SteadyClock::now();
    const double size = polygonSize(geo_.receiverWorld(k));
    if (staticCovered_.empty() || geo_.receiverDynamic()) coverStaticTexels(k, t, size);
    covered_ = staticCovered_;
    if (!movingNear_.empty() && visibility_->dynamicNodeCount() > 0) {
      std::vector<AxisBox> now;
      for (int node : movingNear_) {
        const auto b = geo_.scene().sweptBounds(node, t, t);
        const glm::dvec3 pad(1e-9 * std::max(size, glm::length(b[1] - b[0])));
        now.push_back(AxisBox{b[0] - pad, b[1] + pad});
      }
      visibility_->setTime(t);
      coverTexels(visibility_->movingPart(), k, t, size, covered_, &now);
    }
    stats_.coveredTexelsFilled += fillFromExposedNeighbours();
    stats_.secondsCombine += secondsSince(clock);
  }

 private:
  // Whether texel point p (normal n) of the receiver lies inside a solid of `blockers` at time
  // `at` (insideSolid: the four rays 88 degrees from the normal, so that a gap between the
  // solid and the surface lets them out, and the texels under an open tube closed by a top
  // are covered as those under a box are).
  bool solidAt(const VisibilityScene& blockers, double at, double size, const glm::dvec3& p,
               const glm::dvec3& n) const {
    return insideSolid(blockers, geo_.scene(), solution_.hierarchy, req_.patch.top, p, n, size, at);
  }

  // Marks in `covered` the texels at key k inside a solid of `blockers` at time `at`, then those
  // near a solid's edge (coverNearEdges). `inside`: when given, only texels inside one of these
  // boxes can be covered (the moving nodes' bounds at t: a texel under a moving box lies in the
  // box's bounds).
  void coverTexels(const VisibilityScene& blockers, int k, double at, double size,
                   std::vector<char>& covered, const std::vector<AxisBox>* inside) {
    const std::vector<char> before = covered;
    tbb::parallel_for(size_t(0), texels_, [&](size_t x) {
      if (covered[x]) return;
      if (inside && std::none_of(inside->begin(), inside->end(), [&](const AxisBox& b) {
            return boxHolds(b, geo_.texelPoint(k, x));
          }))
        return;
      const glm::dvec3 p = geo_.texelPoint(k, x), n = geo_.texelNormal(k, x);
      if (solidAt(blockers, at, size, p, n)) covered[x] = 1;
    });
    coverNearEdges(blockers, k, at, size, covered, before);
  }

  // A texel whose centre lies within a quarter texel outside a solid's foot (a partition
  // standing on a texel row, a texel centre a fraction of a millimetre from the wall) is covered
  // too: its own gather meets the foot's edge, where the occlusion masks' rasterization decides
  // the light either way (a dashed dark line along the wall), while its exposed neighbours'
  // mean is its value to a quarter texel. Tested where a 4-neighbour was covered by this pass
  // (covered and not `before`): the centre moved a quarter of the way towards that neighbour.
  void coverNearEdges(const VisibilityScene& blockers, int k, double at, double size,
                      std::vector<char>& covered, const std::vector<char>& before) {
    const int w = geo_.width(), h = geo_.height();
    std::vector<char> add(texels_, 0);
    tbb::parallel_for(0, h, [&](int j) {
      for (int i = 0; i < w; ++i) {
        const size_t x = size_t(j) * w + i;
        if (covered[x]) continue;
        const int di[4] = {-1, 1, 0, 0}, dj[4] = {0, 0, -1, 1};
        for (int e = 0; e < 4; ++e) {
          const int a = i + di[e], b = j + dj[e];
          if (a < 0 || b < 0 || a >= w || b >= h) continue;
          const size_t y = size_t(b) * w + a;
          if (!covered[y] || before[y]) continue;
          const glm::dvec3 p = geo_.texelPoint(k, x);
          if (solidAt(blockers, at, size, p + 0.25 * (geo_.texelPoint(k, y) - p),
                      geo_.texelNormal(k, x))) {
            add[x] = 1;
            break;
          }
        }
      }
    });
    for (size_t x = 0; x < texels_; ++x) covered[x] |= add[x];
  }

  // The texels covered by static solids (staticCovered_; once per movie unless the receiver
  // moves) and the moving nodes whose bounds over the movie meet the receiver (movingNear_).
  void coverStaticTexels(int k, double t, double size) {
    staticCovered_.assign(texels_, 0);
    coverTexels(visibility_->staticPart(), k, t, size, staticCovered_, nullptr);
    const AxisBox box = boxOf(geo_.receiverWorld(k));
    movingNear_.clear();
    for (int node : movingNodesOf(geo_.scene(), tops_, solution_.keyTimes.front(),
                                  solution_.keyTimes.back())) {
      const auto b = geo_.scene().sweptBounds(node, geo_.keyTime(0), geo_.keyTime(geo_.keys() - 1));
      if (boxesMeet(box, AxisBox{b[0], b[1]})) movingNear_.push_back(node);
    }
  }

  // Each covered texel (covered_) next to an exposed one takes the mean of its exposed
  // 8-neighbours in texture_, in two rings outwards. Returns how many were filled.
  long fillFromExposedNeighbours() {
    const int w = geo_.width(), h = geo_.height();
    std::vector<char> exposed(texels_);
    // The texels beyond a triangle are neither read nor filled here (extendBeyondTriangle).
    for (size_t x = 0; x < texels_; ++x) exposed[x] = covered_[x] || beyond(x) ? 0 : 1;
    long filled = 0;
    for (int ring = 0; ring < 2; ++ring) {
      std::vector<char> next = exposed;
      for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
          const size_t x = size_t(j) * w + i;
          if (exposed[x] || beyond(x)) continue;
          float sum[3] = {0, 0, 0};
          int n = 0;
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
              const int a = i + di, b = j + dj;
              if (a < 0 || b < 0 || a >= w || b >= h || !exposed[size_t(b) * w + a]) continue;
              for (int c = 0; c < 3; ++c) sum[c] += texture_[3 * (size_t(b) * w + a) + size_t(c)];
              ++n;
            }
          if (n == 0) continue;
          for (int c = 0; c < 3; ++c) texture_[3 * x + size_t(c)] = sum[c] / float(n);
          next[x] = 1;
          ++filled;
        }
      exposed.swap(next);
    }
    return filled;
  }

 public:
  // Planning: the per-movie part of every bad pair, in badShooters order.
  void plan(const std::vector<uint32_t>& badShooters) {
    saturatedSamples_ = transmittanceSampleCount(std::numeric_limits<double>::infinity(),
                                                 options_.samplesPerFormFactor, options_.minSamples,
                                                 options_.maxSamples);
    // Every pair's form factors first: a pair's share of the direct light needs them all.
    for (uint32_t S : badShooters) {
      BadPair p;
      if (scanPair(S, p)) pairs_.push_back(std::move(p));
    }
    directShares();
    for (BadPair& p : pairs_) planPair(p);
  }

  // Key k: H = G + sum over the pairs, in badShooters order, of B_S F T (the same arithmetic
  // and per-texel order as accumulating pair by pair over all keys), into the sink.
  void bakeKey(int k, double t, BakedKeySink& sink) {
    goodLayer(t);
    for (const BadPair& p : pairs_) {
      OcclusionMaskRenderer& gl = renderer_();
      shapeAt(p, p.coherent ? 0 : k, t);
      const std::vector<double>& f =
          p.coherent ? coherentTransmittance(gl, p, k) : movingTransmittance(gl, p, k);
      combine(p, t, f);
    }
    auto clock = SteadyClock::now();
    if (lamps_) lamps_->add(k, t, acc_);  // the punctual lamps' direct light, per texel
    for (size_t x = 0; x < texels_; ++x)
      for (int c = 0; c < 3; ++c) {
        double v = acc_[x][c];
        // Irradiance is never negative or NaN (docs/design.md §9); clamp rounding only.
        texture_[3 * x + size_t(c)] = std::isfinite(v) ? float(std::max(v, 0.0)) : 0.0f;
      }
    stats_.secondsCombine += secondsSince(clock);
    if (options_.fillCovered && visibility_) fillCoveredTexels(k, t);
    if (!beyond_.empty()) extendBeyondTriangle(texture_, geo_.width(), geo_.height());
    sink.key(size_t(k), texture_);
  }

 private:
  // Counts one formFactorsAt call's texels (`interpolated` of them from a tile's corners).
  void countFormFactors(size_t interpolated) {
    stats_.formFactorTexels += long(texels_);
    stats_.formFactorTexelsInterpolated += long(interpolated);
  }
  // Key 0's form factors of a pair: a coherent pair's own, a moving pair's from the spill (its
  // scan put them there first) or recomputed, into `scratch`.
  const std::vector<double>& keyZeroFormFactors(const BadPair& p, std::vector<double>& scratch) {
    if (p.coherent) return p.formFactor;
    scratch.resize(texels_);
    if (!spill_.get(p.spilled[0], scratch)) countFormFactors(geo_.formFactorsAt(p, 0, scratch));
    return scratch;
  }
  bool scanPair(uint32_t S, BadPair& p);
  void directShares();
  void planPair(BadPair& p);
  double scanFormFactors(BadPair& p);
  std::vector<int> blockerCandidates(uint32_t S, const BadPair& p);
  void planCoherentBlockers(BadPair& p, const std::vector<int>& candidates);

  // Good layer: gathered per texel over the good links, or (paper §3.1) Gouraud over the patch
  // from the global solution. Both carry the top's cluster light (topClusterIrradiance): the
  // gather adds it, the Gouraud vertex values hold it already.
  void goodLayer(double t) {
    auto clock = SteadyClock::now();
    if (gather_) {
      gather_->at(t, acc_);
      stats_.secondsGood += secondsSince(clock);
      return;
    }
    const int R = int(req_.patch.top), w = geo_.width();
    parallelRows(geo_.height(), [&](int j) {
      for (int i = 0; i < w; ++i) {
        size_t x = size_t(j) * w + i;
        acc_[x] = solution_.goodIrradiance(R, geo_.topUv(x), t);
      }
    });
    stats_.secondsGood += secondsSince(clock);
  }

  // A static pair at key k: its dynamic blockers rendered from the movie's samples, merged
  // with the static mask. Returns the pair's form factors (once per movie).
  const std::vector<double>& coherentTransmittance(OcclusionMaskRenderer& gl, const BadPair& p,
                                                   int k) {
    auto clock = SteadyClock::now();
    std::vector<BlockerTriangle> dynamicTris = p.dynamicList.empty()
                                                   ? std::vector<BlockerTriangle>()
                                                   : geo_.blockersAt(p, p.dynamicList, k);
    gl.render(geo_.receiverWorld(0), geo_.width(), geo_.height(), p.keyZeroSamples, dynamicTris,
              keyMask_);
    const glm::dvec3 shooterNormal = p.shooterWorld[0].normal();
    if (!shape_.empty()) {  // exact merge only (shapeAt)
      tbb::parallel_for(size_t(0), texels_, [&](size_t x) {
        const SampleMask occluded =
            (p.staticMask.empty() ? SampleMask(0) : p.staticMask[x]) | keyMask_[x];
        shapedTransmittance_[x] = geo_.shapedTransmittanceAt(0, x, p.keyZeroSamples, shooterNormal,
                                                             occluded, p.valid, shape_);
      });
      stats_.secondsTransmittance += secondsSince(clock);
      return p.formFactor;
    }
    mergeOcclusion(
        options_.merge, p.staticMask, keyMask_, p.valid,
        [&](size_t x, SampleMask occluded) {
          return geo_.texelTransmittance(0, x, p.keyZeroSamples, shooterNormal, occluded, p.valid);
        },
        transmittance_);
    stats_.secondsTransmittance += secondsSince(clock);
    return p.formFactor;
  }

  // A moving pair (or the baseline) at key k: every blocker in the key's shaft rendered from
  // the key's samples; the key's form factors read back from the spill or recomputed.
  const std::vector<double>& movingTransmittance(OcclusionMaskRenderer& gl, const BadPair& p,
                                                 int k) {
    auto clock = SteadyClock::now();
    const std::vector<glm::dvec3> samples = geo_.samplesAt(p, k);
    const SampleMask valid = frontSampleMask(geo_.receiverWorld(k), samples);
    gl.render(geo_.receiverWorld(k), geo_.width(), geo_.height(), samples,
              geo_.blockersAt(p, p.candidates, k), keyMask_);
    const glm::dvec3 shooterNormal = p.shooterWorld[size_t(k)].normal();
    tbb::parallel_for(size_t(0), texels_, [&](size_t x) {
      if (!shape_.empty())
        shapedTransmittance_[x] =
            geo_.shapedTransmittanceAt(k, x, samples, shooterNormal, keyMask_[x], valid, shape_);
      else
        transmittance_[x] =
            float(geo_.texelTransmittance(k, x, samples, shooterNormal, keyMask_[x], valid));
    });
    stats_.secondsTransmittance += secondsSince(clock);
    clock = SteadyClock::now();
    keyFormFactor_.resize(texels_);
    if (!spill_.get(p.spilled[size_t(k)], keyFormFactor_))
      countFormFactors(geo_.formFactorsAt(p, k, keyFormFactor_));
    stats_.secondsFormFactor += secondsSince(clock);
    return keyFormFactor_;
  }

  // The shape of a subdivided shooter at time t into shape_, per channel (colour bleeds unevenly
  // over a wall: the back wall's part beside the red wall is redder). Empty: a light or a leaf
  // (planPair), uniform within 1e-3, or an approximate --merge (popcount transmittances only).
  void shapeAt(const BadPair& p, int geometryKey, double t) {
    shape_.sample.clear();
    shape_.leafWorld.clear();
    shape_.leafShape.clear();
    if (p.sampleLeaf.empty() || options_.merge != MergeMode::kExact) return;
    const glm::dvec3 mean = solution_.radiosity(int(p.shooter), t);
    const auto ratio = [&](const glm::dvec3& b) {
      glm::dvec3 r(1.0);
      for (int c = 0; c < 3; ++c)
        if (mean[c] > 0.0) r[c] = b[c] / mean[c];
      return r;
    };
    bool uniform = true;
    shape_.sample.resize(p.sampleLeaf.size());
    for (size_t i = 0; i < p.sampleLeaf.size(); ++i) {
      const glm::vec3 b = glm::vec3(ratio(solution_.radiosity(p.sampleLeaf[i], t)));
      shape_.sample[i] = b;
      for (int c = 0; c < 3; ++c) uniform = uniform && std::abs(b[c] - 1.0f) < 1e-3f;
    }
    if (uniform) {
      shape_.sample.clear();
      return;
    }
    if (shapedTransmittance_.size() != texels_) shapedTransmittance_.resize(texels_);
    const PatchHierarchy& h = solution_.hierarchy;
    shape_.shooter = p.shooterWorld[size_t(geometryKey)];
    // The samples' spacing: the shooter's size over sqrt(N).
    shape_.nearDistance = polygonSize(shape_.shooter) / std::sqrt(double(std::max(1, p.samples)));
    for (int leaf : p.leaves) {
      shape_.leafWorld.push_back(nodePolygonIn(shape_.shooter, h.node(leaf).id));
      shape_.leafShape.push_back(ratio(solution_.radiosity(leaf, t)));
    }
  }

  // Combine: the bad layer B_S(t) F T added to the irradiance.
  void combine(const BadPair& p, double t, const std::vector<double>& f) {
    auto clock = SteadyClock::now();
    const glm::dvec3 B = solution_.radiosity(int(p.shooter), t);
    if (!shape_.empty())
      for (size_t x = 0; x < texels_; ++x) acc_[x] += B * f[x] * shapedTransmittance_[x];
    else
      for (size_t x = 0; x < texels_; ++x) acc_[x] += B * (f[x] * double(transmittance_[x]));
    stats_.secondsCombine += secondsSince(clock);
  }

  const GlobalSolution& solution_;
  const std::vector<InputPolygon>& tops_;
  const SceneEmitters& emitters_;  // the lights among tops_
  const BlockerIndex& blockers_;
  const TextureMovieBakerOptions& options_;
  TextureMovieBakerStats& stats_;
  const std::function<OcclusionMaskRenderer&()>& renderer_;
  FormFactorSpill& spill_;
  const MovieExtent& req_;
  MovieGeometry& geo_;
  GoodLayerKeys* gather_;                  // null: Gouraud
  SceneVisibility* visibility_;            // null: covered texels are left as they are
  const uint32_t surface_;                 // the receiver top's planar surface: the samples' seed
  std::unique_ptr<LampDirectTerm> lamps_;  // null: the scene has no lamp
  const size_t texels_;
  int saturatedSamples_ = 0;
  std::vector<BadPair> pairs_;
  // Per-key buffers (movieWorkingBytes counts them).
  std::vector<glm::dvec3> acc_;
  std::vector<float> transmittance_, texture_;
  std::vector<SampleMask> keyMask_;
  std::vector<double> keyFormFactor_;            // also the scan's scratch
  ShooterShape shape_;                           // the current pair's at the current key (shapeAt)
  std::vector<glm::dvec3> shapedTransmittance_;  // per texel, when shape_ is not empty
  // fillCoveredTexels: under static solids (once per movie), and at the current key.
  std::vector<char> staticCovered_, covered_;
  // A triangle's texels on or beyond its long edge (triangle_texels.h); empty for a quad.
  std::vector<char> beyond_;
  bool beyond(size_t x) const { return !beyond_.empty() && beyond_[x]; }
  std::vector<int> movingNear_;  // moving nodes whose bounds over the movie meet the receiver
};

// One bad pair's form factors; false when the shooter cannot reach the patch.
bool MovieBake::scanPair(uint32_t S, BadPair& p) {
  if (S >= tops_.size()) return false;
  const InputPolygon& shooterTop = tops_[S];
  ++stats_.badPairs;
  const bool shooterDynamic = geo_.movesDuringMovie(shooterTop.node);
  const bool pairStatic = !geo_.receiverDynamic() && !shooterDynamic;
  (pairStatic ? stats_.staticPairs : stats_.dynamicPairs) += 1;
  p.shooter = S;
  p.coherent = options_.coherence && pairStatic;
  const int K = geo_.keys();
  p.shooterWorld.resize(static_cast<size_t>(K));
  for (int k = 0; k < K; ++k)
    p.shooterWorld[size_t(k)] =
        shooterTop.local.transformed(geo_.scene().worldTransform(shooterTop.node, geo_.keyTime(k)));

  p.maxFormFactor = scanFormFactors(p);
  return p.maxFormFactor > 0.0;  // else the shooter cannot reach this patch during the movie
}

// Each pair's share of the direct light: the largest, over the texels, of its light's
// B_S F(x -> S) over the sum of it over every pair, at key 0 (so coherent and --no-coherence
// agree: they share key 0's form factors). A light is the tops of one mesh node with one
// material: a lamp split into many tops is as strong as the whole lamp.
void MovieBake::directShares() {
  if (!(options_.weakShare > 0.0) || pairs_.size() < 2) return;
  auto clock = SteadyClock::now();
  const double t = geo_.keyTime(0);
  std::vector<int> light(pairs_.size());
  std::vector<std::pair<int, int>> lights;  // (node, material)
  std::vector<std::vector<double>> lightDirect;
  std::vector<double> direct(texels_, 0.0);
  for (size_t i = 0; i < pairs_.size(); ++i) {
    const InputPolygon& top = tops_[pairs_[i].shooter];
    const std::pair<int, int> key{top.node, top.material};
    auto it = std::find(lights.begin(), lights.end(), key);
    light[i] = int(it - lights.begin());
    if (it == lights.end()) {
      lights.push_back(key);
      lightDirect.emplace_back(texels_, 0.0);
    }
    const glm::dvec3 B = solution_.radiosity(int(pairs_[i].shooter), t);
    const double power = std::max(0.0, B.x + B.y + B.z);
    const std::vector<double>& f = keyZeroFormFactors(pairs_[i], keyFormFactor_);
    std::vector<double>& mine = lightDirect[size_t(light[i])];
    for (size_t x = 0; x < texels_; ++x) {
      mine[x] += power * f[x];
      direct[x] += power * f[x];
    }
  }
  std::vector<double> share(lights.size(), 0.0);
  for (size_t g = 0; g < lights.size(); ++g)
    for (size_t x = 0; x < texels_; ++x)
      if (direct[x] > 0.0) share[g] = std::max(share[g], lightDirect[g][x] / direct[x]);
  for (size_t i = 0; i < pairs_.size(); ++i) pairs_[i].share = share[size_t(light[i])];
  stats_.secondsTransmittance += secondsSince(clock);
}

// One bad pair's per-movie part after the scan: its samples and blockers.
void MovieBake::planPair(BadPair& p) {
  const uint32_t S = p.shooter;
  // Shooter samples (paper §3.1 step 1), fixed in the shooter's frame for the whole movie. A
  // weak pair (under --weak-share of every texel's direct light) takes a quarter of the
  // minimum: its penumbra's steps are a quarter of its small share.
  auto clock = SteadyClock::now();
  const int minSamples =
      p.share < options_.weakShare ? std::max(1, options_.minSamples / 4) : options_.minSamples;
  p.samples = transmittanceSampleCount(p.maxFormFactor, options_.samplesPerFormFactor, minSamples,
                                       options_.maxSamples);
  stats_.samples += p.samples;
  if (minSamples < options_.minSamples) ++stats_.weakPairs;
  // Seeded by the receiver's planar surface (planar_surfaces.h), not the movie's node or top: the
  // movies of one surface (a parent's and its children's, neighbours at one level, a wall's
  // triangles) then take the same sample points when they take as many, and their
  // kernel-weighted penumbrae meet without a step (issue 56: per top, two triangles of one wall
  // made two estimates of one penumbra). A top alone in its plane seeds as it did.
  const uint32_t seed = mix32(uint64_t(surface_) * 0x9e3779b97f4a7c15ull ^ S);
  p.unitSamples = multiJitteredPoints(p.samples, seed);
  // A subdivided shooter that does not emit: its leaves' radiosity shapes its light (a light's
  // is its emission, uniform; skipping it keeps the lights' pairs as they were, at no cost).
  const PatchHierarchy& h = solution_.hierarchy;
  if (!h.isLeaf(int(S)) && !emitters_.topEmits(int(S))) {
    const Polygon& shooter = p.shooterWorld[0];
    for (const glm::dvec2& a : p.unitSamples)
      p.sampleLeaf.push_back(
          leafAtTopUv(h, int(S), polygonUvAt(shooter, samplePointOnPolygon(shooter, a))));
    std::vector<int> stack{int(S)};
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      if (h.isLeaf(i)) {
        p.leaves.push_back(i);
        continue;
      }
      for (int c = 3; c >= 0; --c) stack.push_back(h.node(i).firstChild + c);
    }
  }

  std::vector<int> candidates = blockerCandidates(S, p);
  if (p.coherent) {
    planCoherentBlockers(p, candidates);
  } else {
    // A moving end (or the baseline): every blocker in the key's shaft at every key.
    for (int b : candidates) {
      bool dyn = geo_.movesDuringMovie(tops_[size_t(b)].node);
      (dyn ? stats_.dynamicBlockers : stats_.staticBlockers) += 1;
    }
    p.candidates = std::move(candidates);
  }
  stats_.secondsTransmittance += secondsSince(clock);
}

// The largest form factor over the movie fixes N (and whether the pair matters at all). A
// coherent pair keeps its one set; a moving pair's sets are spilled as they are scanned and the
// scan stops once N has reached its maximum (more keys cannot change it; their sets are
// computed when their key is baked).
double MovieBake::scanFormFactors(BadPair& p) {
  auto clock = SteadyClock::now();
  double maxF = 0.0;
  if (p.coherent) {
    countFormFactors(geo_.formFactorsAt(p, 0, p.formFactor));
    for (double v : p.formFactor) maxF = std::max(maxF, v);
    stats_.secondsFormFactor += secondsSince(clock);
    return maxF;
  }
  const int K = geo_.keys();
  p.spilled.assign(static_cast<size_t>(K), -1);
  for (int k = 0; k < K; ++k) {
    countFormFactors(geo_.formFactorsAt(p, k, keyFormFactor_));
    for (double v : keyFormFactor_) maxF = std::max(maxF, v);
    p.spilled[size_t(k)] = spill_.put(keyFormFactor_);
    if (maxF > 0.0 &&
        transmittanceSampleCount(maxF, options_.samplesPerFormFactor, options_.minSamples,
                                 options_.maxSamples) == saturatedSamples_)
      break;
  }
  stats_.secondsFormFactorScan += secondsSince(clock);
  return maxF;
}

// Blocker candidates: the top-level patches whose box may meet the pair's shaft box at some
// key (all keys' for a pair that moves, key 0's for a static one: planCoherentBlockers places
// blockers at key 0), but the two ends and their reversed copies. Each list is filtered again
// against the shafts where it is used; this only keeps far patches out.
std::vector<int> MovieBake::blockerCandidates(uint32_t S, const BadPair& p) {
  const uint32_t R = req_.patch.top;
  const InputPolygon &receiverTop = tops_[R], &shooterTop = tops_[S];
  AxisBox shaft = geo_.shaftAt(p, 0);
  if (!p.coherent)
    for (int k = 1; k < geo_.keys(); ++k) {
      const AxisBox b = geo_.shaftAt(p, k);
      growBox(shaft, b[0]);
      growBox(shaft, b[1]);
    }
  std::vector<int> candidates;
  for (int b : blockers_.near(shaft[0], shaft[1])) {
    if (b == int(R) || b == int(S) || sameSurface(tops_[size_t(b)], receiverTop) ||
        sameSurface(tops_[size_t(b)], shooterTop))
      continue;
    candidates.push_back(b);
  }
  return candidates;
}

// §5: a static pair's shaft blockers split into static ones, rendered here once per movie into
// the pair's static mask, and dynamic ones (in the shaft swept over the movie), rendered per key.
void MovieBake::planCoherentBlockers(BadPair& p, const std::vector<int>& candidates) {
  const AxisBox shaft = geo_.shaftAt(p, 0);
  const Shaft hull = geo_.hullAt(p, 0);
  std::vector<int> staticList;
  for (int b : candidates) {
    int node = tops_[size_t(b)].node;
    if (!geo_.movesDuringMovie(node)) {
      const AxisBox pb = boxOf(geo_.worldPolygon(b, 0));  // t0 is key 0's time
      if (boxesMeet(pb, shaft) && hull.meets(pb[0], pb[1])) staticList.push_back(b);
    } else {
      const std::array<glm::dvec3, 2>& sb = geo_.sweptDuringMovie(node);
      if (boxesMeet(AxisBox{sb[0], sb[1]}, shaft)) p.dynamicList.push_back(b);
    }
  }
  stats_.staticBlockers += long(staticList.size());
  stats_.dynamicBlockers += long(p.dynamicList.size());
  p.keyZeroSamples = geo_.samplesAt(p, 0);
  p.valid = frontSampleMask(geo_.receiverWorld(0), p.keyZeroSamples);
  std::vector<BlockerTriangle> staticTris = geo_.blockersAt(p, staticList, 0);
  renderer_().render(geo_.receiverWorld(0), geo_.width(), geo_.height(), p.keyZeroSamples,
                     staticTris, p.staticMask);
  if (!staticTris.empty())
    stats_.passesSavedByCoherence += geo_.keys() - 1;
  else
    std::vector<SampleMask>().swap(p.staticMask);  // all zero: not kept
}

}  // namespace

const char* goodLayerName(GoodLayer g) {
  return g == GoodLayer::kGather ? "gather" : "gouraud";
}

// TextureMovieBakerOptions::toJson is movies_options.cpp's (its parameter table).

Polygon nodePolygonIn(const Polygon& top, PatchId node) {
  const bool triangle = top.count == 3;
  static const glm::dvec2 quadCorners[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  static const glm::dvec2 triCorners[3] = {{0, 0}, {1, 0}, {0, 1}};
  Polygon out;
  out.count = top.count;
  for (int k = 0; k < out.count; ++k)
    out.v[k] = polygonPointAt(
        top, topUvFromNodeUv(node, triangle ? triCorners[k] : quadCorners[k], triangle));
  return out;
}

Polygon nodeWorldPolygon(const Scene& scene, const InputPolygon& top, PatchId node, double t) {
  return nodePolygonIn(top.local, node).transformed(scene.worldTransform(top.node, t));
}

TextureMovieBaker::TextureMovieBaker(const Scene& scene, const GlobalSolution& solution, double fps,
                                     TextureMovieBakerOptions options,
                                     TextureMovieBakerBackends backends)
    : scene_(scene),
      solution_(solution),
      fps_(fps),
      options_(options),
      backends_(std::move(backends)),
      tops_(solution.hierarchy.tops()),
      emitters_(scene, tops_) {
  if (options_.keyStep < 1) throw Error(ExitCode::kUsage, "--movie-key-step", "must be >= 1");
  if (options_.maxSamples < 1 || options_.maxSamples > kMaxTransmittanceSamples)
    throw Error(ExitCode::kUsage, "--max-samples", "must be in 1..64");
  // A --max-samples below --min-samples lowers the minimum too (transmittanceSampleCount
  // clamps it): `--max-samples 4` means at most 4, whatever the default minimum.
  if (!(options_.gatherShooterRatio >= 0.0) || !std::isfinite(options_.gatherShooterRatio))
    throw Error(ExitCode::kUsage, "--gather-shooter-ratio", "must be a finite number >= 0");
  if (options_.gatherRays < 0 || options_.gatherRays > VisibilityScene::kMaxRecordedPairs)
    throw Error(ExitCode::kUsage, "--gather-rays", "must be in 0..64");
  if (options_.clusterVisibilityRays < 0 ||
      options_.clusterVisibilityRays > VisibilityScene::kMaxRecordedPairs)
    throw Error(ExitCode::kUsage, "--cluster-visibility-rays", "must be in 0..64");
  if (options_.nearShooterLevels < 0 || options_.nearShooterLevels > 3)
    throw Error(ExitCode::kUsage, "--near-shooter-levels", "must be in 0..3");
  if (options_.minSamples < 1) throw Error(ExitCode::kUsage, "--min-samples", "must be >= 1");
  if (!(options_.weakShare >= 0.0 && options_.weakShare <= 1.0))
    throw Error(ExitCode::kUsage, "--weak-share", "must be in [0, 1]");
  if (!(options_.samplesPerFormFactor >= 0.0))
    throw Error(ExitCode::kUsage, "--samples-per-form-factor", "must be >= 0");
  if (!(options_.maxTextureMemoryMiB > 0.0))
    throw Error(ExitCode::kUsage, "--max-texture-memory", "must be > 0");
  if (!(fps_ > 0.0) || !std::isfinite(fps_))
    throw Error(ExitCode::kBadInput, "", "frames per second must be positive");
  if (!(options_.rayCastBudget >= 0.0) || !std::isfinite(options_.rayCastBudget))
    throw Error(ExitCode::kUsage, "--ray-cast-budget", "must be a finite number >= 0");
  if (!backends_.maskRenderer)
    backends_.maskRenderer = [budget = options_.rayCastBudget] {
      return std::make_unique<AdaptiveMaskRenderer>(
          budget, [] { return std::make_unique<TransmittanceRenderer>(); });
    };
  if (!backends_.formFactorSpill)
    backends_.formFactorSpill = [] { return std::make_unique<NoFormFactorSpill>(); };
}

TextureMovieBaker::~TextureMovieBaker() = default;

OcclusionMaskRenderer& TextureMovieBaker::renderer() {
  if (!renderer_) renderer_ = backends_.maskRenderer();
  return *renderer_;
}

std::string TextureMovieBaker::rendererName() const {
  return renderer_ ? renderer_->rendererName() : std::string();
}

std::unique_ptr<TextureMovieBaker> TextureMovieBaker::sibling() const {
  return std::make_unique<TextureMovieBaker>(scene_, solution_, fps_, options_, backends_);
}

void TextureMovieBaker::addStats(const TextureMovieBakerStats& stats) {
  stats_ += stats;
}

double TextureMovieBaker::movieWorkingBytes(int width, int height, size_t badShooters) {
  // Per texel: texel (u,v) and local point (16 + 24); the key's double accumulator (24), its
  // float texture (12) and the sink's copy of key 0 (12, constant-movie check); one pair's
  // float transmittance (4) or, a subdivided shooter's, per channel (24), per-key sample mask
  // (8) and per-key form factor (8). Per coherent bad pair: its form factors (8) and
  // static-blocker sample mask (8).
  const double perTexel = 16 + 24 + 24 + 12 + 12 + 4 + 24 + 8 + 8 + 16.0 * double(badShooters);
  return double(width) * double(height) * perTexel;
}

BakedMovie TextureMovieBaker::bake(const MovieExtent& req) {
  // Collects the keys; a movie whose keys all agree keeps one (coherence on).
  struct Collector : BakedKeySink {
    bool collapse = false;
    std::vector<std::vector<float>> keys;
    void begin(const BakedMovie&) override {}
    void key(size_t, const std::vector<float>& texture) override { keys.push_back(texture); }
    size_t finish() override {
      bool constant = collapse && keys.size() > 1;
      for (size_t k = 1; k < keys.size() && constant; ++k)
        constant = std::memcmp(keys[0].data(), keys[k].data(), keys[0].size() * sizeof(float)) == 0;
      if (constant) keys.resize(1);
      return keys.size();
    }
  } collector;
  collector.collapse = options_.coherence;
  BakedMovie movie = bake(req, collector);
  movie.keys = std::move(collector.keys);
  movie.keyFrames.resize(movie.keys.size());
  movie.keyTimes.resize(movie.keys.size());
  return movie;
}

void TextureMovieBaker::checkRequest(const MovieExtent& req, size_t badShooters) const {
  const std::string where = "movie " + std::to_string(req.movie);
  const int w = req.width, h = req.height;
  // Working memory: one key's buffers and the per-pair ones, whatever the number of keys.
  const double bytes = movieWorkingBytes(w, h, badShooters);
  const double budget = options_.maxTextureMemoryMiB * 1024.0 * 1024.0;
  if (bytes > budget) {
    char budgetText[32];
    std::snprintf(budgetText, sizeof budgetText, "%g", options_.maxTextureMemoryMiB);
    throw Error(ExitCode::kEnvironment, where,
                "texture " + std::to_string(w) + "x" + std::to_string(h) + " with " +
                    std::to_string(badShooters) + " bad shooter(s) needs " +
                    std::to_string(int(std::ceil(bytes / 1048576.0))) +
                    " MiB of working memory; --max-texture-memory is " + budgetText + " MiB");
  }
}

SceneVisibility* TextureMovieBaker::sceneVisibility() {
  if (!visibility_) {  // once per baker: Embree's BVH of the whole scene
    const std::vector<double>& k = solution_.keyTimes;
    visibility_ = std::make_unique<SceneVisibility>(scene_, solution_.hierarchy, k.front(),
                                                    k.back(), /*split=*/true);
    visibility_->setTime(k.front());
  }
  return visibility_.get();
}

// Whether a bad pair's shadows move during the movie: an end moves, or a moving node's swept
// bounds meet the box around the receiver node and the shooter (the shaft's bounds).
bool TextureMovieBaker::shadowsMove(const MovieExtent& req,
                                    const std::vector<uint32_t>& badShooters) const {
  const double t0 = req.firstFrame / fps_, t1 = req.lastFrame / fps_;
  const InputPolygon& top = tops_[req.patch.top];
  if (lampShadowsMove(scene_, tops_, emitters_, top.node,
                      nodeWorldPolygon(scene_, top, req.patch, t0), t0, t1))
    return true;
  if (badShooters.empty()) return false;
  const InputPolygon& receiverTop = tops_[req.patch.top];
  if (scene_.isDynamic(receiverTop.node, t0, t1)) return true;
  std::vector<std::array<glm::dvec3, 2>> swept;
  for (int node : movingNodesOf(scene_, tops_, t0, t1))
    swept.push_back(scene_.sweptBounds(node, t0, t1));
  if (swept.empty()) return false;
  const AxisBox receiver = boxOf(nodeWorldPolygon(scene_, receiverTop, req.patch, t0));
  for (uint32_t S : badShooters) {
    if (S >= tops_.size()) continue;
    if (scene_.isDynamic(tops_[S].node, t0, t1)) return true;
    AxisBox shaft = receiver;
    growBoxTo(shaft, tops_[S].local.transformed(scene_.worldTransform(tops_[S].node, t0)));
    for (const auto& b : swept)
      if (boxesMeet(shaft, AxisBox{b[0], b[1]})) return true;
  }
  return false;
}

void TextureMovieBaker::checkExtent(const MovieExtent& req) const {
  const std::string where = "movie " + std::to_string(req.movie);
  if (req.patch.top >= tops_.size())
    throw inputError(where, "patch " + req.patch.toString() + " names top-level patch " +
                                std::to_string(req.patch.top) + "; the scene has " +
                                std::to_string(tops_.size()));
  if (req.patch.path == 0 || req.patch.level() > PatchId::kMaxLevel)
    throw inputError(where, "invalid patch path");
  if (req.width < 1 || req.height < 1 || req.width > 16384 || req.height > 16384)
    throw inputError(where, "texture " + std::to_string(req.width) + "x" +
                                std::to_string(req.height) + "; expected 1..16384 each way");
  if (req.firstFrame > req.lastFrame) throw inputError(where, "first frame after last frame");
}

BakedMovie TextureMovieBaker::keyPlan(const MovieExtent& req) const {
  checkExtent(req);
  const std::vector<uint32_t> badShooters = solution_.badShooters(req.patch.top);
  BakedMovie movie;
  movie.keyStep = options_.keyStep;
  if (options_.movingShadowKeyStep > 0 && options_.movingShadowKeyStep < options_.keyStep &&
      shadowsMove(req, badShooters))
    movie.keyStep = options_.movingShadowKeyStep;
  movie.keyFrames = keyFrames(req.firstFrame, req.lastFrame, movie.keyStep);
  for (int f : movie.keyFrames) movie.keyTimes.push_back(f / fps_);
  return movie;
}

BakedMovie TextureMovieBaker::bake(const MovieExtent& req, BakedKeySink& sink, MovieKeyRange keys) {
  const auto planStart = SteadyClock::now();
  BakedMovie movie = keyPlan(req);
  const std::vector<uint32_t> badShooters = solution_.badShooters(req.patch.top);
  checkRequest(req, badShooters.size());
  const int movieKeys = int(movie.keyFrames.size());
  const int firstKey = keys.first, endKey = keys.count < 0 ? movieKeys : keys.first + keys.count;
  if (firstKey < 0 || firstKey >= endKey || endKey > movieKeys)
    throw Error(ExitCode::kUsage, "movie " + std::to_string(req.movie),
                "keys " + std::to_string(firstKey) + "+" + std::to_string(keys.count) +
                    " outside its " + std::to_string(movieKeys) + " keys");

  // Planning (everything that does not depend on the key), then the keys one by one.
  MovieGeometry geometry(scene_, tops_, req, movie.keyTimes);
  std::unique_ptr<FormFactorSpill> spill = backends_.formFactorSpill();
  const std::function<OcclusionMaskRenderer&()> gl = [this]() -> OcclusionMaskRenderer& {
    return renderer();
  };
  std::unique_ptr<GoodLinkGather> gather;
  if (options_.goodLayer == GoodLayer::kGather) {
    if (!goodLinks_) goodLinks_ = std::make_unique<GoodLinksByReceiver>(solution_);
    auto clock = SteadyClock::now();
    gather = std::make_unique<GoodLinkGather>(
        scene_, solution_, emitters_, *goodLinks_, req, geometry.texelPoints(), movie.keyTimes,
        options_.gatherShooterRatio, 0.5 * options_.maxTextureMemoryMiB * 1048576.0, stats_.gather,
        options_.gatherRays > 0 ? sceneVisibility() : nullptr, options_.gatherRays,
        options_.nearShooterLevels, options_.gatherPartialShare, options_.clusterVisibilityRays);
    stats_.secondsGood += secondsSince(clock);
  }
  std::unique_ptr<GoodLayerKeys> goodKeys;
  if (gather)
    goodKeys = std::make_unique<GoodLayerKeys>(
        *gather, goodLayerGatherTimes(req.firstFrame, req.lastFrame, movie.keyStep,
                                      options_.goodLayerKeyStep, fps_));
  if (!blockers_) blockers_ = std::make_unique<BlockerIndex>(scene_, tops_);
  if (surfaceOfTop_.empty()) surfaceOfTop_ = planarSurfaceOfTops(tops_);
  MovieBake bake(solution_, tops_, emitters_, options_, stats_, gl, *spill, req, geometry,
                 goodKeys.get(),
                 options_.fillCovered || !emitters_.lamps().empty() ? sceneVisibility() : nullptr,
                 *blockers_, surfaceOfTop_[req.patch.top]);
  bake.plan(badShooters);
  movie.secondsPlan = secondsSince(planStart);
  sink.begin(movie);
  for (int k = firstKey; k < endKey; ++k) bake.bakeKey(k, movie.keyTimes[size_t(k)], sink);
  const size_t stored = sink.finish();

  if (renderer_) {
    stats_.passes = renderer_->passes();
    stats_.samplePasses = renderer_->samplePasses();
    if (auto* adaptive = dynamic_cast<const AdaptiveMaskRenderer*>(renderer_.get()))
      stats_.rayCastPasses = adaptive->rayCastPasses();
  }
  ++stats_.movies;
  if (stored == 1) ++stats_.constantMovies;
  stats_.keys += long(stored);
  stats_.texels += long(size_t(req.width) * req.height * stored);
  return movie;
}

}  // namespace rad
