// Space-time hierarchical radiosity: key-time solves, coherence, merge (see the header).
// The figures behind the reasons given here: docs/results.md, "Figures moved out of the radiosity
// code's comments (issue 55)".
#include "libcommon/radiosity/space_time_radiosity.h"

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <tuple>
#include <unordered_map>
#include <unordered_set>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "libcommon/core/error.h"
#include "libcommon/core/stopwatch.h"
#include "libcommon/radiosity/lamp_coherence.h"
#include "libcommon/radiosity/leaf_vertices.h"
#include "libcommon/radiosity/link_intervals.h"
#include "libcommon/radiosity/scene_visibility.h"
#include "libcommon/radiosity/shaft.h"
#include "libcommon/scene/scene_emitters.h"

namespace rad {

namespace {

// What the merge needs of one key-time solve besides its links (which go straight into the
// LinkIntervals store as each key finishes).
struct KeyRecord {
  std::vector<glm::vec3> radiosity;  // per node of the union hierarchy at that time (push-down)
  // Per node of the key's tree (1 elsewhere): the exposure its links' irradiance is divided
  // by (KeySolution::exposure).
  std::vector<float> exposure;
  // Per node of the union hierarchy: the good-link closure factor of the key-tree leaf it is
  // in or under (KeySolution::goodClosure; 1 for nodes above the leaves, or closure off).
  std::vector<float> goodClosure;
  // Per top: the irradiance it gathered through cluster links (KeySolution::
  // topClusterIrradiance); empty without cluster links.
  std::vector<glm::vec3> clusterIrradiance;
};

// Radiosity of every node, nodes outside the key's tree taking their parent's value.
std::vector<glm::dvec3> pushedDown(const KeySolution& s, const PatchHierarchy& h) {
  std::vector<glm::dvec3> b(s.radiosity.begin(), s.radiosity.end());
  b.resize(size_t(h.size()), glm::dvec3(0.0));
  for (int i = 0; i < h.size(); ++i)
    if (size_t(i) >= s.split.size() || !s.inTree(i, h)) b[size_t(i)] = b[size_t(h.node(i).parent)];
  return b;
}

// The key-tree leaves' good closure factors on every node of the union hierarchy: a node below
// a leaf takes the leaf's, a node above the leaves 1 (it holds no leaf's own row sum).
std::vector<float> pushedDownClosure(const KeySolution& s, const PatchHierarchy& h) {
  std::vector<float> c(size_t(h.size()), 1.0f);
  if (s.goodClosure.empty()) return c;
  for (int i = 0; i < h.size(); ++i) {
    bool inTree = size_t(i) < s.split.size() && s.inTree(i, h);
    if (inTree && !s.split[size_t(i)] && size_t(i) < s.goodClosure.size())
      c[size_t(i)] = float(s.goodClosure[size_t(i)]);
    else if (!inTree)
      c[size_t(i)] = c[size_t(h.node(i).parent)];
  }
  return c;
}

}  // namespace

const char* badLinkRuleName(BadLinkRule r) {
  switch (r) {
    case BadLinkRule::kLights:
      return "lights";
    case BadLinkRule::kPartial:
      return "partial";
    case BadLinkRule::kAll:
      return "all";
    case BadLinkRule::kNone:
      return "none";
  }
  return "?";
}

LinkCache reusableLinks(const KeySolution& prev, const PatchHierarchy& h, const Scene& scene,
                        double t0, double t1) {
  // Static over [t0, t1]? Moving mesh nodes contribute their swept bounds.
  const std::vector<char> moving = movingTopsOf(scene, h, t0, t1);
  auto isStatic = [&](int top) { return !moving[size_t(top)]; };
  std::vector<std::array<glm::dvec3, 2>> swept;
  for (int node : scene.meshNodes())
    if (scene.isDynamic(node, t0, t1)) swept.push_back(scene.sweptBounds(node, t0, t1));
  // Per link, in parallel: whether it is kept (both ends static) and whether a moving object's
  // swept box meets its shaft; then the kept ones in link order, as a serial loop would keep them.
  enum : char { kSkipped, kFree, kShadowed };
  std::vector<char> state(prev.links.size());
  tbb::parallel_for(size_t(0), prev.links.size(), [&](size_t li) {
    const SolverLink& l = prev.links[li];
    // A moving end changes the geometry: nothing of the link is known.
    if (!isStatic(int(h.node(l.receiver).id.top)) || !isStatic(int(h.node(l.shooter).id.top))) {
      state[li] = kSkipped;
      return;
    }
    bool hit = false;
    for (const auto& box : swept)
      if (shaftMeetsBox(prev.world[size_t(l.receiver)], prev.world[size_t(l.shooter)], box[0],
                        box[1])) {
        hit = true;
        break;
      }
    state[li] = hit ? kShadowed : kFree;
  });
  std::vector<std::pair<uint32_t, uint32_t>> keys;
  std::vector<CachedLink> values;
  keys.reserve(prev.links.size());
  values.reserve(prev.links.size());
  for (size_t li = 0; li < prev.links.size(); ++li) {
    if (state[li] == kSkipped) continue;
    const SolverLink& l = prev.links[li];
    CachedLink c;
    c.estimate = l.estimate;
    c.spreadArea = l.spreadArea;
    // computeAccurate leaves F at the estimate for a link it finds invisible (closure off)
    c.formFactor = l.integrated ? l.formFactor : -1.0;
    c.visibility = l.rayVisibility;
    c.openPairs = l.openPairs;
    c.visibilityValid = state[li] == kFree;  // a moving object in the shaft: the shadow rays again
    if (li < prev.rayPairStart.size()) c.rayPairs = prev.rayPairStart[li];
    keys.emplace_back(uint32_t(l.receiver), uint32_t(l.shooter));
    values.push_back(c);
  }
  return LinkCache(keys, std::move(values), uint32_t(h.size()));
}

namespace {

// Paper §3.1: the second pass recomputes a (receiver, shooter) pair of top-level patches per
// texel when it is bad. Marks the pair of link l under `rule`, over all key times (a pair once
// bad stays bad).
// --bad-links partial's partly visible link: gathered, threshold < V < 1.
bool partlyVisible(const SolverLink& l, double partialThreshold) {
  return !l.refined && float(l.rayVisibility) > partialThreshold && float(l.rayVisibility) < 1.0f;
}

void markBadPair(char& bad, BadLinkRule rule, const SolverLink& l, bool shooterEmits,
                 double partialThreshold) {
  switch (rule) {
    case BadLinkRule::kNone:
      break;
    case BadLinkRule::kAll:
      bad = 1;
      break;
    case BadLinkRule::kLights:
      bad |= shooterEmits;
      break;
    case BadLinkRule::kPartial:
      bad |= shooterEmits || partlyVisible(l, partialThreshold);
      break;
  }
}

// --partial-power-share: what a partly visible link's shadow takes from its receiver, B_q F (1 - V)
// A_p (the mean of the channels), summed per pair. The pairs whose shadows are strong move to the
// second pass's per-texel shadows; the weak ones stay with the gathered good layer (per-texel
// shadows for every partly visible pair of a large scene would multiply rad-movies' time).
double meanChannel(const glm::dvec3& B) {
  return (B.x + B.y + B.z) / 3.0;
}

double partialShadowPower(const KeySolution& s, const SolverLink& l) {
  return meanChannel(s.radiosity[size_t(l.shooter)]) * l.formFactor * (1.0 - l.rayVisibility) *
         s.area[size_t(l.receiver)];
}

// The power the surfaces carry, sum A B over the top-level patches (the mean of the channels).
double carriedPower(const KeySolution& s, int topCount) {
  double sum = 0.0;
  for (size_t t = 0; t < size_t(topCount); ++t) sum += s.area[t] * meanChannel(s.radiosity[t]);
  return sum;
}

KeyTimeReport keyTimeReportOf(const KeySolution& s, const PatchHierarchy& h, double time,
                              double secondsCoherence) {
  KeyTimeReport kr;
  kr.time = time;
  kr.secondsCoherence = secondsCoherence;
  kr.links = s.links.size();
  kr.recomputed = s.linksComputed;
  kr.reused = s.linksReused;
  kr.visibilityOnly = s.linksVisibilityOnly;
  kr.iterations = s.iterations;
  kr.refineRounds = s.refineRounds;
  kr.linkCapReached = s.linkCapReached;
  kr.clusterLinks = s.clusterLinks;
  kr.clusterLinksReused = s.clusterLinksReused;
  kr.lampValues = s.lampValues.size();
  kr.lampValuesReused = s.lampValuesReused;
  kr.secondsLinks = s.secondsLinks;
  kr.secondsSolve = s.secondsSolve;
  kr.linkCensus = s.linkCensus.toJson();
  for (int i = 0; i < h.size(); ++i) kr.nodes += s.inTree(i, h) ? 1 : 0;
  return kr;
}

// What the key-time pass leaves for the final merge: the union hierarchy, per key its record,
// the links' activity intervals and the bad pairs (receiver top << 32 | shooter top); per key
// the union's node count after its solve (for key windows).
struct KeyPassResult {
  PatchHierarchy hierarchy;
  std::vector<KeyRecord> records;
  LinkIntervals intervals;
  std::unordered_set<uint64_t> badPairs;
  std::vector<uint32_t> nodeCount;
};

// The key-time pass (paper §4.2): one hierarchical solve per key time on the shared union
// hierarchy, each taking over what stays valid of the previous key's links (coherence), and
// folded into the links' activity intervals, the bad pairs and the per-key radiosity as soon
// as it is solved. It solves keys first..last of `keyTimes` (a window; key k's record and
// intervals index is k - first) and builds what depends on the whole animation from all of
// `keyTimes`, so a window's keys come out as the whole run's.
class KeyTimePass {
 public:
  KeyTimePass(const Scene& scene, const std::vector<double>& keyTimes, size_t first, size_t last,
              const SpaceTimeOptions& opt, SpaceTimeReport& rep)
      : scene_(scene), keyTimes_(keyTimes), first_(first), last_(last), opt_(opt), rep_(rep) {
    auto tSetup = std::chrono::steady_clock::now();
    h_ = PatchHierarchy(scene.inputPolygons());
    if (h_.topCount() == 0) throw inputError(scene.path, "has no polygons");
    T_ = size_t(h_.topCount());
    surfaces_ = surfacePropertiesOf(scene, h_);
    emitters_ = std::make_unique<SceneEmitters>(scene, h_.tops());
    vis_ = std::make_unique<SceneVisibility>(scene, h_, keyTimes.front(), keyTimes.back());
    rep_.topPatches = T_;
    records_.resize(last - first + 1);
    movingTops_ = movingTopsOf(scene, h_, keyTimes.front(), keyTimes.back());
    if (opt_.radiosity.clustering)
      clusters_ = clusterTreeOf(scene, h_, keyTimes.front(), keyTimes.back());
    rep_.secondsSetup = secondsSince(tSetup);
  }

