// Texture-movie baking, the second pass of Martín, Pueyo, Tost, "Frame-to-frame coherent
// animation with two-pass radiosity" (§3.1 texture computation, §5 frame-to-frame coherence;
// docs/design.md §6.3 "rad-movies").
//
// Per movie (patch node P of top-level patch R, frames [f0, f1], texture w x h) and key time
// t, the irradiance at texel centre x is
//
//   H(x, t) = G(x, t) + \sum_{S \in bad(R)} B_S(t) \, F(x \to S(t)) \, T(x, S, t)
//
// with G the global solution's good-link irradiance (gathered per texel over the good links,
// good_link_gather.h, or the paper's Gouraud), B_S the shooter's radiosity,
// F the exact point-to-polygon form factor (for a shooter far from a tile of texels, its ratio to
// the point kernel interpolated from the tile's corners: MovieGeometry::formFactorsAt) and T the
// transmittance (transmittance.h).
//
// Coherence (§5): for a bad pair whose receiver and shooter are static over the movie, F is
// computed once and the blockers in the pair's shaft are split by Scene::isDynamic: the static
// ones are rendered once per movie into a sample mask, the dynamic ones once per key, and the
// masks are ORed (exact) or their transmittances merged approximately (--merge). A pair with a
// moving end renders every blocker at every key. When every key texture of a movie comes out
// identical the movie is stored with one key (a "constant" movie). With coherence off every
// bad pair recomputes F and renders every blocker at every key and all keys are stored: the
// per-frame method the paper compares against, same binary.
//
// Memory: a movie is baked key-major. What does not depend on the key (texel positions; per
// coherent bad pair its form factors, valid-sample mask and static-blocker sample mask) is
// computed first; then each key's irradiance is accumulated (good layer, then the bad shooters
// in badShooters order: the same arithmetic and order as shooter-major) and handed to a
// BakedKeySink before the next key starts. The working memory is then
// texels x (per-key buffers + per coherent pair buffers), whatever the number of keys. A moving
// pair's form factors, scanned ahead of the keys for their largest value, are parked in a
// FormFactorSpill (form_factor_spill.h) until their key, or recomputed then.
//
// Doors (TextureMovieBakerBackends): the occlusion masks come from an OcclusionMaskRenderer
// (occlusion_mask_renderer.h; OSMesa projective shadows by default) and the spill from a
// factory, so a new shadow method or scratch store is a new class, not an edit of bake().
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "libcommon/intervals/movie_extent.h"
#include "libcommon/movies/form_factor_spill.h"
#include "libcommon/movies/good_link_gather.h"
#include "libcommon/movies/occlusion_mask_renderer.h"
#include "libcommon/movies/transmittance.h"
#include "libcommon/radiosity/global_solution.h"
#include "libcommon/scene/patch_hierarchy.h"
#include "libcommon/scene/scene.h"
#include "libcommon/scene/scene_emitters.h"

