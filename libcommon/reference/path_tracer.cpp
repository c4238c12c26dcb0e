// Reference path tracer (see path_tracer.h): Kajiya 1986; PBRT 3rd ed. §13.6 (cosine-weighted
// hemisphere sampling), §14.5 (path tracing with next-event estimation, Russian roulette);
// Duff et al. 2017 (orthonormal basis); Embree 3 (Wald et al. 2014).
#include "libcommon/reference/path_tracer.h"
#include "libcommon/scene/emission_texture.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <string>

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "libcommon/core/error.h"
#include "libcommon/radiosity/visibility.h"  // splitMix64, uniformOpen01 (counter-based random numbers)
#include "libcommon/scene/scene_emitters.h"

namespace rad {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr std::uint32_t kNoPolygon = 0xffffffffu;
// Shadow rays stop this fraction short of the emitter point, so the emitter's own plane
// (and polygons flush with it) never occludes.
constexpr double kShadowShortening = 1e-4;

// Counter-based random stream: value i of stream `seed` is uniformOpen01(seed, i).
struct RandomStream {
  std::uint64_t seed;
  std::uint64_t counter = 0;
  double next() { return uniformOpen01(seed, counter++); }
};

// Orthonormal basis around unit n (Duff et al. 2017, "Building an orthonormal basis, revisited").
void basis(const glm::dvec3& n, glm::dvec3& b1, glm::dvec3& b2) {
  const double sign = std::copysign(1.0, n.z);
  const double a = -1.0 / (sign + n.z);
  const double b = n.x * n.y * a;
  b1 = glm::dvec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
  b2 = glm::dvec3(b, sign + n.y * n.y * a, -n.y);
}

// Cosine-distributed direction about n (Malley's method: uniform disk, projected up).
glm::dvec3 cosineDirection(const glm::dvec3& n, double u1, double u2) {
  const double r = std::sqrt(u1), phi = 2.0 * kPi * u2;
  const double x = r * std::cos(phi), y = r * std::sin(phi);
  const double z = std::sqrt(std::max(0.0, 1.0 - u1));
  glm::dvec3 b1, b2;
  basis(n, b1, b2);
  return glm::normalize(x * b1 + y * b2 + z * n);
}

double maxComponent(const glm::dvec3& v) {
  return std::max(v.x, std::max(v.y, v.z));
}

// Intersection context carrying the polygon the ray leaves (never hit again: it is planar).
struct FilterContext {
  RTCIntersectContext context;
  std::uint32_t ignore;
};

void ignoreOwnPolygon(const RTCFilterFunctionNArguments* args) {
  const auto* fc = reinterpret_cast<const FilterContext*>(args->context);
  const auto* polygonOf = static_cast<const std::uint32_t*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    if (polygonOf[RTCHitN_primID(args->hit, args->N, i)] == fc->ignore) args->valid[i] = 0;
  }
}

}  // namespace

struct PathTracer::Impl {
  struct Surface {
    Polygon world;
    glm::dvec3 normal{0.0};  // front normal (unit)
    glm::dvec3 reflectance{0.0};
    glm::dvec3 emission{0.0};
    bool doubleSided = false;
    // Reflectance texture (glTF baseColorTexture): rho(x) = factor x texel(uv(x)), bilinear,
    // repeat-wrapped; texture == nullptr means constant reflectance.
    const Texture* texture = nullptr;
    glm::dvec3 factor{0.0};
    std::array<glm::dvec2, 4> uv{};
    // Shading normals at the vertices (glTF NORMAL, world, unit); zero: flat.
    std::array<glm::dvec3, 4> shadingNormal{};
    int frontEmitter = -1;  // index into emitters of the side facing the front normal
    int backEmitter = -1;   // of the back side (doubleSided emitters only)
  };
  // A light of the scene (scene_emitters.h) placed at the current time.
  struct Emitter {
    std::unique_ptr<PlacedEmitter> placed;
    double area = 0.0;         // placed->area(), read once per frame
    double probability = 0.0;  // of being chosen for next-event estimation
  };