  void run() {
    KeySolution prev;
    for (size_t k = first_; k <= last_; ++k) {
      KeySolution s = solveKey(k, prev);
      const size_t r = k - first_;
      // After the last key no key takes over its values: what only the next key's coherence
      // caches read goes before the fold, whose sort and rows are rad-global's peak at the end of
      // a run (of one key: the whole run's).
      if (k == last_) releaseCoherenceState(s);
      foldLinks(s, uint32_t(r));
      std::vector<glm::dvec3> b = pushedDown(s, h_);
      records_[r].radiosity.assign(b.begin(), b.end());
      records_[r].exposure.assign(s.exposure.begin(), s.exposure.end());  // one per node
      records_[r].goodClosure = pushedDownClosure(s, h_);
      records_[r].clusterIrradiance.assign(s.topClusterIrradiance.begin(),
                                           s.topClusterIrradiance.end());
      nodeCount_.push_back(uint32_t(h_.size()));
      // Key 0 grew its ray pairs by doubling (no previous key to reserve by): the spare capacity,
      // held through the next key's solve, goes once it passes a quarter of the size.
      if (s.rayPairs.capacity() > s.rayPairs.size() + s.rayPairs.size() / 4)
        s.rayPairs.shrink_to_fit();
      prev = std::move(s);
    }
  }

