// Space-time hierarchical radiosity: key-time solves, coherence, merge (see the header).
#include "libcommon/radiosity/space_time_radiosity.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <map>
#include <memory>
#include <unordered_map>

#include "libcommon/core/error.h"

namespace rad {

namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// What the merge needs of one key-time solve besides its links (which go straight into the
// LinkIntervals store as each key finishes).
struct KeyRecord {
  std::vector<glm::vec3> radiosity;  // per node of the union hierarchy at that time (push-down)
};

// The links' activity intervals (paper §4.2), built incrementally as each key time finishes so
// that memory holds the compact result, not every key's links: per link, its rows (maximal runs
// of consecutive keys with the same refined flag) and, for a row whose F·V changes, its F·V at
// every key of the run. A row whose F·V has not changed (yet) keeps only its first value; when
// it first changes, the run so far is written out as copies of that value. The rows and their
// values are exactly those of GlobalSolution::links / linkSample* (keys are implied: a row's
// samples are at firstKey..lastKey, or only at firstKey when constant).
class LinkIntervals {
 public:
  static constexpr uint32_t kNone = ~uint32_t(0);

  struct Row {
    uint32_t firstKey = 0, lastKey = 0;
    float firstFv = 0, firstVisibility = 0;
    // F·V at every key of the run once one differed from firstFv (in its bits), else none.
    uint32_t firstBlock = kNone, lastBlock = kNone;
    uint32_t valueCount = 0;
    uint32_t nextRow = kNone;  // the same link's next row (later keys)
    bool refined = false, constant = true, visibilityChanged = false;
  };

  // The link's value at key `key`; keys arrive in non-decreasing order.
  void add(uint64_t link, uint32_t key, float fv, float visibility, bool refined) {
    auto [it, fresh] = links_.try_emplace(link, LinkRows{kNone, kNone});
    LinkRows& lr = it->second;
    if (!fresh) {
      Row& r = rows_[lr.last];
      if (r.lastKey + 1 == key && r.refined == refined) {  // the run goes on
        r.lastKey = key;
        r.visibilityChanged |= visibility != r.firstVisibility;
        r.constant &= fv == r.firstFv;
        // Values are kept from the first one that differs in its bits (F·V changed, or only
        // the sign of a zero: such a row stays constant, but its values are kept exact).
        if (r.valueCount == 0 && (!r.constant || !sameBits(fv, r.firstFv)))
          for (uint32_t k = r.firstKey; k < key; ++k) append(r, r.firstFv);
        if (r.valueCount > 0) append(r, fv);
        return;
      }
    }
    // A new row: the link's first, or a gap / a change of the refined flag ends the last one.
    Row r;
    r.firstKey = r.lastKey = key;
    r.firstFv = fv;
    r.firstVisibility = visibility;
    r.refined = refined;
    uint32_t index = uint32_t(rows_.size());
    rows_.push_back(r);
    if (fresh)
      lr.first = index;
    else
      rows_[lr.last].nextRow = index;
    lr.last = index;
  }

  // (link, first row) in ascending link order. Ends the adding (the link index is freed).
  std::vector<std::pair<uint64_t, uint32_t>> takeSortedLinks() {
    std::vector<std::pair<uint64_t, uint32_t>> v;
    v.reserve(links_.size());
    for (const auto& [key, lr] : links_) v.emplace_back(key, lr.first);
    std::unordered_map<uint64_t, LinkRows>().swap(links_);
    std::sort(v.begin(), v.end());
    return v;
  }
  const Row& row(uint32_t i) const { return rows_[i]; }
  size_t rowCount() const { return rows_.size(); }
  // The samples a row contributes to GlobalSolution::linkSample*.
  static uint32_t sampleCount(const Row& r) { return r.constant ? 1 : r.valueCount; }
  // Calls f(key, fv) for every key of the row's run.
  template <class F>
  void forEachKey(const Row& r, F&& f) const {
    if (r.valueCount == 0) {  // every value had the bits of the first
      for (uint32_t k = r.firstKey; k <= r.lastKey; ++k) f(k, r.firstFv);
      return;
    }
    uint32_t k = r.firstKey, left = r.valueCount;
    for (uint32_t b = r.firstBlock; b != kNone && left > 0; b = block(b).next) {
      const Block& blk = block(b);
      for (uint32_t j = 0; j < kBlockValues && left > 0; ++j, --left) f(k++, blk.values[j]);
    }
  }

 private:
  // Values live in fixed-size blocks chained per row, allocated from slabs that never move: no
  // per-link vector slack and no reallocation copies (a row wastes less than one block).
  static constexpr uint32_t kBlockValues = 15;
  struct Block {
    float values[kBlockValues];
    uint32_t next;
  };
  static bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }
  static constexpr uint32_t kSlabShift = 14;  // 16384 blocks of 64 bytes: 1 MiB slabs
  struct LinkRows {
    uint32_t first, last;
  };