  RTCDevice device = nullptr;
  RTCScene bvh = nullptr;
  std::vector<InputPolygon> inputs;       // Scene::inputPolygons(), in local frames
  std::unique_ptr<SceneEmitters> lights;  // the scene's emitters, top() indexing `inputs`
  std::vector<Surface> surfaces;          // ray-castable polygons (reversed copies left out)
  std::vector<std::uint32_t> polygonOf;   // Embree triangle -> surface index
  std::vector<std::uint8_t> fanIndex;     // Embree triangle -> k of its fan triangle (0, k, k+1)
  std::vector<Emitter> emitters;          // every emitting side (reversed copies included)
  std::vector<double> emitterCdf;         // cumulative probabilities
  double sceneSize = 1.0;                 // largest coordinate magnitude (ray offsets)
  std::mutex errorMutex;
  std::string lastError;

  ~Impl() {
    if (bvh) rtcReleaseScene(bvh);
    if (device) rtcReleaseDevice(device);
  }

  void check(const char* what) {
    if (rtcGetDeviceError(device) == RTC_ERROR_NONE) return;
    std::lock_guard<std::mutex> lock(errorMutex);
    throw Error(ExitCode::kEnvironment, "embree",
                std::string(what) + " failed" + (lastError.empty() ? "" : ": " + lastError));
  }

  static void onError(void* user, RTCError, const char* str) {
    auto* self = static_cast<Impl*>(user);
    std::lock_guard<std::mutex> lock(self->errorMutex);
    self->lastError = str ? str : "";
  }

  void build(const Scene& scene, double t) {
    surfaces.clear();
    emitters.clear();
    polygonOf.clear();
    fanIndex.clear();
    sceneSize = 0.0;
    std::vector<glm::dmat4> worldFromLocal(scene.nodes.size());
    std::vector<bool> known(scene.nodes.size(), false);
    double emitterWeight = 0.0;
    for (size_t i = 0; i < inputs.size(); ++i) {
      const InputPolygon& in = inputs[i];
      if (!known[size_t(in.node)]) {
        worldFromLocal[size_t(in.node)] = scene.worldTransform(in.node, t);
        known[size_t(in.node)] = true;
      }
      Polygon world = in.local.transformed(worldFromLocal[size_t(in.node)]);
      const glm::dvec3 n = world.normal();
      if (n == glm::dvec3(0.0)) continue;  // degenerate after a zero scale
      const Material m = in.material >= 0 && in.material < int(scene.materials.size())
                             ? scene.materials[size_t(in.material)]
                             : Material();
      for (int k = 0; k < world.count; ++k)
        for (int d = 0; d < 3; ++d) sceneSize = std::max(sceneSize, std::abs(world.v[k][d]));
      int emitter = -1;
      if (const int light = lights->indexOfTop(int(i)); light >= 0) {
        // Placed from the same node transform as `world` above: the same polygon, bit for bit.
        Emitter e{(*lights)[size_t(light)].at(t), 0.0, 0.0};
        if (e.placed) {
          e.area = e.placed->area();
          emitterWeight += e.placed->samplingWeight();
          emitter = int(emitters.size());
          emitters.push_back(std::move(e));
        }
      }
      if (in.backFace) {
        // Scene::inputPolygons puts the reversed copy right after its front polygon, which
        // stands for both sides in the BVH.
        if (!surfaces.empty()) surfaces.back().backEmitter = emitter;
        continue;
      }
      // An emissive texture's mean over the patch, as the lights' list samples it.
      Surface surface{world, n, m.reflectance, meanEmissionOver(scene, in), m.doubleSided};
      surface.frontEmitter = emitter;
      if (in.normal[0] != glm::dvec3(0.0)) {
        const glm::dmat3 normalMap =
            glm::transpose(glm::inverse(glm::dmat3(worldFromLocal[size_t(in.node)])));
        for (int k = 0; k < world.count; ++k)
          surface.shadingNormal[size_t(k)] = glm::normalize(normalMap * in.normal[size_t(k)]);
      }
      if (m.baseColorTexture >= 0 && m.baseColorTexture < int(scene.textures.size())) {
        const Texture& tex = scene.textures[size_t(m.baseColorTexture)];
        if (tex.width > 0 && tex.height > 0 &&
            tex.rgb.size() == size_t(tex.width) * size_t(tex.height) * 3) {
          surface.texture = &tex;
          surface.uv = in.uv;
          // Material::reflectance is factor x mean(texture); undo the mean.
          for (int c = 0; c < 3; ++c)
            surface.factor[c] = tex.mean[c] > 0.0 ? m.reflectance[c] / tex.mean[c] : 0.0;
        }
      }
      surfaces.push_back(surface);
    }
    // The punctual lights (delta lights: no surface, never hit), after every polygon light so a
    // scene without lamps samples exactly as before.
    for (int lamp : lights->lamps()) {
      Emitter e{(*lights)[size_t(lamp)].at(t), 0.0, 0.0};
      if (!e.placed || !(e.placed->samplingWeight() > 0.0)) continue;
      emitterWeight += e.placed->samplingWeight();
      emitters.push_back(std::move(e));
    }
    emitterCdf.clear();
    double sum = 0.0;
    for (Emitter& e : emitters) {
      e.probability = e.placed->samplingWeight() / emitterWeight;
      sum += e.probability;
      emitterCdf.push_back(sum);
    }
    if (!emitterCdf.empty()) emitterCdf.back() = 1.0;
    if (!(sceneSize > 0.0)) sceneSize = 1.0;
    buildBvh();
  }