  // The parts of a key's solution that only the next key's solve reads (solveKey's caches and
  // reserves), freed.
  static void releaseCoherenceState(KeySolution& s) {
    std::vector<LinkRayPair>().swap(s.rayPairs);
    std::vector<uint32_t>().swap(s.rayPairStart);
    std::vector<ClusterLink>().swap(s.clusterLinkValues);
    std::vector<uint8_t>().swap(s.clusterMemberVisibility);
    std::vector<NearLinkTest>().swap(s.clusterNearTests);
    decltype(s.leafTopFormFactor)().swap(s.leafTopFormFactor);
    std::vector<uint64_t>().swap(s.coveredPoints);
  }

  KeyPassResult take() {
    return {std::move(h_), std::move(records_), std::move(intervals_), std::move(badPairs_),
            std::move(nodeCount_)};
  }

 private:
  // Takes what the coherence caches need out of `prev` (the previous key's solution, not used
  // after this).
  KeySolution solveKey(size_t k, KeySolution& prev) {
    double t = keyTimes_[k];
    vis_->setTime(t);
    KeySolveInput in;
    in.topToWorld = topTransforms(scene_, h_, t);
    in.movingTops = movingTops_;
    in.visibility = &vis_->visibility();
    in.clusters = &clusters_;
    LinkCache cache;
    ClusterLinkCache clusterCache;
    double secondsCoherence = 0;
    in.expectedLinks = prev.links.size();
    in.expectedRayPairs = prev.rayPairs.size();
    in.expectedClusterLinks = prev.clusterLinkValues.size();
    PlacedLamps lamps = placeLamps(*emitters_, t);
    in.lamps = lamps.lamps;
    LampValueCache lampCache;
    if (opt_.coherence && k > first_) {
      auto tc = std::chrono::steady_clock::now();
      // The caches hold what the solve takes over of prev's links and cluster links; of prev itself
      // it still reads the ray pairs (reuseRayPairs). Each part of prev goes as soon as its cache
      // is made, so that at most one cache is being built beside all of prev: prev held beside the
      // caches and the new key's links, or all three built before any is freed, would set the peak
      // between keys.
      // Swapped with empty vectors: `v = {}` would pick operator=(initializer_list), which empties
      // v but keeps its capacity.
      cache = reusableLinks(prev, h_, scene_, keyTimes_[k - 1], t);
      in.reuse = &cache;
      std::vector<SolverLink>().swap(prev.links);
      std::vector<uint32_t>().swap(prev.rayPairStart);  // the cache holds each link's start
      in.reuseRayPairs = &prev.rayPairs;
      if (!clusters_.empty()) {
        clusterCache = reusableClusterLinks(prev, clusters_, h_, scene_, keyTimes_[k - 1], t);
        in.reuseClusterLinks = &clusterCache;
      }
      std::vector<ClusterLink>().swap(prev.clusterLinkValues);
      std::vector<uint8_t>().swap(prev.clusterMemberVisibility);
      std::vector<NearLinkTest>().swap(prev.clusterNearTests);
      // The closure integrates only pairs of patches that never move (KeySolveInput::
      // movingTops), so every leaf-to-top form factor prev kept stays valid; the union
      // hierarchy's dense node numbering is the same at every key. The solve takes them over.
      in.reuseLeafFormFactors = &prev.leafTopFormFactor;
      in.reuseClosed = &closedCache_;
      in.reuseCoveredPoints = &prev.coveredPoints;
      in.releaseRayPairs = [&] { std::vector<LinkRayPair>().swap(prev.rayPairs); };
      in.releaseClusterLinks = [&] { clusterCache = ClusterLinkCache(); };
      if (!lamps.lamps.empty()) {
        lampCache =
            reusableLampValues(prev, prevLamps_, *emitters_, h_, scene_, keyTimes_[k - 1], t);
        in.reuseLamps = &lampCache;
      }
      LampValueCache().swap(prev.lampValues);
      secondsCoherence = secondsSince(tc);
    }
    KeySolution s = solveKeyTime(h_, surfaces_, in, opt_.radiosity);
    prevLamps_ = std::move(lamps);
    if (opt_.coherence)
      for (const auto& [id, closed] : s.closedNodes) closedCache_.emplace(id, closed);
    rep_.keys.push_back(keyTimeReportOf(s, h_, t, secondsCoherence));
    if (opt_.onKeySolved) opt_.onKeySolved();
    return s;
  }

