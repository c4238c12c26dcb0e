// Texture-movie baking (paper §3.1 and §5). Sources and the formula in texture_movie_baker.h.
#include "libcommon/texture_movie_baker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "libcommon/error.h"
#include "libcommon/form_factor.h"

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

BakedMovie TextureMovieBaker::bake(const MovieRequest& req) {
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

  // Key frames, within the memory budget: float key textures plus the double accumulators.
  BakedMovie movie;
  int step = options_.keyStep;
  std::vector<int> frames = movieKeyFrames(req.firstFrame, req.lastFrame, step);
  const double bytesPerKey = double(texels) * (3 * sizeof(float) + 3 * sizeof(double) + 8);
  const double budget = options_.maxTextureMemoryMiB * 1024.0 * 1024.0;
  if (double(std::min<size_t>(frames.size(), 2)) * bytesPerKey > budget)
    throw Error(ExitCode::kEnvironment, where,
                "texture " + std::to_string(w) + "x" + std::to_string(h) + " needs " +
                    std::to_string(int(std::ceil(2 * bytesPerKey / 1048576.0))) +
                    " MiB for two keys; --max-texture-memory is " +
                    std::to_string(options_.maxTextureMemoryMiB) + " MiB");
  if (double(frames.size()) * bytesPerKey > budget) {
    while (double(frames.size()) * bytesPerKey > budget && frames.size() > 2) {
      step *= 2;
      frames = movieKeyFrames(req.firstFrame, req.lastFrame, step);
    }
    ++stats_.keyStepRaised;
    stats_.warnings.push_back(where + ": key step raised to " + std::to_string(step) +
                              " to fit --max-texture-memory");
  }
  movie.keyStep = step;
  movie.keyFrames = frames;
  const int K = int(frames.size());
  for (int f : frames) movie.keyTimes.push_back(f / fps_);
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

  // Good layer (paper §3.1: Gouraud over the patch from the global solution).
  auto clock = Clock::now();
  std::vector<std::vector<glm::dvec3>> acc(static_cast<size_t>(K), std::vector<glm::dvec3>(texels));
  for (int k = 0; k < K; ++k) {
    std::vector<glm::dvec3>& a = acc[size_t(k)];
    const double t = movie.keyTimes[size_t(k)];
    parallelRows(h, [&](int j) {
      for (int i = 0; i < w; ++i) {
        size_t x = size_t(j) * w + i;
        a[x] = solution_.goodIrradiance(int(R), topUv[x], t);
      }
    });
  }
  stats_.secondsGood += secondsSince(clock);

  const bool receiverDynamic = scene_.isDynamic(receiverTop.node, t0, t1);
  std::vector<Polygon> receiverWorld(static_cast<size_t>(K));
  std::vector<glm::dmat4> receiverTransform(static_cast<size_t>(K));
  for (int k = 0; k < K; ++k) {
    receiverTransform[size_t(k)] =
        scene_.worldTransform(receiverTop.node, movie.keyTimes[size_t(k)]);
    receiverWorld[size_t(k)] =
        nodeWorldPolygon(scene_, receiverTop, req.patch, movie.keyTimes[size_t(k)]);
  }
  const glm::dvec3 receiverNormalLocal = receiverTop.local.normal();

  for (uint32_t S : solution_.badShooters(R)) {
    if (S >= tops_.size()) continue;
    const InputPolygon& shooterTop = tops_[S];
    ++stats_.badPairs;
    const bool shooterDynamic = scene_.isDynamic(shooterTop.node, t0, t1);
    const bool pairStatic = !receiverDynamic && !shooterDynamic;
    (pairStatic ? stats_.staticPairs : stats_.dynamicPairs) += 1;
    const bool coherent = options_.coherence && pairStatic;

    std::vector<Polygon> shooterWorld(static_cast<size_t>(K));
    for (int k = 0; k < K; ++k)
      shooterWorld[size_t(k)] = shooterTop.local.transformed(
          scene_.worldTransform(shooterTop.node, movie.keyTimes[size_t(k)]));

    // Unoccluded form factors F(x -> S) per texel (once for a static pair when coherent).
    clock = Clock::now();
    const int formFactorSets = coherent ? 1 : K;
    std::vector<std::vector<double>> formFactor(static_cast<size_t>(formFactorSets),
                                                std::vector<double>(texels));
    double maxF = 0.0;
    for (int k = 0; k < formFactorSets; ++k) {
      const glm::dmat4& m = receiverTransform[size_t(k)];
      glm::dvec3 n = glm::normalize(
          glm::dvec3(glm::transpose(glm::inverse(m)) * glm::dvec4(receiverNormalLocal, 0.0)));
      std::vector<double>& f = formFactor[size_t(k)];
      const Polygon& sw = shooterWorld[size_t(k)];
      parallelRows(h, [&](int j) {
        for (int i = 0; i < w; ++i) {
          size_t x = size_t(j) * w + i;
          glm::dvec3 p(m * glm::dvec4(localPoint[x], 1.0));
          f[x] = pointToPolygonFormFactor(p, n, sw);
        }
      });
      for (double v : f) maxF = std::max(maxF, v);
    }
    stats_.secondsFormFactor += secondsSince(clock);
    if (!(maxF > 0.0)) continue;  // the shooter cannot reach this patch during the movie

    // Shooter samples (paper §3.1 step 1), fixed in the shooter's frame for the whole movie.
    clock = Clock::now();
    const int N = transmittanceSampleCount(maxF, options_.samplesPerFormFactor, options_.minSamples,
                                           options_.maxSamples);
    stats_.samples += N;
    const uint32_t seed = mix32(req.patch.packed() * 0x9e3779b97f4a7c15ull ^ S);
    const std::vector<glm::dvec2> unitSamples = multiJitteredPoints(N, seed);
    auto samplesAt = [&](int k) {
      std::vector<glm::dvec3> s(static_cast<size_t>(N));
      for (int i = 0; i < N; ++i)
        s[size_t(i)] = samplePointOnPolygon(shooterWorld[size_t(k)], unitSamples[size_t(i)]);
      return s;
    };

    // Blocker candidates: every top-level patch but the two ends (and their reversed copies).
    std::vector<int> candidates;
    for (size_t b = 0; b < tops_.size(); ++b) {
      if (b == R || b == S || sameSurface(tops_[b], receiverTop) ||
          sameSurface(tops_[b], shooterTop))
        continue;
      candidates.push_back(int(b));
    }
    auto shaftAt = [&](int k) {
      Box box;
      box.grow(receiverWorld[size_t(k)]);
      box.grow(shooterWorld[size_t(k)]);
      return box;
    };
    auto worldPolygon = [&](int b, double t) {
      return tops_[size_t(b)].local.transformed(scene_.worldTransform(tops_[size_t(b)].node, t));
    };
    // Blockers of candidate list `list` in the shaft at key k, as world triangles.
    auto blockersAt = [&](const std::vector<int>& list, int k) {
      Box shaft = shaftAt(k);
      std::vector<BlockerTriangle> tris;
      for (int b : list) {
        Polygon p = worldPolygon(b, movie.keyTimes[size_t(k)]);
        Box pb;
        pb.grow(p);
        if (pb.overlaps(shaft)) appendTriangles(p, tris);
      }
      return tris;
    };

    TransmittanceRenderer& gl = renderer();
    std::vector<SampleMask> staticMask, keyMask;
    std::vector<std::vector<float>> transmittance(static_cast<size_t>(K),
                                                  std::vector<float>(texels, 1.0f));
    if (coherent) {
      // §5: split the shaft's blockers into static ones (once per movie) and dynamic ones.
      Box shaft = shaftAt(0);
      std::vector<int> staticList, dynamicList;
      for (int b : candidates) {
        int node = tops_[size_t(b)].node;
        if (!scene_.isDynamic(node, t0, t1)) {
          Box pb;
          pb.grow(worldPolygon(b, t0));
          if (pb.overlaps(shaft)) staticList.push_back(b);
        } else {
          std::array<glm::dvec3, 2> sb = scene_.sweptBounds(node, t0, t1);
          Box swept{sb[0], sb[1]};
          if (swept.overlaps(shaft)) dynamicList.push_back(b);
        }
      }
      stats_.staticBlockers += long(staticList.size());
      stats_.dynamicBlockers += long(dynamicList.size());
      const std::vector<glm::dvec3> samples = samplesAt(0);
      const SampleMask valid = frontSampleMask(receiverWorld[0], samples);
      std::vector<BlockerTriangle> staticTris = blockersAt(staticList, 0);
      gl.render(receiverWorld[0], w, h, samples, staticTris, staticMask);
      if (!staticTris.empty()) stats_.passesSavedByCoherence += K - 1;
      for (int k = 0; k < K; ++k) {
        std::vector<BlockerTriangle> dynamicTris =
            dynamicList.empty() ? std::vector<BlockerTriangle>() : blockersAt(dynamicList, k);
        gl.render(receiverWorld[0], w, h, samples, dynamicTris, keyMask);
        std::vector<float>& t = transmittance[size_t(k)];
        if (options_.merge == MergeMode::kExact) {
          for (size_t x = 0; x < texels; ++x)
            t[x] = float(transmittanceFromMask(staticMask[x] | keyMask[x], valid));
        } else {
          for (size_t x = 0; x < texels; ++x)
            t[x] = float(mergeTransmittance(options_.merge,
                                            transmittanceFromMask(staticMask[x], valid),
                                            transmittanceFromMask(keyMask[x], valid)));
        }
      }
    } else {
      // A moving end (or the baseline): every blocker in the key's shaft at every key.
      long counted = 0;
      for (int b : candidates) {
        bool dyn = scene_.isDynamic(tops_[size_t(b)].node, t0, t1);
        (dyn ? stats_.dynamicBlockers : stats_.staticBlockers) += 1;
        ++counted;
      }
      (void)counted;
      for (int k = 0; k < K; ++k) {
        const std::vector<glm::dvec3> samples = samplesAt(k);
        const SampleMask valid = frontSampleMask(receiverWorld[size_t(k)], samples);
        gl.render(receiverWorld[size_t(k)], w, h, samples, blockersAt(candidates, k), keyMask);
        std::vector<float>& t = transmittance[size_t(k)];
        for (size_t x = 0; x < texels; ++x) t[x] = float(transmittanceFromMask(keyMask[x], valid));
      }
    }
    stats_.secondsTransmittance += secondsSince(clock);

    // Bad layer: B_S(t) F T, accumulated per key.
    clock = Clock::now();
    for (int k = 0; k < K; ++k) {
      const glm::dvec3 B = solution_.radiosity(int(S), movie.keyTimes[size_t(k)]);
      const std::vector<double>& f = formFactor[size_t(coherent ? 0 : k)];
      const std::vector<float>& t = transmittance[size_t(k)];
      std::vector<glm::dvec3>& a = acc[size_t(k)];
      for (size_t x = 0; x < texels; ++x) a[x] += B * (f[x] * double(t[x]));
    }
    stats_.secondsCombine += secondsSince(clock);
  }

  clock = Clock::now();
  movie.keys.assign(static_cast<size_t>(K), std::vector<float>(texels * 3));
  for (int k = 0; k < K; ++k) {
    std::vector<float>& out = movie.keys[size_t(k)];
    const std::vector<glm::dvec3>& a = acc[size_t(k)];
    for (size_t x = 0; x < texels; ++x)
      for (int c = 0; c < 3; ++c) {
        double v = a[x][c];
        // Irradiance is never negative or NaN (DESIGN.md §9); clamp rounding only.
        out[3 * x + size_t(c)] = std::isfinite(v) ? float(std::max(v, 0.0)) : 0.0f;
      }
  }
  // A movie whose key textures all agree is stored with one key.
  if (options_.coherence && K > 1) {
    bool constant = true;
    for (int k = 1; k < K && constant; ++k)
      constant = std::memcmp(movie.keys[0].data(), movie.keys[size_t(k)].data(),
                             texels * 3 * sizeof(float)) == 0;
    if (constant) {
      movie.keys.resize(1);
      movie.keyFrames.resize(1);
      movie.keyTimes.resize(1);
    }
  }
  stats_.secondsCombine += secondsSince(clock);
  if (renderer_) {
    stats_.passes = renderer_->passes();
    stats_.samplePasses = renderer_->samplePasses();
  }
  ++stats_.movies;
  if (movie.keys.size() == 1) ++stats_.constantMovies;
  stats_.keys += long(movie.keys.size());
  stats_.texels += long(texels * movie.keys.size());
  return movie;
}

}  // namespace rad