  // The BVH of `surfaces`, each polygon a fan of triangles (0, k, k+1); polygonOf and fanIndex
  // map a hit triangle back to its polygon.
  void buildBvh() {
    if (bvh) rtcReleaseScene(bvh);
    bvh = rtcNewScene(device);
    check("rtcNewScene");
    rtcSetSceneFlags(bvh, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(bvh, RTC_BUILD_QUALITY_HIGH);
    size_t triangles = 0;
    for (const Surface& s : surfaces) triangles += size_t(s.world.count - 2);
    if (triangles > 0) {
      RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
      check("rtcNewGeometry");
      auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * triangles));
      auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), triangles));
      if (!vb || !ib) {
        rtcReleaseGeometry(g);
        check("rtcSetNewGeometryBuffer");
        throw Error(ExitCode::kEnvironment, "embree", "rtcSetNewGeometryBuffer failed");
      }
      size_t tri = 0;
      for (size_t s = 0; s < surfaces.size(); ++s) {
        const Polygon& p = surfaces[s].world;
        for (int k = 1; k + 1 < p.count; ++k, ++tri) {  // fan (0, k, k+1): convex polygons
          const glm::dvec3* corners[3] = {&p.v[0], &p.v[size_t(k)], &p.v[size_t(k + 1)]};
          for (int c = 0; c < 3; ++c) {
            for (int d = 0; d < 3; ++d) vb[9 * tri + 3 * c + d] = float((*corners[c])[d]);
            ib[3 * tri + c] = unsigned(3 * tri + c);
          }
          polygonOf.push_back(std::uint32_t(s));
          fanIndex.push_back(std::uint8_t(k));
        }
      }
      rtcSetGeometryUserData(g, polygonOf.data());
      rtcSetGeometryIntersectFilterFunction(g, ignoreOwnPolygon);
      rtcSetGeometryOccludedFilterFunction(g, ignoreOwnPolygon);
      rtcCommitGeometry(g);
      rtcAttachGeometry(bvh, g);
      rtcReleaseGeometry(g);
    }
    rtcCommitScene(bvh);
    check("building the BVH");
  }

  // Nearest hit on [tNear, tFar]: surface index and distance, or kNoPolygon.
  struct Hit {
    std::uint32_t surface = kNoPolygon;
    double t = 0.0;
    int fan = 1;              // triangle (0, fan, fan + 1) of the polygon
    double u = 0.0, v = 0.0;  // Embree barycentrics: p = (1-u-v) v0 + u v_fan + v v_fan+1
  };

  Hit intersect(const glm::dvec3& origin, const glm::dvec3& dir, double tNear, double tFar,
                std::uint32_t ignore) const {
    FilterContext fc;
    rtcInitIntersectContext(&fc.context);
    fc.ignore = ignore;
    RTCRayHit rh;
    rh.ray.org_x = float(origin.x);
    rh.ray.org_y = float(origin.y);
    rh.ray.org_z = float(origin.z);
    rh.ray.dir_x = float(dir.x);
    rh.ray.dir_y = float(dir.y);
    rh.ray.dir_z = float(dir.z);
    rh.ray.tnear = float(tNear);
    rh.ray.tfar = std::isinf(tFar) ? std::numeric_limits<float>::infinity() : float(tFar);
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xffffffffu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(bvh, &fc.context, &rh);
    Hit hit;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return hit;
    hit.surface = polygonOf[rh.hit.primID];
    hit.fan = fanIndex[rh.hit.primID];
    hit.t = double(rh.ray.tfar);
    hit.u = double(rh.hit.u);
    hit.v = double(rh.hit.v);
    return hit;
  }

  // The shading normal at a hit on the side of the flat normal n (which is s.normal or its
  // negation): the vertex normals interpolated over the hit's fan triangle, normalised; n
  // itself for a flat polygon or where the interpolation faces away from n.
  glm::dvec3 shadingNormal(const Surface& s, const Hit& h, const glm::dvec3& n) const {
    if (s.shadingNormal[0] == glm::dvec3(0.0)) return n;
    glm::dvec3 ns = (1.0 - h.u - h.v) * s.shadingNormal[0] + h.u * s.shadingNormal[size_t(h.fan)] +
                    h.v * s.shadingNormal[size_t(h.fan + 1)];
    if (glm::dot(n, s.normal) < 0.0) ns = -ns;
    const double len = glm::length(ns);
    return len > 1e-12 && glm::dot(ns, n) > 0.0 ? ns / len : n;
  }

  // Reflectance at a hit: constant, or factor x bilinear texel lookup (glTF: uv (0, 0) is the
  // top-left corner of the image, texel centres at half-integers, REPEAT wrap).
  glm::dvec3 reflectanceAt(const Surface& s, const Hit& h) const {
    if (!s.texture) return s.reflectance;
    const glm::dvec2 uv =
        (1.0 - h.u - h.v) * s.uv[0] + h.u * s.uv[size_t(h.fan)] + h.v * s.uv[size_t(h.fan + 1)];
    const Texture& tex = *s.texture;
    const double x = uv.x * tex.width - 0.5, y = uv.y * tex.height - 0.5;
    if (!std::isfinite(x) || !std::isfinite(y)) return s.reflectance;
    const double x0 = std::floor(x), y0 = std::floor(y);
    const double fx = x - x0, fy = y - y0;
    auto wrap = [](double i, int n) {
      const long long m = (long long)std::fmod(i, double(n));
      return int(m < 0 ? m + n : m);
    };
    const int xa = wrap(x0, tex.width), xb = wrap(x0 + 1, tex.width);
    const int ya = wrap(y0, tex.height), yb = wrap(y0 + 1, tex.height);
    auto texel = [&](int tx, int ty) {
      const size_t i = (size_t(ty) * size_t(tex.width) + size_t(tx)) * 3;
      return glm::dvec3(tex.rgb[i], tex.rgb[i + 1], tex.rgb[i + 2]);
    };
    const glm::dvec3 value = (1 - fy) * ((1 - fx) * texel(xa, ya) + fx * texel(xb, ya)) +
                             fy * ((1 - fx) * texel(xa, yb) + fx * texel(xb, yb));
    return glm::clamp(s.factor * value, glm::dvec3(0.0), glm::dvec3(1.0));
  }

  bool occluded(const glm::dvec3& origin, const glm::dvec3& dir, double tFar,
                std::uint32_t ignore) const {
    FilterContext fc;
    rtcInitIntersectContext(&fc.context);
    fc.ignore = ignore;
    RTCRay ray;
    ray.org_x = float(origin.x);
    ray.org_y = float(origin.y);
    ray.org_z = float(origin.z);
    ray.dir_x = float(dir.x);
    ray.dir_y = float(dir.y);
    ray.dir_z = float(dir.z);
    ray.tnear = 0.0f;
    ray.tfar = float(tFar);
    ray.time = 0.0f;
    ray.mask = 0xffffffffu;
    ray.id = 0;
    ray.flags = 0;
    rtcOccluded1(bvh, &fc.context, &ray);
    return ray.tfar < 0.0f;  // Embree sets tfar = -inf on a hit
  }

  // Origin for rays leaving a surface point on the side of unit normal n: lifted off the plane
  // by a few float ulps of the scene's coordinates (the own polygon is also ignored).
  glm::dvec3 liftOff(const glm::dvec3& x, const glm::dvec3& n) const {
    return x + n * (4e-7 * sceneSize);
  }

  // Next-event estimate of the reflected-radiance integrand's emitter part at x (normal n on
  // the side the path arrived from): one emitter point, returns sum L_e cos cos' / d^2 / pdf.
  glm::dvec3 directLight(const glm::dvec3& x, const glm::dvec3& n, const glm::dvec3& geometric,
                         std::uint32_t surface, RandomStream& rng) const {
    const double u0 = rng.next(), u1 = rng.next(), u2 = rng.next();
    if (emitters.empty()) return glm::dvec3(0.0);
    const size_t e =
        size_t(std::lower_bound(emitterCdf.begin(), emitterCdf.end(), u0) - emitterCdf.begin());
    const Emitter& em = emitters[std::min(e, emitters.size() - 1)];
    if (!(em.probability > 0.0)) return glm::dvec3(0.0);
    const glm::dvec3 origin = liftOff(x, geometric);
    if (em.area == 0.0) return deltaLight(em, origin, n, geometric, surface);
    const EmitterSample sample = em.placed->sample(glm::dvec2(u1, u2));
    const glm::dvec3& y = sample.point;
    const glm::dvec3 d = y - origin;
    const double dist2 = glm::dot(d, d);
    if (!(dist2 > 0.0)) return glm::dvec3(0.0);
    const double dist = std::sqrt(dist2);
    const glm::dvec3 w = d / dist;
    const double cosX = glm::dot(n, w), cosY = -glm::dot(sample.normal, w);
    if (cosX <= 0.0 || cosY <= 0.0) return glm::dvec3(0.0);     // one-sided emitter / receiver
    if (glm::dot(geometric, w) <= 0.0) return glm::dvec3(0.0);  // below the surface itself
    if (occluded(origin, w, dist * (1.0 - kShadowShortening), surface)) return glm::dvec3(0.0);
    // Multiple importance sampling against the cosine-distributed continuation (Veach &
    // Guibas 1995, power heuristic), both densities per unit solid angle.
    const double pdfLight = em.probability / em.area * dist2 / cosY;
    const double pdfBsdf = cosX / kPi;
    const double weight = pdfLight * pdfLight / (pdfLight * pdfLight + pdfBsdf * pdfBsdf);
    return em.placed->emittedRadiance(y, -w) * (cosX / pdfLight * weight);
  }

  // A delta light's estimate (emitter.h: no MIS, a continuation never finds it): its unoccluded
  // irradiance at the receiver, $I \cos\theta / d^2$ or a sun's $E \cos\theta$, if the
  // segment to its shadowTarget is clear, over the probability of choosing it.
  glm::dvec3 deltaLight(const Emitter& em, const glm::dvec3& origin, const glm::dvec3& n,
                        const glm::dvec3& geometric, std::uint32_t surface) const {
    const glm::dvec3 d = em.placed->shadowTarget(origin) - origin;
    const double dist = glm::length(d);
    if (!(dist > 0.0) || glm::dot(geometric, d) <= 0.0) return glm::dvec3(0.0);
    const glm::dvec3 E = em.placed->irradiance(origin, n);
    if (maxComponent(E) <= 0.0) return glm::dvec3(0.0);
    if (occluded(origin, d / dist, dist * (1.0 - kShadowShortening), surface))
      return glm::dvec3(0.0);
    return E / em.probability;
  }

  // Solid-angle density with which directLight() picks the point at distance `dist` on
  // emitter e seen under cosine cosY.
  double lightPdf(int e, double dist, double cosY) const {
    const Emitter& em = emitters[size_t(e)];
    return em.probability / em.area * dist * dist / cosY;
  }

  glm::dvec3 radiance(const Ray& ray, std::uint64_t seed, const PathTracerOptions& o) const {
    RandomStream rng{seed};
    glm::dvec3 L(0.0), throughput(1.0);
    glm::dvec3 origin = ray.origin, dir = ray.direction;
    double tNear = ray.tNear, tFar = ray.tFar;
    std::uint32_t from = kNoPolygon;
    double pdfBsdf = 0.0;  // solid-angle density of the continuation that reached this hit
    constexpr int kMaxCulledPasses = 64;  // back faces a primary ray may pass through
    int culledPasses = 0;
    for (int bounce = 0;; ++bounce) {
      const Hit h = intersect(origin, dir, tNear, tFar, from);
      if (h.surface == kNoPolygon) break;
      const std::uint32_t hit = h.surface;
      const double t = h.t;
      const Surface& s = surfaces[hit];
      glm::dvec3 n = s.normal;
      int emitter = s.frontEmitter;
      if (glm::dot(dir, n) >= 0.0) {
        if (!s.doubleSided && bounce == 0 && culledPasses < kMaxCulledPasses) {
          // The camera does not see the back of a one-sided polygon: glTF culls back faces
          // (doubleSided false), and so does rad-compose's item buffer (docs/design.md §4:
          // one-sided by winding). The primary ray goes on past it. Light paths still treat
          // the polygon as opaque, as the radiosity stages' visibility does.
          // The search restarts from the same origin just short of this hit, with this
          // polygon ignored: a coincident front face (a polygon modelled seen from both sides
          // as two faces) is still met whichever of the two the rounding put first.
          // Restarting at the hit point with tNear = 0 would lose it for some of the rays.
          ++culledPasses;
          tNear = t * (1.0 - 1e-6);
          from = hit;
          --bounce;  // still the primary ray
          continue;
        }
        if (!s.doubleSided) break;  // back of a one-sided polygon: black, absorbing
        n = -n;
        emitter = s.backEmitter;
      }
      if (bounce == 0) {
        L += throughput * s.emission;  // seen directly: nothing else can account for it
      } else if (emitter >= 0) {
        // Found by the continuation: MIS weight against next-event estimation.
        const double pdfLight = lightPdf(emitter, t, -glm::dot(dir, n));
        const double weight = pdfBsdf * pdfBsdf / (pdfBsdf * pdfBsdf + pdfLight * pdfLight);
        L += throughput *
             emitters[size_t(emitter)].placed->emittedRadiance(origin + t * dir, -dir) * weight;
      }
      if (bounce >= o.maxDepth) break;
      const glm::dvec3 rho = reflectanceAt(s, h);
      if (maxComponent(rho) <= 0.0) break;
      const glm::dvec3 x = origin + t * dir;
      // The shading normal (glTF NORMAL, interpolated; Cycles and glTF viewers shade with it)
      // on the side the path arrived from; the flat n keeps the ray offsets and side tests.
      const glm::dvec3 ns = shadingNormal(s, h, n);
      // Reflected direct light: BRDF rho / pi times the NEE estimate.
      L += throughput * rho * (1.0 / kPi) * directLight(x, ns, n, hit, rng);
      // Continue with a cosine-distributed direction: BRDF x cos / pdf = rho.
      const double u1 = rng.next(), u2 = rng.next(), uRoulette = rng.next();
      throughput *= rho;
      if (bounce + 1 >= o.rouletteDepth) {
        const double q = std::min(0.95, maxComponent(rho));
        if (uRoulette >= q) break;
        throughput /= q;
      }
      origin = liftOff(x, n);
      dir = cosineDirection(ns, u1, u2);
      if (glm::dot(dir, n) <= 0.0) break;  // into the surface: absorbed
      pdfBsdf = std::max(glm::dot(ns, dir), 0.0) / kPi;
      tNear = 0.0;
      tFar = std::numeric_limits<double>::infinity();
      from = hit;
    }
    return L;
  }
};