  // Per link (receiver << 32 | shooter): its value at key k into the activity intervals, and
  // its (receiver top, shooter top) pair into the bad pairs.
  void foldLinks(const KeySolution& s, uint32_t k) {
    std::vector<LinkIntervals::KeyValue> values;
    values.reserve(s.links.size());
    const bool byPower = opt_.badLinks == BadLinkRule::kPartial && opt_.partialPowerShare > 0.0;
    std::unordered_map<uint64_t, double> shadowPower;  // per pair (partialShadowPower)
    for (const SolverLink& l : s.links) {
      values.push_back({LinkIntervals::linkOf(l.receiver, l.shooter), float(l.fv()),
                        float(l.visibility), l.refined});
      uint32_t rt = h_.node(l.receiver).id.top, st = h_.node(l.shooter).id.top;
      const uint64_t pair = (uint64_t(rt) << 32) | st;
      const bool emits = emitters_->topEmits(int(st));
      if (byPower && !emits) {
        if (partlyVisible(l, opt_.partialThreshold)) shadowPower[pair] += partialShadowPower(s, l);
        continue;
      }
      char bad = 0;
      markBadPair(bad, opt_.badLinks, l, emits, opt_.partialThreshold);
      if (bad) badPairs_.insert(pair);
    }
    if (byPower) {
      const double least = opt_.partialPowerShare * carriedPower(s, h_.topCount());
      for (const auto& [pair, power] : shadowPower)
        if (power >= least) badPairs_.insert(pair);
    }
    intervals_.addKey(std::move(values), k);
  }

