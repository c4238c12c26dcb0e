// Texture-movie baking (paper §3.1 and §5). Sources and the formula in texture_movie_baker.h.
#include "libcommon/movies/texture_movie_baker.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <unordered_map>

#include <unistd.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "libcommon/core/error.h"
#include "libcommon/radiosity/form_factor.h"

namespace rad {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

struct Box {
  glm::dvec3 lo{std::numeric_limits<double>::infinity()};
  glm::dvec3 hi{-std::numeric_limits<double>::infinity()};
  void grow(const glm::dvec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void grow(const Polygon& p) {
    for (int k = 0; k < p.count; ++k) grow(p.v[k]);
  }
  bool overlaps(const Box& o) const {
    return lo.x <= o.hi.x && o.lo.x <= hi.x && lo.y <= o.hi.y && o.lo.y <= hi.y && lo.z <= o.hi.z &&
           o.lo.z <= hi.z;
  }
};

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

void appendTriangles(const Polygon& p, std::vector<BlockerTriangle>& out) {
  for (int i = 1; i + 1 < p.count; ++i) out.push_back({p.v[0], p.v[i], p.v[i + 1]});
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

// A moving pair's per-key form factors, computed ahead of the keys to find their largest value,
// are spilled to an unlinked temporary file and read back when their key is baked: the page
// cache holds them (the kernel writes them out under memory pressure), not the process, and
// reading them back costs far less than recomputing. Any failure (no temporary directory, a
// full disk) only means the set is recomputed: same values, bit for bit.
class FormFactorSpill {
 public:
  FormFactorSpill() = default;
  FormFactorSpill(const FormFactorSpill&) = delete;
  FormFactorSpill& operator=(const FormFactorSpill&) = delete;
  ~FormFactorSpill() {
    if (file_) std::fclose(file_);
  }
  // Offset of the stored set, or -1 when it could not be stored.
  long long put(const std::vector<double>& f) {
    if (failed_) return -1;
    if (!file_ && !(file_ = std::tmpfile())) {
      failed_ = true;
      return -1;
    }
    const char* p = reinterpret_cast<const char*>(f.data());
    size_t left = f.size() * sizeof(double);
    long long at = size_;
    off_t offset = off_t(size_);
    while (left > 0) {
      ssize_t n = ::pwrite(fileno(file_), p, left, offset);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        failed_ = true;
        return -1;
      }
      p += n;
      left -= size_t(n);
      offset += n;
    }
    size_ += (long long)(f.size() * sizeof(double));
    return at;
  }
  // Reads a stored set of f.size() values; false on failure.
  bool get(long long at, std::vector<double>& f) const {
    if (!file_ || at < 0) return false;
    char* p = reinterpret_cast<char*>(f.data());
    size_t left = f.size() * sizeof(double);
    off_t offset = off_t(at);
    while (left > 0) {
      ssize_t n = ::pread(fileno(file_), p, left, offset);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return false;
      p += n;
      left -= size_t(n);
      offset += n;
    }
    return true;
  }

 private:
  std::FILE* file_ = nullptr;
  long long size_ = 0;
  bool failed_ = false;
};

}  // namespace

nlohmann::json TextureMovieBakerOptions::toJson() const {
  return {{"key-step", keyStep},
          {"min-samples", minSamples},
          {"max-samples", maxSamples},
          {"samples-per-form-factor", samplesPerFormFactor},
          {"merge", mergeModeName(merge)},
          {"no-coherence", !coherence},
          {"max-texture-memory", maxTextureMemoryMiB}};
}

nlohmann::json TextureMovieBakerStats::toJson() const {
  return {{"movies", movies},
          {"constant_movies", constantMovies},
          {"keys", keys},
          {"texels", texels},
          {"bad_pairs", badPairs},
          {"static_pairs", staticPairs},
          {"dynamic_pairs", dynamicPairs},
          {"samples", samples},
          {"blockers_static", staticBlockers},
          {"blockers_dynamic", dynamicBlockers},
          {"render_passes", passes},
          {"sample_passes", samplePasses},
          {"render_passes_saved_by_coherence", passesSavedByCoherence},
          {"key_step_raised", keyStepRaised},
          {"seconds",
           {{"good_layer", secondsGood},
            {"form_factors", secondsFormFactor},
            {"form_factor_max_scan", secondsFormFactorScan},
            {"transmittance", secondsTransmittance},
            {"combine", secondsCombine}}},
          {"warnings", warnings}};
}

std::vector<int> movieKeyFrames(int firstFrame, int lastFrame, int step) {
  step = std::max(step, 1);
  std::vector<int> frames;
  for (long f = firstFrame; f < lastFrame; f += step) frames.push_back(int(f));
  frames.push_back(lastFrame);
  return frames;
}

Polygon nodeWorldPolygon(const Scene& scene, const InputPolygon& top, PatchId node, double t) {
  const bool triangle = top.local.count == 3;
  static const glm::dvec2 quadCorners[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  static const glm::dvec2 triCorners[3] = {{0, 0}, {1, 0}, {0, 1}};
  Polygon local;
  local.count = top.local.count;
  for (int k = 0; k < local.count; ++k)
    local.v[k] = polygonPointAt(
        top.local, topUvFromNodeUv(node, triangle ? triCorners[k] : quadCorners[k], triangle));
  return local.transformed(scene.worldTransform(top.node, t));
}

TextureMovieBaker::TextureMovieBaker(const Scene& scene, const GlobalSolution& solution, double fps,
                                     TextureMovieBakerOptions options)
    : scene_(scene),
      solution_(solution),
      fps_(fps),
      options_(options),
      tops_(solution.hierarchy.tops()) {
  if (options_.keyStep < 1) throw Error(ExitCode::kUsage, "--key-step", "must be >= 1");
  if (options_.maxSamples < 1 || options_.maxSamples > kMaxTransmittanceSamples)
    throw Error(ExitCode::kUsage, "--max-samples", "must be in 1..64");
  if (options_.minSamples < 1 || options_.minSamples > options_.maxSamples)
    throw Error(ExitCode::kUsage, "--min-samples", "must be in 1..--max-samples");
  if (!(options_.samplesPerFormFactor >= 0.0))
    throw Error(ExitCode::kUsage, "--samples-per-form-factor", "must be >= 0");
  if (!(options_.maxTextureMemoryMiB > 0.0))
    throw Error(ExitCode::kUsage, "--max-texture-memory", "must be > 0");
  if (!(fps_ > 0.0) || !std::isfinite(fps_))
    throw Error(ExitCode::kBadInput, "", "frames per second must be positive");
}

TextureMovieBaker::~TextureMovieBaker() = default;

TransmittanceRenderer& TextureMovieBaker::renderer() {
  if (!renderer_) renderer_ = std::make_unique<TransmittanceRenderer>();
  return *renderer_;
}

std::string TextureMovieBaker::rendererName() const {
  return renderer_ ? renderer_->rendererName() : std::string();
}

double TextureMovieBaker::movieWorkingBytes(int width, int height, size_t badShooters) {
  // Per texel: texel (u,v) and local point (16 + 24); the key's double accumulator (24), its
  // float texture (12) and the sink's copy of key 0 (12, constant-movie check); one pair's
  // float transmittance (4), per-key sample mask (8) and per-key form factor (8). Per coherent
  // bad pair: its form factors (8) and static-blocker sample mask (8).
  const double perTexel = 16 + 24 + 24 + 12 + 12 + 4 + 8 + 8 + 16.0 * double(badShooters);
  return double(width) * double(height) * perTexel;
}

// A bad pair's per-movie data, computed before the first key (paper §5: what the coherence
// makes per-movie instead of per-key).
struct TextureMovieBaker::Pair {
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
};

BakedMovie TextureMovieBaker::bake(const MovieRequest& req) {
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

BakedMovie TextureMovieBaker::bake(const MovieRequest& req, BakedKeySink& sink) {
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

  const uint32_t R = req.patch.top;
  const InputPolygon& receiverTop = tops_[R];
  const bool triangle = receiverTop.local.count == 3;
  const int w = req.width, h = req.height;
  const size_t texels = size_t(w) * h;
  const std::vector<uint32_t> badShooters = solution_.badShooters(R);

  // Working memory: one key's buffers and the per-pair ones, whatever the number of keys.
  const double bytes = movieWorkingBytes(w, h, badShooters.size());
  const double budget = options_.maxTextureMemoryMiB * 1024.0 * 1024.0;
  if (bytes > budget) {
    char budgetText[32];
    std::snprintf(budgetText, sizeof budgetText, "%g", options_.maxTextureMemoryMiB);
    throw Error(ExitCode::kEnvironment, where,
                "texture " + std::to_string(w) + "x" + std::to_string(h) + " with " +
                    std::to_string(badShooters.size()) + " bad shooter(s) needs " +
                    std::to_string(int(std::ceil(bytes / 1048576.0))) +
                    " MiB of working memory; --max-texture-memory is " + budgetText + " MiB");
  }

  BakedMovie movie;
  movie.keyStep = options_.keyStep;
  movie.keyFrames = movieKeyFrames(req.firstFrame, req.lastFrame, movie.keyStep);
  const int K = int(movie.keyFrames.size());
  for (int f : movie.keyFrames) movie.keyTimes.push_back(f / fps_);
  const double t0 = movie.keyTimes.front(), t1 = movie.keyTimes.back();

  // Texel centres: node (u,v) -> top (u,v) -> local point.
  std::vector<glm::dvec2> topUv(texels);
  std::vector<glm::dvec3> localPoint(texels);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      size_t x = size_t(j) * w + i;
      topUv[x] = topUvFromNodeUv(req.patch, {(i + 0.5) / w, (j + 0.5) / h}, triangle);
      localPoint[x] = polygonPointAt(receiverTop.local, topUv[x]);
    }

  // Whether a node moves during the movie, and its swept bounds, are asked for every blocker
  // candidate of every bad pair (with 32 moving cubes that was over half of rad-movies' time,
  // recomputing the same answers); each node's answer over [t0, t1] is computed once.
  std::vector<signed char> nodeMoves(scene_.nodes.size(), -1);
  auto movesDuringMovie = [&](int node) {
    if (node < 0 || node >= int(nodeMoves.size())) return scene_.isDynamic(node, t0, t1);
    signed char& m = nodeMoves[size_t(node)];
    if (m < 0) m = scene_.isDynamic(node, t0, t1) ? 1 : 0;
    return m == 1;
  };
  std::unordered_map<int, std::array<glm::dvec3, 2>> nodeSwept;
  auto sweptDuringMovie = [&](int node) -> const std::array<glm::dvec3, 2>& {
    auto it = nodeSwept.find(node);
    if (it == nodeSwept.end()) it = nodeSwept.emplace(node, scene_.sweptBounds(node, t0, t1)).first;
    return it->second;
  };
  const bool receiverDynamic = movesDuringMovie(receiverTop.node);
  std::vector<Polygon> receiverWorld(static_cast<size_t>(K));
  std::vector<glm::dmat4> receiverTransform(static_cast<size_t>(K));
  for (int k = 0; k < K; ++k) {
    receiverTransform[size_t(k)] =
        scene_.worldTransform(receiverTop.node, movie.keyTimes[size_t(k)]);
    receiverWorld[size_t(k)] =
        nodeWorldPolygon(scene_, receiverTop, req.patch, movie.keyTimes[size_t(k)]);
  }
  const glm::dvec3 receiverNormalLocal = receiverTop.local.normal();

  // Unoccluded form factors F(x -> S) per texel at key k.
  auto formFactorsAt = [&](const Pair& p, int k, std::vector<double>& f) {
    f.resize(texels);
    const glm::dmat4& m = receiverTransform[size_t(k)];
    glm::dvec3 n = glm::normalize(
        glm::dvec3(glm::transpose(glm::inverse(m)) * glm::dvec4(receiverNormalLocal, 0.0)));
    const Polygon& sw = p.shooterWorld[size_t(k)];
    parallelRows(h, [&](int j) {
      for (int i = 0; i < w; ++i) {
        size_t x = size_t(j) * w + i;
        glm::dvec3 pt(m * glm::dvec4(localPoint[x], 1.0));
        f[x] = pointToPolygonFormFactor(pt, n, sw);
      }
    });
  };
  auto samplesAt = [&](const Pair& p, int k) {
    std::vector<glm::dvec3> s(static_cast<size_t>(p.samples));
    for (int i = 0; i < p.samples; ++i)
      s[size_t(i)] = samplePointOnPolygon(p.shooterWorld[size_t(k)], p.unitSamples[size_t(i)]);
    return s;
  };
  auto shaftAt = [&](const Pair& p, int k) {
    Box box;
    box.grow(receiverWorld[size_t(k)]);
    box.grow(p.shooterWorld[size_t(k)]);
    return box;
  };
  // World transform of a node at key k, once per movie: the blockers of every pair at every
  // key are placed with it, several polygons per node.
  std::unordered_map<long long, glm::dmat4> nodeWorldAtKey;
  auto worldPolygon = [&](int b, int k) {
    const int node = tops_[size_t(b)].node;
    const long long key = (long long)k * (long long)(scene_.nodes.size() + 1) + (node + 1);
    auto it = nodeWorldAtKey.find(key);
    if (it == nodeWorldAtKey.end())
      it =
          nodeWorldAtKey.emplace(key, scene_.worldTransform(node, movie.keyTimes[size_t(k)])).first;
    return tops_[size_t(b)].local.transformed(it->second);
  };
  // Blockers of candidate list `list` in the pair's shaft at key k, as world triangles.
  auto blockersAt = [&](const Pair& p, const std::vector<int>& list, int k) {
    Box shaft = shaftAt(p, k);
    std::vector<BlockerTriangle> tris;
    for (int b : list) {
      Polygon poly = worldPolygon(b, k);
      Box pb;
      pb.grow(poly);
      if (pb.overlaps(shaft)) appendTriangles(poly, tris);
    }
    return tris;
  };

  // Per-movie part of every bad pair, in badShooters order.
  const int saturatedSamples = transmittanceSampleCount(std::numeric_limits<double>::infinity(),
                                                        options_.samplesPerFormFactor,
                                                        options_.minSamples, options_.maxSamples);
  std::vector<Pair> pairs;
  std::vector<double> keyFormFactor;
  FormFactorSpill spill;
  for (uint32_t S : badShooters) {
    if (S >= tops_.size()) continue;
    const InputPolygon& shooterTop = tops_[S];
    ++stats_.badPairs;
    const bool shooterDynamic = movesDuringMovie(shooterTop.node);
    const bool pairStatic = !receiverDynamic && !shooterDynamic;
    (pairStatic ? stats_.staticPairs : stats_.dynamicPairs) += 1;
    Pair p;
    p.shooter = S;
    p.coherent = options_.coherence && pairStatic;
    p.shooterWorld.resize(static_cast<size_t>(K));
    for (int k = 0; k < K; ++k)
      p.shooterWorld[size_t(k)] = shooterTop.local.transformed(
          scene_.worldTransform(shooterTop.node, movie.keyTimes[size_t(k)]));

    // The largest form factor over the movie fixes N (and whether the pair matters at all).
    // A coherent pair keeps its one set; a moving pair's sets are spilled as they are scanned
    // (FormFactorSpill) and the scan stops once N has reached its maximum (more keys cannot
    // change it; their sets are computed when their key is baked).
    auto clock = Clock::now();
    double maxF = 0.0;
    if (p.coherent) {
      formFactorsAt(p, 0, p.formFactor);
      for (double v : p.formFactor) maxF = std::max(maxF, v);
      stats_.secondsFormFactor += secondsSince(clock);
    } else {
      p.spilled.assign(static_cast<size_t>(K), -1);
      for (int k = 0; k < K; ++k) {
        formFactorsAt(p, k, keyFormFactor);
        for (double v : keyFormFactor) maxF = std::max(maxF, v);
        p.spilled[size_t(k)] = spill.put(keyFormFactor);
        if (maxF > 0.0 &&
            transmittanceSampleCount(maxF, options_.samplesPerFormFactor, options_.minSamples,
                                     options_.maxSamples) == saturatedSamples)
          break;
      }
      stats_.secondsFormFactorScan += secondsSince(clock);
    }
    if (!(maxF > 0.0)) continue;  // the shooter cannot reach this patch during the movie

    // Shooter samples (paper §3.1 step 1), fixed in the shooter's frame for the whole movie.
    clock = Clock::now();
    p.samples = transmittanceSampleCount(maxF, options_.samplesPerFormFactor, options_.minSamples,
                                         options_.maxSamples);
    stats_.samples += p.samples;
    const uint32_t seed = mix32(req.patch.packed() * 0x9e3779b97f4a7c15ull ^ S);
    p.unitSamples = multiJitteredPoints(p.samples, seed);

    // Blocker candidates: every top-level patch but the two ends (and their reversed copies).
    std::vector<int> candidates;
    for (size_t b = 0; b < tops_.size(); ++b) {
      if (b == R || b == S || sameSurface(tops_[b], receiverTop) ||
          sameSurface(tops_[b], shooterTop))
        continue;
      candidates.push_back(int(b));
    }
    if (p.coherent) {
      // §5: split the shaft's blockers into static ones (once per movie) and dynamic ones.
      Box shaft = shaftAt(p, 0);
      std::vector<int> staticList;
      for (int b : candidates) {
        int node = tops_[size_t(b)].node;
        if (!movesDuringMovie(node)) {
          Box pb;
          pb.grow(worldPolygon(b, 0));  // t0 is key 0's time
          if (pb.overlaps(shaft)) staticList.push_back(b);
        } else {
          const std::array<glm::dvec3, 2>& sb = sweptDuringMovie(node);
          Box swept{sb[0], sb[1]};
          if (swept.overlaps(shaft)) p.dynamicList.push_back(b);
        }
      }
      stats_.staticBlockers += long(staticList.size());
      stats_.dynamicBlockers += long(p.dynamicList.size());
      p.keyZeroSamples = samplesAt(p, 0);
      p.valid = frontSampleMask(receiverWorld[0], p.keyZeroSamples);
      std::vector<BlockerTriangle> staticTris = blockersAt(p, staticList, 0);
      renderer().render(receiverWorld[0], w, h, p.keyZeroSamples, staticTris, p.staticMask);
      if (!staticTris.empty())
        stats_.passesSavedByCoherence += K - 1;
      else
        std::vector<SampleMask>().swap(p.staticMask);  // all zero: not kept
    } else {
      // A moving end (or the baseline): every blocker in the key's shaft at every key.
      for (int b : candidates) {
        bool dyn = movesDuringMovie(tops_[size_t(b)].node);
        (dyn ? stats_.dynamicBlockers : stats_.staticBlockers) += 1;
      }
      p.candidates = std::move(candidates);
    }
    stats_.secondsTransmittance += secondsSince(clock);
    pairs.push_back(std::move(p));
  }

  // Key by key: H = G + sum over the pairs, in badShooters order, of B_S F T (the same
  // arithmetic and per-texel order as accumulating pair by pair over all keys).
  sink.begin(movie);
  std::vector<glm::dvec3> acc(texels);
  std::vector<float> transmittance(texels), texture(texels * 3);
  std::vector<SampleMask> keyMask;
  for (int k = 0; k < K; ++k) {
    const double t = movie.keyTimes[size_t(k)];
    // Good layer (paper §3.1: Gouraud over the patch from the global solution).
    auto clock = Clock::now();
    parallelRows(h, [&](int j) {
      for (int i = 0; i < w; ++i) {
        size_t x = size_t(j) * w + i;
        acc[x] = solution_.goodIrradiance(int(R), topUv[x], t);
      }
    });
    stats_.secondsGood += secondsSince(clock);

    for (const Pair& p : pairs) {
      TransmittanceRenderer& gl = renderer();
      clock = Clock::now();
      if (p.coherent) {
        std::vector<BlockerTriangle> dynamicTris = p.dynamicList.empty()
                                                       ? std::vector<BlockerTriangle>()
                                                       : blockersAt(p, p.dynamicList, k);
        gl.render(receiverWorld[0], w, h, p.keyZeroSamples, dynamicTris, keyMask);
        const bool noStatic = p.staticMask.empty();
        if (options_.merge == MergeMode::kExact) {
          for (size_t x = 0; x < texels; ++x)
            transmittance[x] = float(transmittanceFromMask(
                (noStatic ? SampleMask(0) : p.staticMask[x]) | keyMask[x], p.valid));
        } else {
          for (size_t x = 0; x < texels; ++x)
            transmittance[x] = float(mergeTransmittance(
                options_.merge,
                transmittanceFromMask(noStatic ? SampleMask(0) : p.staticMask[x], p.valid),
                transmittanceFromMask(keyMask[x], p.valid)));
        }
        stats_.secondsTransmittance += secondsSince(clock);
      } else {
        const std::vector<glm::dvec3> samples = samplesAt(p, k);
        const SampleMask valid = frontSampleMask(receiverWorld[size_t(k)], samples);
        gl.render(receiverWorld[size_t(k)], w, h, samples, blockersAt(p, p.candidates, k), keyMask);
        for (size_t x = 0; x < texels; ++x)
          transmittance[x] = float(transmittanceFromMask(keyMask[x], valid));
        stats_.secondsTransmittance += secondsSince(clock);
        clock = Clock::now();
        keyFormFactor.resize(texels);
        if (!spill.get(p.spilled[size_t(k)], keyFormFactor)) formFactorsAt(p, k, keyFormFactor);
        stats_.secondsFormFactor += secondsSince(clock);
      }

      // Bad layer: B_S(t) F T.
      clock = Clock::now();
      const glm::dvec3 B = solution_.radiosity(int(p.shooter), t);
      const std::vector<double>& f = p.coherent ? p.formFactor : keyFormFactor;
      for (size_t x = 0; x < texels; ++x) acc[x] += B * (f[x] * double(transmittance[x]));
      stats_.secondsCombine += secondsSince(clock);
    }

    clock = Clock::now();
    for (size_t x = 0; x < texels; ++x)
      for (int c = 0; c < 3; ++c) {
        double v = acc[x][c];
        // Irradiance is never negative or NaN (DESIGN.md §9); clamp rounding only.
        texture[3 * x + size_t(c)] = std::isfinite(v) ? float(std::max(v, 0.0)) : 0.0f;
      }
    stats_.secondsCombine += secondsSince(clock);
    sink.key(size_t(k), texture);
  }
  const size_t stored = sink.finish();

  if (renderer_) {
    stats_.passes = renderer_->passes();
    stats_.samplePasses = renderer_->samplePasses();
  }
  ++stats_.movies;
  if (stored == 1) ++stats_.constantMovies;
  stats_.keys += long(stored);
  stats_.texels += long(texels * stored);
  return movie;
}

}  // namespace rad