PathTracer::PathTracer(const Scene& scene, double t) : impl_(new Impl), scene_(scene) {
  impl_->device = rtcNewDevice("verbose=0");
  if (!impl_->device)
    throw Error(ExitCode::kEnvironment, "embree", "rtcNewDevice failed (unsupported CPU?)");
  rtcSetDeviceErrorFunction(impl_->device, &Impl::onError, impl_.get());
  impl_->inputs = scene.inputPolygons();
  impl_->lights = std::make_unique<SceneEmitters>(scene, impl_->inputs);
  setTime(t);
}

PathTracer::~PathTracer() = default;

void PathTracer::setTime(double t) {
  impl_->build(scene_, t);
  time_ = t;
}

int PathTracer::polygonCount() const {
  return int(impl_->surfaces.size());
}
int PathTracer::emitterCount() const {
  return int(impl_->emitters.size());
}

glm::dvec3 PathTracer::radianceSample(const Ray& ray, std::uint64_t seed,
                                      const PathTracerOptions& options) const {
  return impl_->radiance(ray, seed, options);
}

RadianceEstimate PathTracer::estimateRadiance(const Ray& ray, long long n, std::uint64_t seed,
                                              const PathTracerOptions& options) const {
  RadianceEstimate e;
  glm::dvec3 sum(0.0), sumSq(0.0);
  for (long long i = 0; i < n; ++i) {
    const glm::dvec3 L =
        impl_->radiance(ray, splitMix64(seed ^ splitMix64(std::uint64_t(i))), options);
    sum += L;
    sumSq += L * L;
  }
  e.samples = n;
  if (n > 0) {
    e.mean = sum / double(n);
    if (n > 1) {
      const glm::dvec3 var =
          glm::max(sumSq / double(n) - e.mean * e.mean, glm::dvec3(0.0)) * (double(n) / (n - 1));
      e.standardError = glm::sqrt(var / double(n));
    }
  }
  return e;
}