  const Scene& scene_;
  const std::vector<double>& keyTimes_;
  size_t first_, last_;
  const SpaceTimeOptions& opt_;
  SpaceTimeReport& rep_;
  PatchHierarchy h_;
  size_t T_ = 0;
  std::vector<SurfaceProperties> surfaces_;
  // The lights among the tops (the light seam): which pairs are the lights' bad pairs. The
  // solve itself treats a polygon light as a patch with B_e (surfaces_).
  std::unique_ptr<SceneEmitters> emitters_;
  PlacedLamps prevLamps_;  // the lamps of the key solved last (reusableLampValues)
  std::unique_ptr<SceneVisibility> vis_;
  std::vector<KeyRecord> records_;   // per key first..last
  std::vector<uint32_t> nodeCount_;  // per key: h_.size() after its solve
  // The activity intervals so far, compacted as each key time finishes (memory: the compact
  // result, not every key's links).
  LinkIntervals intervals_;
  std::unordered_set<uint64_t> badPairs_;  // receiver top << 32 | shooter top
  ClusterTree clusters_;                   // empty without clustering
  std::vector<char> movingTops_;           // per top: moves during the key times (KeySolveInput)
  ClosedNodeCache closedCache_;  // coherence: static nodes' closed-room tests, all keys so far
};

// One per-node field of the key records as node i, key k at i * K + k (GlobalSolution's and
// KeyWindow's layout). A node made after key k, beyond its record, takes `absent` or, without
// it, its parent's value at k (a parent's index is below its children's: filled first).
template <class T>
std::vector<T> nodeByKey(const std::vector<KeyRecord>& records, std::vector<T> KeyRecord::*field,
                         const PatchHierarchy& h, std::optional<T> absent = std::nullopt) {
  const size_t N = size_t(h.size()), K = records.size();
  std::vector<T> out(N * K);
  for (size_t k = 0; k < K; ++k) {
    const std::vector<T>& v = records[k].*field;
    for (size_t i = 0; i < N; ++i)
      out[i * K + k] = i < v.size() ? v[i]
                       : absent     ? *absent
                                    : out[size_t(h.node(int(i)).parent) * K + k];
  }
  return out;
}

// Merge: radiosity per node and key; nodes created after key k take their ancestor's value.
void mergeNodeRadiosity(const std::vector<KeyRecord>& records, const PatchHierarchy& h,
                        GlobalSolution& g) {
  g.nodeRadiosity = nodeByKey(records, &KeyRecord::radiosity, h);
}

// Merge: the bad pairs as (receiver top, shooter top), sorted.
std::vector<std::pair<uint32_t, uint32_t>> sortedBadPairs(
    const std::unordered_set<uint64_t>& badPairs) {
  std::vector<uint64_t> sorted(badPairs.begin(), badPairs.end());
  std::sort(sorted.begin(), sorted.end());
  std::vector<std::pair<uint32_t, uint32_t>> out;
  for (uint64_t p : sorted) out.emplace_back(uint32_t(p >> 32), uint32_t(p & 0xffffffffu));
  return out;
}

// One activity interval as a GlobalLink, its samples appended to g.linkSample*.
GlobalLink globalLinkOf(const LinkIntervals& intervals, const LinkIntervals::Row& r, uint32_t rcv,
                        uint32_t sh, bool bad, GlobalSolution& g) {
  GlobalLink gl;
  gl.receiver = rcv;
  gl.shooter = sh;
  gl.firstKey = r.firstKey;
  gl.lastKey = r.lastKey;
  gl.sampleOffset = uint32_t(g.linkSampleKeys.size());
  if (r.constant) {
    g.linkSampleKeys.push_back(r.firstKey);
    g.linkSampleValues.push_back(r.firstFv);
    g.linkSampleVisibility.push_back(r.firstVisibility);
  } else {
    intervals.forEachKey(r, [&](uint32_t k, float fv, float v) {
      g.linkSampleKeys.push_back(k);
      g.linkSampleValues.push_back(fv);
      g.linkSampleVisibility.push_back(v);
    });
  }
  gl.sampleCount = uint32_t(g.linkSampleKeys.size()) - gl.sampleOffset;
  gl.flags = uint8_t((bad ? kLinkBad : 0) | (r.visibilityChanged ? kLinkVisibilityEvent : 0) |
                     (r.refined ? kLinkRefined : 0));
  return gl;
}

// Merge: the links, one row per activity interval (maximal run of consecutive keys, same
// refined flag), in ascending (receiver, shooter) order, rows in key order. Returns the
// good-link irradiance $H_i = \sum_j F_{ij} V_{ij} B_j$ gathered at each node i at each key
// (N x K, key-major), summed in that link order (the same whatever the thread count or the
// coherence). Ends the adding of `intervals`.
std::vector<glm::dvec3> mergeLinks(LinkIntervals& intervals,
                                   const std::unordered_set<uint64_t>& badPairs,
                                   const std::vector<KeyRecord>& records, const PatchHierarchy& h,
                                   GlobalSolution& g) {
  const size_t N = size_t(h.size()), K = records.size();
  std::vector<glm::dvec3> goodH(N * K, glm::dvec3(0.0));
  const std::vector<std::pair<uint64_t, uint32_t>> linkKeys = intervals.takeSortedLinks();
  size_t sampleTotal = 0;
  for (uint32_t i = 0; i < uint32_t(intervals.rowCount()); ++i)
    sampleTotal += LinkIntervals::sampleCount(intervals.row(i));
  g.links.reserve(intervals.rowCount());
  g.linkSampleKeys.reserve(sampleTotal);
  g.linkSampleValues.reserve(sampleTotal);
  g.linkSampleVisibility.reserve(sampleTotal);
  for (const auto& [key, firstRow] : linkKeys) {
    uint32_t rcv = uint32_t(key >> 32), sh = uint32_t(key & 0xffffffffu);
    bool bad = badPairs.count((uint64_t(h.node(int(rcv)).id.top) << 32) | h.node(int(sh)).id.top);
    for (uint32_t ri = firstRow; ri != LinkIntervals::kNone; ri = intervals.row(ri).nextRow) {
      const LinkIntervals::Row& r = intervals.row(ri);
      if (!bad && !r.refined)
        intervals.forEachKey(r, [&](uint32_t k, float fv, float) {
          const double e = records[k].exposure[rcv];  // the gather's division (exposure)
          if (e > 0.0) goodH[k * N + rcv] += double(fv) * glm::dvec3(records[k].radiosity[sh]) / e;
        });
      g.links.push_back(globalLinkOf(intervals, r, rcv, sh, bad, g));
    }
  }
  return goodH;
}

// Merge: good-link irradiance at the union leaves' vertices (Gouraud: a leaf's H is the sum of
// goodH over it and its ancestors times its good closure factor, averaged at each vertex over the
// leaves of the same top-level patch that share it), per leaf, key and corner. Also sets g.leafRow.
void mergeLeafVertexIrradiance(const std::vector<glm::dvec3>& goodH,
                               const std::vector<KeyRecord>& records, const PatchHierarchy& h,
                               GlobalSolution& g) {
  const size_t K = records.size();
  const size_t N = size_t(h.size());
  g.leafRow.assign(N, -1);
  std::vector<int> leaves;
  for (size_t i = 0; i < N; ++i)
    if (h.isLeaf(int(i))) {
      g.leafRow[i] = int32_t(leaves.size());
      leaves.push_back(int(i));
    }
  const size_t L = leaves.size();
  const LeafVertices lv = leafVerticesOf(h, leaves);
  g.leafVertexGoodIrradiance.assign(L * K * 4, glm::vec3(0.0f));
  std::vector<glm::dvec3> vertexSum(lv.vertexCount.size());
  for (size_t k = 0; k < K; ++k) {
    const glm::dvec3* nodeH = &goodH[k * N];
    std::fill(vertexSum.begin(), vertexSum.end(), glm::dvec3(0.0));
    for (size_t li = 0; li < L; ++li) {
      glm::dvec3 H(0.0);
      for (int a = leaves[li]; a >= 0; a = h.node(a).parent) H += nodeH[size_t(a)];
      int inKey = leaves[li];  // nodes made after key k take their ancestor's factor there
      while (size_t(inKey) >= records[k].goodClosure.size()) inKey = h.node(inKey).parent;
      H *= double(records[k].goodClosure[size_t(inKey)]);
      const PatchNode& n = h.node(leaves[li]);
      if (!records[k].clusterIrradiance.empty())  // cluster links: no closure factor
        H += glm::dvec3(records[k].clusterIrradiance[n.id.top]);
      for (int c = 0; c < (n.local.count == 3 ? 3 : 4); ++c)
        vertexSum[size_t(lv.leafVertex[li][size_t(c)])] += H;
    }
    for (size_t v = 0; v < vertexSum.size(); ++v)
      if (lv.vertexCount[v] > 0) vertexSum[v] /= double(lv.vertexCount[v]);
    for (const LeafVertices::Constraint& c : lv.constraints)
      vertexSum[size_t(c.vertex)] =
          (1.0 - c.t) * vertexSum[size_t(c.a)] + c.t * vertexSum[size_t(c.b)];
    for (size_t li = 0; li < L; ++li)
      for (int c = 0; c < 4; ++c)
        g.leafVertexGoodIrradiance[(li * K + k) * 4 + size_t(c)] =
            glm::vec3(vertexSum[size_t(lv.leafVertex[li][size_t(c)])]);
  }
}

// Merge: each node's exposure at each key (1 for nodes not in that key's tree), for the
// per-texel gather of rad-movies (good_link_gather.h), which divides as the solve did.
void mergeNodeExposure(const std::vector<KeyRecord>& records, const PatchHierarchy& h,
                       GlobalSolution& g) {
  g.nodeExposure = nodeByKey(records, &KeyRecord::exposure, h, std::optional<float>(1.0f));
}

// Merge: per top and key, the irradiance gathered through cluster links; left empty when no key
// has any (no clustering, or every cluster link refined down to patch links).
void mergeClusterIrradiance(const std::vector<KeyRecord>& records, size_t T, GlobalSolution& g) {
  const size_t K = records.size();
  bool any = false;
  for (const KeyRecord& r : records)
    for (const glm::vec3& h : r.clusterIrradiance) any = any || h != glm::vec3(0.0f);
  if (!any) return;
  g.topClusterIrradiance.assign(T * K, glm::vec3(0.0f));
  for (size_t k = 0; k < K; ++k)
    for (size_t t = 0; t < std::min(T, records[k].clusterIrradiance.size()); ++t)
      g.topClusterIrradiance[t * K + k] = records[k].clusterIrradiance[t];
}

}  // namespace

namespace {

// The final merge, the same whether the key-time pass ran whole (solveSpaceTime) or in windows
// (mergeKeyWindows): node radiosity and exposure per key, bad pairs, cluster irradiance, link
// rows with their F·V samples, the good-link irradiance at the union leaves' vertices.
GlobalSolution mergeKeyTimes(KeyPassResult& pass, const std::vector<double>& keyTimes,
                             SpaceTimeReport& rep) {
  auto tMerge = std::chrono::steady_clock::now();
  GlobalSolution g;
  g.keyTimes = keyTimes;
  mergeNodeRadiosity(pass.records, pass.hierarchy, g);
  mergeNodeExposure(pass.records, pass.hierarchy, g);
  g.badPairs = sortedBadPairs(pass.badPairs);
  mergeClusterIrradiance(pass.records, size_t(pass.hierarchy.topCount()), g);
  std::vector<glm::dvec3> goodH =
      mergeLinks(pass.intervals, pass.badPairs, pass.records, pass.hierarchy, g);
  pass.intervals = LinkIntervals();  // its memory back before the leaf arrays
  mergeLeafVertexIrradiance(goodH, pass.records, pass.hierarchy, g);
  rep.unionNodes = size_t(pass.hierarchy.size());
  g.hierarchy = std::move(pass.hierarchy);
  g.validate("rad-global");
  rep.secondsMerge = secondsSince(tMerge);
  rep.linkRows = g.links.size();
  rep.badPairs = g.badPairs.size();
  return g;
}

// A window's rows: its links' activity intervals in ascending (receiver, shooter) order, rows
// in key order, each with one value when every key has the first one's bits, else one per key.
// Ends the adding of `intervals`.
void windowLinksOf(LinkIntervals& intervals, KeyWindow& w) {
  for (const auto& [link, firstRow] : intervals.takeSortedLinks())
    for (uint32_t ri = firstRow; ri != LinkIntervals::kNone; ri = intervals.row(ri).nextRow) {
      const LinkIntervals::Row& r = intervals.row(ri);
      GlobalLink l;
      l.receiver = uint32_t(link >> 32);
      l.shooter = uint32_t(link & 0xffffffffu);
      l.firstKey = r.firstKey;
      l.lastKey = r.lastKey;
      l.sampleOffset = uint32_t(w.linkValues.size());
      l.flags = r.refined ? kLinkRefined : 0;
      auto keep = [&](uint32_t, float fv, float v) {
        w.linkValues.push_back(fv);
        w.linkVisibility.push_back(v);
      };
      if (LinkIntervals::sameBitsThroughout(r))
        keep(r.firstKey, r.firstFv, r.firstVisibility);
      else
        intervals.forEachKey(r, keep);
      l.sampleCount = uint32_t(w.linkValues.size()) - l.sampleOffset;
      w.links.push_back(l);
    }
}

// Which window each key of the run comes from: the first, in `order` (by first key), that holds
// it. Throws naming the window beside a gap when a key is in none.
std::vector<size_t> keyOwners(const std::vector<KeyWindow>& windows,
                              const std::vector<size_t>& order,
                              const std::vector<std::string>& names,
                              const std::vector<double>& keyTimes) {
  const size_t K = keyTimes.size();
  constexpr size_t kNoWindow = ~size_t(0);
  std::vector<size_t> owner(K, kNoWindow);
  for (size_t w : order)
    for (size_t k = windows[w].firstKey; k < windows[w].firstKey + windows[w].keyCount(); ++k)
      if (owner[k] == kNoWindow) owner[k] = w;
  for (size_t k = 0; k < K; ++k) {
    if (owner[k] != kNoWindow) continue;
    size_t end = k;
    while (end + 1 < K && owner[end + 1] == kNoWindow) ++end;
    const std::string missing =
        (k == end ? "key " + std::to_string(k)
                  : "keys " + std::to_string(k) + "-" + std::to_string(end)) +
        " of the run's " + std::to_string(K) + " (t = " + numberText(keyTimes[k]) +
        (k == end ? "" : " .. " + numberText(keyTimes[end])) + " s)";
    // Named: the window before the gap, or the first one when the gap opens the run.
    const size_t beside = k > 0 ? owner[k - 1] : order.front();
    const KeyWindow& b = windows[beside];
    throw inputError(names[beside],
                     missing + (k == end ? " is" : " are") + " in none of the " +
                         std::to_string(windows.size()) + " windows; this one " +
                         (k > 0 ? "ends at key " + std::to_string(b.firstKey + b.keyCount() - 1)
                                : "starts at key " + std::to_string(b.firstKey)));
  }
  return owner;
}

// Windows that share a key must hold the same solution there (the same run's windows do, bit
// for bit): compared on the top-level patches' radiosity and exposure, which every solve change
// reaches.
void checkSharedKeys(const std::vector<KeyWindow>& windows, const std::vector<size_t>& owner,
                     const std::vector<std::string>& names, size_t T) {
  for (size_t w = 0; w < windows.size(); ++w) {
    const KeyWindow& a = windows[w];
    for (size_t ka = 0; ka < a.keyCount(); ++ka) {
      const size_t k = a.firstKey + ka;
      if (owner[k] == w) continue;
      const KeyWindow& b = windows[owner[k]];
      const size_t kb = k - b.firstKey;
      for (size_t t = 0; t < T; ++t)
        if (std::memcmp(&a.radiosity[t * a.keyCount() + ka], &b.radiosity[t * b.keyCount() + kb],
                        sizeof(glm::vec3)) != 0 ||
            std::memcmp(&a.exposure[t * a.keyCount() + ka], &b.exposure[t * b.keyCount() + kb],
                        sizeof(float)) != 0)
          throw inputError(names[w], "key " + std::to_string(k) +
                                         " (t = " + numberText(a.keyTimes[ka]) +
                                         " s) differs from " + names[owner[k]] +
                                         "'s: the windows were not computed alike");
    }
  }
}

// Replays the windows' subdivisions key by key into `h` (the tops alone at first): key k's new
// nodes, in the order its solve made them, are made where `h` does not have them yet, which is
// the whole run's order (a key splits the same nodes in the same order whatever the union
// before it). Returns per key the node count after it.
std::vector<uint32_t> replaySubdivisions(const std::vector<KeyWindow>& windows,
                                         const std::vector<size_t>& owner,
                                         const std::vector<std::string>& names, PatchHierarchy& h) {
  std::vector<uint32_t> count(owner.size());
  for (size_t k = 0; k < owner.size(); ++k) {
    const KeyWindow& w = windows[owner[k]];
    const size_t kw = k - w.firstKey;
    const uint32_t begin = kw > 0 ? w.nodeCount[kw - 1] : uint32_t(w.hierarchy.topCount());
    for (uint32_t i = begin; i < w.nodeCount[kw]; i += 4) {
      const int p = h.find(w.hierarchy.node(w.hierarchy.node(int(i)).parent).id);
      if (p < 0)
        throw inputError(names[owner[k]], "node " + std::to_string(i) + " made at key " +
                                              std::to_string(k) +
                                              " has a parent no key before it made");
      if (h.isLeaf(p)) h.subdivide(p);
    }
    count[k] = uint32_t(h.size());
  }
  return count;
}

// Per node of `of`, its dense index in `in`, -1 where `in` has no such node.
std::vector<int> nodeIndices(const PatchHierarchy& of, const PatchHierarchy& in) {
  std::vector<int> out(size_t(of.size()));
  for (int i = 0; i < of.size(); ++i) out[size_t(i)] = in.find(of.node(i).id);
  return out;
}

// Key k's record over the merged hierarchy's first `count` nodes from window w's key kw: its
// node's values where the window has the node; elsewhere (a node the window never made, not
// in the key's tree) the parent's B and closure factor and exposure 1, as the whole run's.
KeyRecord recordOf(const KeyWindow& w, size_t kw, const std::vector<int>& windowIndex,
                   const PatchHierarchy& h, uint32_t count) {
  const size_t K = w.keyCount();
  KeyRecord r;
  r.radiosity.resize(count);
  r.exposure.resize(count);
  r.goodClosure.resize(count);
  for (size_t i = 0; i < count; ++i) {
    const int wi = windowIndex[i];
    const size_t parent = size_t(h.node(int(i)).parent);  // filled first (a lower index)
    r.radiosity[i] = wi >= 0 ? w.radiosity[size_t(wi) * K + kw] : r.radiosity[parent];
    r.exposure[i] = wi >= 0 ? w.exposure[size_t(wi) * K + kw] : 1.0f;
    r.goodClosure[i] = wi >= 0 ? w.goodClosure[size_t(wi) * K + kw] : r.goodClosure[parent];
  }
  if (!w.clusterIrradiance.empty()) {
    const size_t T = size_t(h.topCount());
    r.clusterIrradiance.resize(T);
    for (size_t t = 0; t < T; ++t) r.clusterIrradiance[t] = w.clusterIrradiance[t * K + kw];
  }
  return r;
}

// Re-adds window w's link values at the keys it owns to `intervals`, key by key (the windows
// are taken in order of their first keys, so the keys keep increasing): the rows that span
// windows join as in the whole run.
void addWindowLinks(const KeyWindow& w, size_t self, const std::vector<size_t>& owner,
                    const std::vector<int>& mergedIndex, const std::vector<uint32_t>& count,
                    const std::string& name, LinkIntervals& intervals) {
  for (uint32_t kw = 0; kw < uint32_t(w.keyCount()); ++kw) {
    const size_t k = w.firstKey + kw;
    if (owner[k] != self) continue;
    std::vector<LinkIntervals::KeyValue> values;
    for (size_t li = 0; li < w.links.size(); ++li) {
      const GlobalLink& l = w.links[li];
      if (kw < l.firstKey || kw > l.lastKey) continue;
      const int rcv = mergedIndex[l.receiver], sh = mergedIndex[l.shooter];
      if (rcv < 0 || sh < 0 || uint32_t(rcv) >= count[k] || uint32_t(sh) >= count[k])
        throw inputError(name, "link row " + std::to_string(li) + " names a node key " +
                                   std::to_string(k) + " does not have");
      const uint32_t j = l.sampleOffset + (l.sampleCount == 1 ? 0 : kw - l.firstKey);
      values.push_back({LinkIntervals::linkOf(rcv, sh), w.linkValues[j], w.linkVisibility[j],
                        (l.flags & kLinkRefined) != 0});
    }
    intervals.addKey(std::move(values), uint32_t(k));
  }
}

}  // namespace

GlobalSolution solveSpaceTime(const Scene& scene, const std::vector<double>& keyTimes,
                              const SpaceTimeOptions& opt, SpaceTimeReport* report) {
  SpaceTimeReport localReport;
  SpaceTimeReport& rep = report ? *report : localReport;
  if (keyTimes.empty()) throw Error(ExitCode::kUsage, "", "no key times");
  KeyTimePass pass(scene, keyTimes, 0, keyTimes.size() - 1, opt, rep);
  pass.run();
  KeyPassResult result = pass.take();
  return mergeKeyTimes(result, keyTimes, rep);
}

KeyWindow solveKeyWindow(const Scene& scene, const std::vector<double>& keyTimes, size_t firstKey,
                         size_t lastKey, const SpaceTimeOptions& opt, SpaceTimeReport* report) {
  SpaceTimeReport localReport;
  SpaceTimeReport& rep = report ? *report : localReport;
  if (firstKey > lastKey || lastKey >= keyTimes.size())
    throw Error(ExitCode::kUsage, "",
                "key window " + std::to_string(firstKey) + "-" + std::to_string(lastKey) +
                    " is not within the " + std::to_string(keyTimes.size()) + " key times");
  KeyTimePass pass(scene, keyTimes, firstKey, lastKey, opt, rep);
  pass.run();
  KeyPassResult r = pass.take();
  auto tPack = std::chrono::steady_clock::now();
  KeyWindow w;
  w.firstKey = uint32_t(firstKey);
  w.keyTimes.assign(keyTimes.begin() + long(firstKey), keyTimes.begin() + long(lastKey) + 1);
  w.nodeCount = std::move(r.nodeCount);
  w.radiosity = nodeByKey(r.records, &KeyRecord::radiosity, r.hierarchy);
  w.exposure = nodeByKey(r.records, &KeyRecord::exposure, r.hierarchy, std::optional<float>(1.0f));
  w.goodClosure = nodeByKey(r.records, &KeyRecord::goodClosure, r.hierarchy);
  const size_t T = size_t(r.hierarchy.topCount()), K = w.keyCount();
  if (!r.records.front().clusterIrradiance.empty()) {  // the same at every key (the run's tree)
    w.clusterIrradiance.assign(T * K, glm::vec3(0.0f));
    for (size_t k = 0; k < K; ++k)
      for (size_t t = 0; t < std::min(T, r.records[k].clusterIrradiance.size()); ++t)
        w.clusterIrradiance[t * K + k] = r.records[k].clusterIrradiance[t];
  }
  windowLinksOf(r.intervals, w);
  w.badPairs = sortedBadPairs(r.badPairs);
  w.hierarchy = std::move(r.hierarchy);
  w.reports = rep.keys;
  rep.unionNodes = size_t(w.hierarchy.size());
  rep.linkRows = w.links.size();
  rep.badPairs = w.badPairs.size();
  w.validate("rad-global");
  rep.secondsMerge = secondsSince(tPack);
  return w;
}

GlobalSolution mergeKeyWindows(const Scene& scene, const std::vector<double>& keyTimes,
                               std::vector<KeyWindow> windows,
                               const std::vector<std::string>& names, SpaceTimeReport* report) {
  SpaceTimeReport localReport;
  SpaceTimeReport& rep = report ? *report : localReport;
  auto tMerge = std::chrono::steady_clock::now();
  if (windows.empty() || names.size() != windows.size())
    throw Error(ExitCode::kUsage, "", "no key windows to merge");
  KeyPassResult pass;
  pass.hierarchy = PatchHierarchy(scene.inputPolygons());
  const size_t K = keyTimes.size(), T = size_t(pass.hierarchy.topCount());
  for (size_t w = 0; w < windows.size(); ++w) {
    const KeyWindow& win = windows[w];
    win.validate(names[w]);
    if (size_t(win.hierarchy.topCount()) != T)
      throw inputError(names[w], "has " + std::to_string(win.hierarchy.topCount()) +
                                     " top-level patches; this scene has " + std::to_string(T));
    if (win.firstKey + win.keyCount() > K ||
        !std::equal(win.keyTimes.begin(), win.keyTimes.end(), keyTimes.begin() + win.firstKey))
      throw inputError(names[w], "its key times are not this run's keys " +
                                     std::to_string(win.firstKey) +
                                     ".. (another --frames, --fps "
                                     "or --key-step?)");
  }
  std::vector<size_t> order(windows.size());
  for (size_t w = 0; w < order.size(); ++w) order[w] = w;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return windows[a].firstKey < windows[b].firstKey; });
  const std::vector<size_t> owner = keyOwners(windows, order, names, keyTimes);
  checkSharedKeys(windows, owner, names, T);

  const std::vector<uint32_t> count = replaySubdivisions(windows, owner, names, pass.hierarchy);
  pass.records.resize(K);
  for (size_t w : order) {
    const KeyWindow& win = windows[w];
    const std::vector<int> windowIndex = nodeIndices(pass.hierarchy, win.hierarchy);
    for (size_t kw = 0; kw < win.keyCount(); ++kw)
      if (owner[win.firstKey + kw] == w)
        pass.records[win.firstKey + kw] =
            recordOf(win, kw, windowIndex, pass.hierarchy, count[win.firstKey + kw]);
    addWindowLinks(win, w, owner, nodeIndices(win.hierarchy, pass.hierarchy), count, names[w],
                   pass.intervals);
    for (const auto& [r, s] : win.badPairs) pass.badPairs.insert((uint64_t(r) << 32) | s);
    for (size_t kw = 0; kw < win.keyCount() && win.reports.size() == win.keyCount(); ++kw)
      if (owner[win.firstKey + kw] == w) rep.keys.push_back(win.reports[kw]);
    windows[w] = KeyWindow();  // its memory back
  }
  rep.topPatches = T;
  GlobalSolution g = mergeKeyTimes(pass, keyTimes, rep);
  rep.secondsMerge = secondsSince(tMerge);
  return g;
}

}  // namespace rad