namespace rad {

// The good layer G(x, t): the paper's Gouraud interpolation of the global solution's vertex
// irradiance, or the per-texel gather over its good links (good_link_gather.h).
enum class GoodLayer { kGouraud, kGather };
const char* goodLayerName(GoodLayer g);

// rad-movies binds its flags to these fields; toJson() is the provenance parameters, keyed by
// the flag names. The figures behind the defaults: docs/results.md, "Figures moved out of the
// movies code's comments (issue 55)".
struct TextureMovieBakerOptions {
  int keyStep = 6;  // --movie-key-step: frames between key textures (>= 1)
  // --moving-shadow-key-step: the key step of a movie whose bad links' shadows move (a moving
  // node's swept bounds meet a bad pair's shaft, or an end moves): the paper computes the dynamic
  // blockers' shadows every frame (§5, Figure 6), and a shadow interpolated between two keys
  // shows at both places half dark, a double shadow that the structured error reads as blotches
  // (issue 56). 0: keyStep.
  int movingShadowKeyStep = 1;
  // --good-layer-key-step: in a movie keyed more finely than this, the good layer is gathered
  // every this many frames and interpolated in time at the keys between (good_layer_keys.h): the
  // gather is most of a key's cost and the indirect light it carries changes slowly. 0 or at
  // most the movie's key step: gathered at every key.
  int goodLayerKeyStep = 3;
  // Shooter samples per bad link, lower bound. 16, not 4: a small light (the Cornell box's) gets
  // only a few samples from 256 x its form factor, and its penumbrae then show as straight-edged
  // bands, one hard shadow per sample; at 16 the bands are gone.
  int minSamples = 16;
  // --weak-share: a bad pair whose light (the tops of one mesh node and material) gives less than
  // this share of every texel's direct light (B_S F over the sum over the movie's bad pairs, at
  // key 0) takes minSamples / 4 at least; 0: every pair takes minSamples. In a scene of many
  // lights most bad pairs are weak, and the fewer samples of their soft shadows change its frames
  // little.
  double weakShare = 0.1;
  int maxSamples = 64;                  // upper bound (<= 64)
  double samplesPerFormFactor = 256.0;  // N = ceil(this * max texel form factor), then clamped
  MergeMode merge = MergeMode::kExact;  // static/dynamic occlusion merge
  // --ray-cast-budget: a pair's occlusion masks are ray cast on the CPU while they cost at most
  // this many texel-samples (texels x samples), else rendered with OSMesa
  // (ray_cast_masks.h); 0: always OSMesa.
  double rayCastBudget = 16384.0;
  GoodLayer goodLayer = GoodLayer::kGather;  // --good-layer
  // --gather-shooter-ratio: a gathered link's shooter is split into the parts of its sub-tree
  // larger than this times their distance to the receiver (good_link_gather.h); 0: no split.
  // The parts' size then bounds how much two neighbouring receivers, linked to one shooter at
  // different levels, differ in what they gather: each weights a part's mean B by a form factor
  // that varies over the part by about this ratio (issue 56; "Seams from the link sets'
  // resolution" in docs/results.md).
  double gatherShooterRatio = 0.5;
  // --gather-rays: a gathered link that is partly occluded gets its visibility per texel from this
  // many shadow rays to its shooter part, weighted by the shooter's radiosity at their ends
  // (good_link_gather.h); 0: the link's one V over its receiver node, which steps where two
  // receiver nodes whose links are occluded differently meet.
  int gatherRays = 16;
  // --gather-partial-share: a partly occluded gathered link takes its visibility per texel when its
  // risk, B F (1 - V), is at least this share of what the texel gathers, or when the smaller ones
  // left on their V would sum to more than 2.5 shares; and a far one interpolated over a tile goes
  // per texel where the tile's middle misses by this share (good_link_gather.h). A smaller share
  // sends more links per texel: more accurate and slower; the final setting uses 0.001.
  double gatherPartialShare = 0.002;
  // --cluster-visibility-rays: the cluster light of a texel (rad-global's, one value per top
  // and key) scaled by the share of this many rays from the texel to points on the top's far
  // surfaces that are open, over the same share's mean across the top (good_link_gather.h);
  // 0: the top's one value. Needs --gather-rays > 0.
  int clusterVisibilityRays = 32;
  // --near-shooter-levels: a near leaf shooter is split into up to 4^L cells, each with its
  // radiosity re-gathered at its centre from the leaf's links (good_link_gather.h); 0: the leaf's
  // one B (the default: the cells multiply rad-movies' time, a cost the final setting pays).
  int nearShooterLevels = 0;
  // --no-fill-covered: false leaves the texels under a touching solid as they come out (~0),
  // which darkens the pixels beside the solid's foot (fillCoveredTexels).
  bool fillCovered = true;
  bool coherence = true;  // false: the per-key baseline
  // Working memory of one movie (one key's buffers plus the per-pair buffers, see
  // movieWorkingBytes); a movie that needs more is refused with an environment error.
  double maxTextureMemoryMiB = 1024.0;
  // The provenance parameters: moviesParameters() (movies_options.h) under their flags' names.
  nlohmann::json toJson() const;
};

// The parts of the bake a new method replaces without editing it (the doors). Empty members
// take the defaults.
struct TextureMovieBakerBackends {
  // The occlusion masks (default: AdaptiveMaskRenderer, ray-cast masks for small ones and OSMesa
  // projective shadows for the rest), made on the first render the baker needs.
  OcclusionMaskRendererFactory maskRenderer;
  // One store per movie for moving pairs' scanned form factors (default: NoFormFactorSpill,
  // every set recomputed; rad-movies passes formats/form_factor_scratch_file.h's).
  FormFactorSpillFactory formFactorSpill;
};

// The result, as formats/texture_movie.h stores it: keys[k] has width * height * 3 floats
// (RGB irradiance, W/m^2), row j = 0 at v = 0, texel (i, j) at node (u,v) = ((i+.5)/w, (j+.5)/h).
// bake(request, sink) fills in keyFrames, keyTimes and keyStep only (the keys went to the sink).
struct BakedMovie {
  std::vector<int> keyFrames;
  std::vector<double> keyTimes;
  std::vector<std::vector<float>> keys;
  int keyStep = 0;  // the key step used
  // Seconds of the movie's planning (everything before its first key: texel points, the good
  // layer's links, the bad pairs' form factors and static shadows), which every piece of a movie
  // pays again (pipelines/farm_model.py splits a movie's time with it).
  double secondsPlan = 0.0;
};

// Keys [first, first + count) of a movie: what one bake() call bakes. count < 0: to the last.
struct MovieKeyRange {
  int first = 0, count = -1;
};

// Receives one movie's key textures in key order as they are baked (only one key texture is
// alive in the baker at a time). rad-movies streams them into the movie file
// (formats/texture_movie.h TextureMovieWriter).
class BakedKeySink {
 public:
  virtual ~BakedKeySink() = default;
  // Before the first key: keyFrames, keyTimes and keyStep of the movie (keys empty).
  virtual void begin(const BakedMovie& plan) = 0;
  // Key k = 0, 1, ... K-1 in order: width * height * 3 floats, valid during the call only.
  virtual void key(size_t k, const std::vector<float>& texture) = 0;
  // After the last key: the number of keys stored (1 when a movie whose keys are all equal is
  // stored as a constant movie, else K). Counted in the stats.
  virtual size_t finish() = 0;
};

// Counters for --report, summed over movies.
struct TextureMovieBakerStats {
  long movies = 0, constantMovies = 0, keys = 0, texels = 0;
  long badPairs = 0, staticPairs = 0, dynamicPairs = 0;
  long samples = 0;                              // shooter samples over all bad pairs
  long weakPairs = 0;                            // of the bad pairs, under --weak-share
  long staticBlockers = 0, dynamicBlockers = 0;  // per pair, in the pair's (swept) shaft
  long passes = 0, samplePasses = 0;             // transmittance renders
  long rayCastPasses = 0;                        // of them, ray cast (ray_cast_masks.h)
  long passesSavedByCoherence = 0;               // static-blocker renders not repeated
  long coveredTexelsFilled = 0;  // texels under a touching solid given their exposed neighbours'
  // Bad pairs' unoccluded form factors per texel: evaluated, and interpolated over a tile from
  // its corners (a far shooter: MovieGeometry::formFactorsAt).
  long formFactorTexels = 0, formFactorTexelsInterpolated = 0;