FloatImage PathTracer::render(const CameraView& view, ImageSize size,
                              const PathTracerOptions& options, int frame) const {
  FloatImage image(size.width, size.height, {"R", "G", "B"});
  const int spp = std::max(1, options.samplesPerPixel);
  const int strata = int(std::floor(std::sqrt(double(spp))));  // strata x strata jittered grid
  std::uint64_t base = splitMix64(options.seed ^ 0x7265666572656E63ull);  // "referenc"
  if (options.decorrelateFrames) base = splitMix64(base ^ splitMix64(std::uint64_t(frame)));
  const PrimaryRays rays(view, size);
  const PixelFilterSampler filter(options.filter);
  tbb::parallel_for(tbb::blocked_range<int>(0, size.height), [&](const tbb::blocked_range<int>& r) {
    for (int row = r.begin(); row < r.end(); ++row) {
      for (int col = 0; col < size.width; ++col) {
        const std::uint64_t pixelSeed =
            splitMix64(base ^ splitMix64(std::uint64_t(row) * std::uint64_t(size.width) +
                                         std::uint64_t(col) + 1));
        glm::dvec3 sum(0.0);
        for (int s = 0; s < spp; ++s) {
          const std::uint64_t sampleSeed = splitMix64(pixelSeed + std::uint64_t(s) * 2 + 1);
          // Offset from the centre: jittered strata for the first strata^2 samples, uniform after,
          // mapped through the filter's inverse distribution (Cycles' filter table).
          const double jx = uniformOpen01(sampleSeed, 1000001);
          const double jy = uniformOpen01(sampleSeed, 1000002);
          glm::dvec2 u(jx, jy);
          if (s < strata * strata)
            u = glm::dvec2((s % strata + jx) / strata, (s / strata + jy) / strata);
          const glm::dvec2 pixel(col + 0.5 + filter.offset(u.x), row + 0.5 + filter.offset(u.y));
          const Ray ray = rays.at(pixel);
          const glm::dvec3 L = impl_->radiance(ray, sampleSeed, options);
          if (std::isfinite(L.x) && std::isfinite(L.y) && std::isfinite(L.z)) sum += L;
        }
        const glm::dvec3 mean = sum / double(spp);
        for (int c = 0; c < 3; ++c) image.at(col, row, c) = float(mean[c]);
      }
    }
  });
  return image;
}

}  // namespace rad