  Block& block(uint32_t i) { return slabs_[i >> kSlabShift][i & ((1u << kSlabShift) - 1)]; }
  const Block& block(uint32_t i) const {
    return slabs_[i >> kSlabShift][i & ((1u << kSlabShift) - 1)];
  }
  uint32_t newBlock() {
    if ((blockCount_ >> kSlabShift) >= slabs_.size())
      slabs_.push_back(std::make_unique<Block[]>(size_t(1) << kSlabShift));
    uint32_t i = blockCount_++;
    block(i).next = kNone;
    return i;
  }
  void append(Row& r, float fv) {
    uint32_t slot = r.valueCount % kBlockValues;
    if (slot == 0) {
      uint32_t b = newBlock();
      if (r.lastBlock == kNone)
        r.firstBlock = b;
      else
        block(r.lastBlock).next = b;
      r.lastBlock = b;
    }
    block(r.lastBlock).values[slot] = fv;
    ++r.valueCount;
  }

  std::unordered_map<uint64_t, LinkRows> links_;
  std::vector<Row> rows_;
  std::vector<std::unique_ptr<Block[]>> slabs_;
  uint32_t blockCount_ = 0;
};

// Radiosity of every node, nodes outside the key's tree taking their parent's value.
std::vector<glm::dvec3> pushedDown(const KeySolution& s, const PatchHierarchy& h) {
  std::vector<glm::dvec3> b(s.radiosity.begin(), s.radiosity.end());
  b.resize(size_t(h.size()), glm::dvec3(0.0));
  for (int i = 0; i < h.size(); ++i)
    if (size_t(i) >= s.split.size() || !s.inTree(i, h)) b[size_t(i)] = b[size_t(h.node(i).parent)];
  return b;
}

}  // namespace

BadLinkRule parseBadLinkRule(const std::string& s) {
  if (s == "lights") return BadLinkRule::kLights;
  if (s == "partial") return BadLinkRule::kPartial;
  if (s == "all") return BadLinkRule::kAll;
  if (s == "none") return BadLinkRule::kNone;
  throw Error(ExitCode::kUsage, "--bad-links",
              "expected lights, partial, all or none, got '" + s + "'");
}

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
  // Per mesh node: static over [t0, t1]? Dynamic ones contribute their swept bounds.
  std::unordered_map<int, bool> dynamic;
  std::vector<std::array<glm::dvec3, 2>> swept;
  for (int node : scene.meshNodes()) {
    bool d = scene.isDynamic(node, t0, t1);
    dynamic[node] = d;
    if (d) swept.push_back(scene.sweptBounds(node, t0, t1));
  }
  auto isStatic = [&](int top) {
    int node = h.top(top).node;
    auto it = dynamic.find(node);
    return node < 0 || it == dynamic.end() || !it->second;
  };
  LinkCache cache;
  cache.reserve(prev.links.size());
  for (const SolverLink& l : prev.links) {
    const PatchNode& r = h.node(l.receiver);
    const PatchNode& s = h.node(l.shooter);
    // A moving end changes the geometry: nothing of the link is known.
    if (!isStatic(int(r.id.top)) || !isStatic(int(s.id.top))) continue;
    bool hit = false;
    for (const auto& box : swept)
      if (shaftMeetsBox(prev.world[size_t(l.receiver)], prev.world[size_t(l.shooter)], box[0],
                        box[1])) {
        hit = true;
        break;
      }
    CachedLink c;
    c.estimate = l.estimate;
    c.spreadArea = l.spreadArea;
    // computeAccurate leaves F at the estimate for a link it finds invisible
    c.formFactor = l.accurate && l.visibility > 0.0 ? l.formFactor : -1.0;
    c.visibility = l.visibility;
    c.visibilityValid = !hit;  // a moving object in the shaft: the shadow rays again
    cache.emplace(std::make_pair(r.id.packed(), s.id.packed()), c);
  }
  return cache;
}