  GoodLinkGatherStats gather;  // --good-layer gather
  double secondsGood = 0, secondsFormFactor = 0, secondsTransmittance = 0, secondsCombine = 0;
  // Moving pairs' form factors computed ahead of the keys only to find their largest value
  // (which fixes N): the price of baking key by key without every key's form factors held.
  double secondsFormFactorScan = 0;
  std::vector<std::string> warnings;
  // Adds another baker's counters and seconds (bakeMovieSequence's workers, one baker each).
  TextureMovieBakerStats& operator+=(const TextureMovieBakerStats& other);
  nlohmann::json toJson() const;
};

struct BlockerIndex;

class TextureMovieBaker {
 public:
  // scene and solution must outlive the baker; fps converts frames to times (t = frame / fps).
  // Throws a usage Error for inconsistent options. Key frames of a movie: rad::keyFrames(first,
  // last, options.keyStep) (libcommon/scene/frame_range.h).
  TextureMovieBaker(const Scene& scene, const GlobalSolution& solution, double fps,
                    TextureMovieBakerOptions options, TextureMovieBakerBackends backends = {});
  ~TextureMovieBaker();

  // The movie's key frames, times and step (no key baked): keyFrames(first, last, step) with
  // the moving-shadow step where the movie's shadows move. Throws as bake() does for a bad
  // request.
  BakedMovie keyPlan(const MovieExtent& request) const;