GlobalSolution solveSpaceTime(const Scene& scene, const std::vector<double>& keyTimes,
                              const SpaceTimeOptions& opt, SpaceTimeReport* report) {
  SpaceTimeReport localReport;
  SpaceTimeReport& rep = report ? *report : localReport;
  const size_t K = keyTimes.size();
  if (K == 0) throw Error(ExitCode::kUsage, "", "no key times");
  auto tSetup = std::chrono::steady_clock::now();
  PatchHierarchy h(scene.inputPolygons());
  if (h.topCount() == 0) throw inputError(scene.path, "has no polygons");
  const int T = h.topCount();
  std::vector<SurfaceProperties> surfaces = surfacePropertiesOf(scene, h);
  SceneVisibility vis(scene, h, keyTimes.front(), keyTimes.back());
  rep.secondsSetup = secondsSince(tSetup);

  std::vector<KeyRecord> records(K);
  // Per link (receiver << 32 | shooter): its activity intervals so far, compacted as each key
  // time finishes (memory: the compact result, not every key's links).
  LinkIntervals intervals;
  std::vector<char> badPair(size_t(T) * size_t(T), 0);  // paper §3.1, over all key times
  KeySolution prev;
  for (size_t k = 0; k < K; ++k) {
    double t = keyTimes[k];
    vis.setTime(t);
    KeySolveInput in;
    in.topToWorld = topTransforms(scene, h, t);
    in.visibility = &vis.visibility();
    KeyTimeReport kr;
    kr.time = t;
    LinkCache cache;
    if (opt.coherence && k > 0) {
      auto tc = std::chrono::steady_clock::now();
      cache = reusableLinks(prev, h, scene, keyTimes[k - 1], t);
      in.reuse = &cache;
      kr.secondsCoherence = secondsSince(tc);
    }
    KeySolution s = solveKeyTime(h, surfaces, in, opt.radiosity);
    kr.links = s.links.size();
    kr.recomputed = s.linksComputed;
    kr.reused = s.linksReused;
    kr.visibilityOnly = s.linksVisibilityOnly;
    kr.iterations = s.iterations;
    kr.refineRounds = s.refineRounds;
    kr.secondsLinks = s.secondsLinks;
    kr.secondsSolve = s.secondsSolve;
    for (int i = 0; i < h.size(); ++i) kr.nodes += s.inTree(i, h) ? 1 : 0;
    rep.keys.push_back(kr);
    if (opt.onKeySolved) opt.onKeySolved();

    KeyRecord& rec = records[k];
    for (const SolverLink& l : s.links) {
      intervals.add((uint64_t(uint32_t(l.receiver)) << 32) | uint32_t(l.shooter), uint32_t(k),
                    float(l.fv()), float(l.visibility), l.refined);
      // Bad pairs: by shooter top (and partial visibility).
      uint32_t rt = h.node(l.receiver).id.top, st = h.node(l.shooter).id.top;
      char& bad = badPair[size_t(rt) * size_t(T) + st];
      switch (opt.badLinks) {
        case BadLinkRule::kNone:
          break;
        case BadLinkRule::kAll:
          bad = 1;
          break;
        case BadLinkRule::kLights:
          bad |= surfaces[st].isEmitter();
          break;
        case BadLinkRule::kPartial:
          bad |= surfaces[st].isEmitter() ||
                 (!l.refined && float(l.visibility) > opt.partialThreshold &&
                  float(l.visibility) < 1.0f);
          break;
      }
    }
    std::vector<glm::dvec3> b = pushedDown(s, h);
    rec.radiosity.assign(b.begin(), b.end());
    prev = std::move(s);
  }

  // ---- merge into the union hierarchy
  auto tMerge = std::chrono::steady_clock::now();
  const size_t N = size_t(h.size());
  GlobalSolution g;
  g.keyTimes = keyTimes;
  // Radiosity per node and key; nodes created after key k take their ancestor's value there.
  g.nodeRadiosity.assign(N * K, glm::vec3(0.0f));
  for (size_t k = 0; k < K; ++k) {
    const KeyRecord& rec = records[k];
    for (size_t i = 0; i < N; ++i) {
      glm::vec3 b = i < rec.radiosity.size()
                        ? rec.radiosity[i]
                        : g.nodeRadiosity[size_t(h.node(int(i)).parent) * K + k];
      g.nodeRadiosity[i * K + k] = b;
    }
  }

  for (uint32_t r = 0; r < uint32_t(T); ++r)
    for (uint32_t s = 0; s < uint32_t(T); ++s)
      if (badPair[size_t(r) * size_t(T) + s]) g.badPairs.emplace_back(r, s);

  // Links: one row per activity interval (maximal run of consecutive keys, same refined flag),
  // in ascending (receiver, shooter) order, rows in key order. Good-link irradiance gathered at
  // each node at each key, summed in that link order (the same whatever the thread count or
  // the coherence).
  std::vector<glm::dvec3> goodH(N * K, glm::dvec3(0.0));
  {
    const std::vector<std::pair<uint64_t, uint32_t>> linkKeys = intervals.takeSortedLinks();
    size_t sampleTotal = 0;
    for (uint32_t i = 0; i < uint32_t(intervals.rowCount()); ++i)
      sampleTotal += LinkIntervals::sampleCount(intervals.row(i));
    g.links.reserve(intervals.rowCount());
    g.linkSampleKeys.reserve(sampleTotal);
    g.linkSampleValues.reserve(sampleTotal);
    for (const auto& [key, firstRow] : linkKeys) {
      uint32_t rcv = uint32_t(key >> 32), sh = uint32_t(key & 0xffffffffu);
      bool bad = badPair[size_t(h.node(int(rcv)).id.top) * size_t(T) + h.node(int(sh)).id.top];
      for (uint32_t ri = firstRow; ri != LinkIntervals::kNone; ri = intervals.row(ri).nextRow) {
        const LinkIntervals::Row& r = intervals.row(ri);
        if (!bad && !r.refined)
          intervals.forEachKey(r, [&](uint32_t k, float fv) {
            goodH[k * N + rcv] += double(fv) * glm::dvec3(records[k].radiosity[sh]);
          });
        GlobalLink gl;
        gl.receiver = rcv;
        gl.shooter = sh;
        gl.firstKey = r.firstKey;
        gl.lastKey = r.lastKey;
        gl.sampleOffset = uint32_t(g.linkSampleKeys.size());
        if (r.constant) {
          g.linkSampleKeys.push_back(r.firstKey);
          g.linkSampleValues.push_back(r.firstFv);
        } else {
          intervals.forEachKey(r, [&](uint32_t k, float fv) {
            g.linkSampleKeys.push_back(k);
            g.linkSampleValues.push_back(fv);
          });
        }
        gl.sampleCount = uint32_t(g.linkSampleKeys.size()) - gl.sampleOffset;
        gl.flags = uint8_t((bad ? kLinkBad : 0) | (r.visibilityChanged ? kLinkVisibilityEvent : 0) |
                           (r.refined ? kLinkRefined : 0));
        g.links.push_back(gl);
      }
    }
  }
  intervals = LinkIntervals();  // its memory back before the leaf arrays

  // Good-link irradiance at the union leaves' vertices (Gouraud: averaged over the leaves of
  // the same top-level patch that share the vertex, in exact dyadic top-level (u,v)).
  g.leafRow.assign(N, -1);
  std::vector<int> leaves;
  for (size_t i = 0; i < N; ++i)
    if (h.isLeaf(int(i))) {
      g.leafRow[i] = int32_t(leaves.size());
      leaves.push_back(int(i));
    }
  const size_t L = leaves.size();
  std::vector<std::array<int, 4>> leafVertex(L);  // vertex index per corner
  std::vector<int> vertexCount;
  {
    std::vector<std::map<std::pair<double, double>, int>> perTop(static_cast<size_t>(T));
    for (size_t li = 0; li < L; ++li) {
      const PatchNode& n = h.node(leaves[li]);
      bool tri = n.local.count == 3;
      const glm::dvec2 corners[4] = {
          {0, 0}, {1, 0}, tri ? glm::dvec2(0, 1) : glm::dvec2(1, 1), {0, 1}};
      for (int c = 0; c < 4; ++c) {
        if (tri && c == 3) {
          leafVertex[li][3] = leafVertex[li][0];
          continue;
        }
        glm::dvec2 uv = topUvFromNodeUv(n.id, corners[c], tri);
        auto [it, fresh] =
            perTop[n.id.top].emplace(std::make_pair(uv.x, uv.y), int(vertexCount.size()));
        if (fresh) vertexCount.push_back(0);
        leafVertex[li][size_t(c)] = it->second;
        vertexCount[size_t(it->second)]++;
      }
    }
  }
  g.leafVertexGoodIrradiance.assign(L * K * 4, glm::vec3(0.0f));
  std::vector<glm::dvec3> leafH(L), vertexSum(vertexCount.size());
  for (size_t k = 0; k < K; ++k) {
    const glm::dvec3* nodeH = &goodH[k * N];
    std::fill(vertexSum.begin(), vertexSum.end(), glm::dvec3(0.0));
    for (size_t li = 0; li < L; ++li) {
      glm::dvec3 H(0.0);
      for (int a = leaves[li]; a >= 0; a = h.node(a).parent) H += nodeH[size_t(a)];
      leafH[li] = H;
      const PatchNode& n = h.node(leaves[li]);
      for (int c = 0; c < (n.local.count == 3 ? 3 : 4); ++c)
        vertexSum[size_t(leafVertex[li][size_t(c)])] += H;
    }
    for (size_t li = 0; li < L; ++li)
      for (int c = 0; c < 4; ++c) {
        int v = leafVertex[li][size_t(c)];
        g.leafVertexGoodIrradiance[(li * K + k) * 4 + size_t(c)] =
            glm::vec3(vertexSum[size_t(v)] / double(vertexCount[size_t(v)]));
      }
  }
  g.hierarchy = std::move(h);
  g.validate("rad-global");
  rep.secondsMerge = secondsSince(tMerge);
  rep.unionNodes = N;
  rep.linkRows = g.links.size();
  rep.badPairs = g.badPairs.size();
  return g;
}

}  // namespace rad