  // Bakes one movie, streaming its keys to `sink`. Throws rad::inputError("movie N", ...) when
  // the request names a patch outside the scene or a bad size, an environment Error when the
  // movie's working memory exceeds maxTextureMemoryMiB. Creates the GL context on first need
  // (a scene without bad pairs never touches GL).
  //
  // `keys`: only these keys are baked and handed to the sink (sink.begin still gets the whole
  // movie's plan, and key(k) the movie's index k). The planning is the whole movie's, so each
  // key comes out bit-identical to the same key of the whole bake; a piece pays the planning
  // (and with it the static shadows of paper §5) again. Throws a usage Error for keys outside
  // the movie.
  BakedMovie bake(const MovieExtent& request, BakedKeySink& sink, MovieKeyRange keys = {});
  // The same with the keys collected in memory (K keys alive; for tests and small movies). A
  // movie whose keys are all bit-equal keeps one key when coherence is on.
  BakedMovie bake(const MovieExtent& request);

  // Bytes bake() holds for a w x h movie of a receiver with `badShooters` bad shooters: one
  // key's buffers plus the per-pair ones, independent of the number of keys.
  static double movieWorkingBytes(int width, int height, size_t badShooters);

  const TextureMovieBakerStats& stats() const { return stats_; }
  const TextureMovieBakerOptions& options() const { return options_; }
  // The renderer's GL_RENDERER, or "" when no render was needed yet.
  std::string rendererName() const;

  // A baker of the same scene, solution, options and backends for another thread. It has its
  // own mask renderer (a GL context is current in one thread at a time), blocker and good-link
  // indexes and scene visibility (whose moving part is set to each key's time, and whose
  // near-shooter store fills as movies go; the values stored do not depend on the order, so
  // every movie comes out the same whichever baker makes it).
  std::unique_ptr<TextureMovieBaker> sibling() const;
  // Adds a sibling's counters.
  void addStats(const TextureMovieBakerStats& stats);

 private:
  const Scene& scene_;
  const GlobalSolution& solution_;
  double fps_;
  TextureMovieBakerOptions options_;
  TextureMovieBakerBackends backends_;
  std::vector<InputPolygon> tops_;
  SceneEmitters emitters_;  // the lights among tops_ (the light seam, scene_emitters.h)
  std::unique_ptr<OcclusionMaskRenderer> renderer_;
  std::unique_ptr<BlockerIndex> blockers_;          // made on the first bake
  std::vector<uint32_t> surfaceOfTop_;              // planar_surfaces.h, on the first bake
  std::unique_ptr<GoodLinksByReceiver> goodLinks_;  // --good-layer gather
  std::unique_ptr<SceneVisibility> visibility_;     // the gather's rays and the covered texels
  SceneVisibility* sceneVisibility();
  TextureMovieBakerStats stats_;

  OcclusionMaskRenderer& renderer();
  bool shadowsMove(const MovieExtent& request, const std::vector<uint32_t>& badShooters) const;
  // Throws for a request bake() cannot do (see bake): a bad patch, size or frames.
  void checkExtent(const MovieExtent& request) const;
  // Throws when the movie's working memory exceeds the budget.
  void checkRequest(const MovieExtent& request, size_t badShooters) const;
};

// Texel centres of a node: world points at time t via the top polygon's (u,v) map.
// out[j * w + i]; also the node's world polygon (corners in the patch (u,v) order).
Polygon nodeWorldPolygon(const Scene& scene, const InputPolygon& top, PatchId node, double t);
// The polygon of `node` in the frame `top` (its top-level patch's polygon) is given in.
Polygon nodePolygonIn(const Polygon& top, PatchId node);

}  // namespace rad
