// Shadow-ray visibility with Embree 3 (Wald et al. 2014); stratified ray pairs after Hanrahan,
// Salzman, Aupperle 1991; splitmix64 from Steele, Lea, Flood 2014.
// The figures behind the reasons given here: docs/results.md, "Figures moved out of the radiosity
// code's comments (issue 55)".
#include "libcommon/radiosity/visibility.h"

#include <algorithm>
#include <array>
#include <bitset>
#include <cmath>
#include <deque>
#include <limits>
#include <mutex>
#include <numeric>
#include <string>

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "libcommon/core/error.h"

namespace rad {

std::uint64_t splitMix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

double uniformOpen01(std::uint64_t seed, std::uint64_t counter) {
  std::uint64_t r = splitMix64(splitMix64(seed) ^ splitMix64(counter + 0x632BE59BD9B4E019ull));
  return (static_cast<double>(r >> 11) + 0.5) * 0x1.0p-53;
}

std::vector<int> permutation(int k, std::uint64_t seed) {
  std::vector<int> p(k);
  std::iota(p.begin(), p.end(), 0);
  for (int i = k - 1; i > 0; --i) {
    int j = std::min(i, static_cast<int>(uniformOpen01(seed, i) * (i + 1)));
    std::swap(p[i], p[j]);
  }
  return p;
}

namespace {

const char* embreeErrorName(RTCError e) {
  switch (e) {
    case RTC_ERROR_NONE:
      return "no error";
    case RTC_ERROR_UNKNOWN:
      return "unknown error";
    case RTC_ERROR_INVALID_ARGUMENT:
      return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION:
      return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY:
      return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU:
      return "unsupported CPU";
    case RTC_ERROR_CANCELLED:
      return "cancelled";
  }
  return "unknown error";
}

// Intersection context extended with the surfaces a query ignores (Embree's documented way
// of passing per-ray data to filter functions).
struct FilterContext {
  RTCIntersectContext context;
  std::uint32_t ignoreA;
  std::uint32_t ignoreB;
};

FilterContext filterContext(std::uint32_t ignoreA, std::uint32_t ignoreB) {
  FilterContext fc;
  rtcInitIntersectContext(&fc.context);
  fc.ignoreA = ignoreA;
  fc.ignoreB = ignoreB;
  return fc;
}

void ignoreEndSurfaces(const RTCFilterFunctionNArguments* args) {
  const auto* fc = reinterpret_cast<const FilterContext*>(args->context);
  const auto* surfaces = static_cast<const std::uint32_t*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    std::uint32_t s = surfaces[RTCHitN_primID(args->hit, args->N, i)];
    if (s == fc->ignoreA || s == fc->ignoreB) args->valid[i] = 0;
  }
}

// Random-number streams of one query.
enum Stream : std::uint64_t { kJitterA = 1, kJitterB = 2, kPermuteA = 3, kPermuteB = 4, kPair = 5 };

std::uint64_t streamSeed(std::uint64_t seed, Stream s) {
  return splitMix64(seed ^ (0xD1B54A32D192ED03ull * static_cast<std::uint64_t>(s)));
}

// k stratified points in the open unit square.
std::vector<glm::dvec2> stratified(int k, std::uint64_t jitterSeed, std::uint64_t permSeed) {
  std::vector<glm::dvec2> pts(k);
  int m = static_cast<int>(std::lround(std::sqrt(static_cast<double>(k))));
  if (m * m == k) {
    for (int i = 0; i < k; ++i) {
      pts[i] = {(i % m + uniformOpen01(jitterSeed, 2 * i)) / m,
                (i / m + uniformOpen01(jitterSeed, 2 * i + 1)) / m};
    }
  } else {
    std::vector<int> py = permutation(k, permSeed);
    for (int i = 0; i < k; ++i) {
      pts[i] = {(i + uniformOpen01(jitterSeed, 2 * i)) / k,
                (py[i] + uniformOpen01(jitterSeed, 2 * i + 1)) / k};
    }
  }
  return pts;
}

// Area-uniform map of the unit square onto triangle abc.
glm::dvec3 onTriangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, double u,
                      double v) {
  double su = std::sqrt(u);
  return (1.0 - su) * a + su * (1.0 - v) * b + su * v * c;
}

// Area-uniform map of the unit square onto a triangle or a convex quad (split along v0-v2,
// u chooses the half in proportion to its area, so strata stay strata).
glm::dvec3 onPolygon(const Polygon& p, glm::dvec2 s) {
  if (p.count == 3) return onTriangle(p.v[0], p.v[1], p.v[2], s.x, s.y);
  double a0 = glm::length(glm::cross(p.v[1] - p.v[0], p.v[2] - p.v[0]));
  double a1 = glm::length(glm::cross(p.v[2] - p.v[0], p.v[3] - p.v[0]));
  double w = a0 + a1 > 0.0 ? a0 / (a0 + a1) : 0.5;
  if (s.x < w) return onTriangle(p.v[0], p.v[1], p.v[2], s.x / w, s.y);
  return onTriangle(p.v[0], p.v[2], p.v[3], std::min((s.x - w) / (1.0 - w), 1.0), s.y);
}

// The ray origin + t direction for t in [kSegmentEpsilon, tfar] (in units of |direction|), in
// Embree's single precision; no time, every mask bit.
RTCRay rayOf(const glm::dvec3& origin, const glm::dvec3& direction, double tfar) {
  RTCRay ray;
  ray.org_x = static_cast<float>(origin.x);
  ray.org_y = static_cast<float>(origin.y);
  ray.org_z = static_cast<float>(origin.z);
  ray.dir_x = static_cast<float>(direction.x);
  ray.dir_y = static_cast<float>(direction.y);
  ray.dir_z = static_cast<float>(direction.z);
  ray.tnear = static_cast<float>(VisibilityScene::kSegmentEpsilon);
  ray.tfar = static_cast<float>(tfar);
  ray.time = 0.0f;
  ray.mask = 0xffffffffu;
  ray.id = 0;
  ray.flags = 0;
  return ray;
}

// The k stratified points on b of a query seeded `seed`, in the order they pair with a's
// (samplePoints(a, k, seed)): b's strata randomly permuted against a's.
std::vector<glm::dvec3> pairedPoints(const Polygon& b, int k, std::uint64_t seed) {
  k = std::max(k, 1);
  std::vector<glm::dvec2> sb =
      stratified(k, streamSeed(seed, kJitterB), streamSeed(seed, kPermuteB));
  std::vector<int> pair = permutation(k, streamSeed(seed, kPair));
  std::vector<glm::dvec3> out(static_cast<std::size_t>(k));
  for (int i = 0; i < k; ++i) out[size_t(i)] = onPolygon(b, sb[size_t(pair[size_t(i)])]);
  return out;
}

// A ray pair's weight in F: cos(theta_a) cos(theta_b) / r^2 (unnormalised normals times d,
// over r^4), 0 where either point is behind the other's plane: those pairs carry no energy, but
// an area-uniform count let them darken the link (a box face gathering from a floor patch half
// behind it read V = 0.5).
double pairKernel(const glm::dvec3& a, const glm::dvec3& aNormal, const glm::dvec3& b,
                  const glm::dvec3& bNormal) {
  const glm::dvec3 d = b - a;
  const double r2 = glm::dot(d, d);
  return r2 > 0.0 ? std::max(0.0, glm::dot(aNormal, d)) * std::max(0.0, -glm::dot(bNormal, d)) /
                        (r2 * r2)
                  : 0.0;
}

}  // namespace

struct VisibilityScene::Impl {
  RTCDevice device = nullptr;
  RTCScene top = nullptr;
  std::vector<RTCScene> children;                   // [0] static, then one per dynamic object
  std::vector<RTCGeometry> instances;               // dynamic instances, by instance id
  std::deque<std::vector<std::uint32_t>> surfaces;  // stable addresses for the filter
  // Per child scene (= per instance geometry id of the top scene, the static one first): its
  // triangles' surface ids, null for an empty child.
  std::vector<const std::vector<std::uint32_t>*> childSurfaces;
  std::mutex errorMutex;
  std::string lastError;
  // The top scene's bounds at the last commit, widened by far more than single precision's
  // rounding of a ray (segmentMayHit); empty (lo > hi) for a scene without triangles. Tested
  // only in a scene of instances alone (SceneVisibility's moving part): a scene with static
  // triangles spans the room its rays are cast in, and the test would only cost.
  glm::dvec3 lo{1.0}, hi{-1.0};
  bool boundsTest = false;

  ~Impl() {
    for (RTCGeometry g : instances) rtcReleaseGeometry(g);
    if (top) rtcReleaseScene(top);
    for (RTCScene s : children) rtcReleaseScene(s);
    if (device) rtcReleaseDevice(device);
  }

  void check(const char* what) {
    RTCError e = rtcGetDeviceError(device);
    if (e == RTC_ERROR_NONE) return;
    std::string msg;
    {
      std::lock_guard<std::mutex> lock(errorMutex);
      msg = lastError;
    }
    throw Error(
        ExitCode::kEnvironment, "embree",
        std::string(what) + ": " + embreeErrorName(e) + (msg.empty() ? "" : " (" + msg + ")"));
  }

  static void onError(void* user, RTCError, const char* str) {
    auto* self = static_cast<Impl*>(user);
    std::lock_guard<std::mutex> lock(self->errorMutex);
    self->lastError = str ? str : "";
  }

  RTCScene buildMesh(const std::vector<VisibilityTriangle>& tris) {
    RTCScene scene = rtcNewScene(device);
    check("rtcNewScene");
    children.push_back(scene);
    childSurfaces.push_back(nullptr);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    if (!tris.empty()) {
      RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
      check("rtcNewGeometry(triangle)");
      auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * tris.size()));
      auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), tris.size()));
      if (!vb || !ib) {
        rtcReleaseGeometry(g);
        check("rtcSetNewGeometryBuffer");
        throw Error(ExitCode::kEnvironment, "embree", "rtcSetNewGeometryBuffer failed");
      }
      surfaces.emplace_back();
      std::vector<std::uint32_t>& ids = surfaces.back();
      ids.reserve(tris.size());
      for (std::size_t t = 0; t < tris.size(); ++t) {
        for (int c = 0; c < 3; ++c) {
          for (int d = 0; d < 3; ++d) vb[9 * t + 3 * c + d] = static_cast<float>(tris[t].v[c][d]);
          ib[3 * t + c] = static_cast<unsigned>(3 * t + c);
        }
        ids.push_back(tris[t].surface);
      }
      rtcSetGeometryUserData(g, ids.data());
      rtcSetGeometryOccludedFilterFunction(g, ignoreEndSurfaces);
      rtcSetGeometryIntersectFilterFunction(g, ignoreEndSurfaces);
      childSurfaces.back() = &ids;
      rtcCommitGeometry(g);
      rtcAttachGeometry(scene, g);
      rtcReleaseGeometry(g);
    }
    rtcCommitScene(scene);
    check("building a triangle BVH");
    return scene;
  }

  RTCGeometry instance(RTCScene child, const glm::dmat4& m) {
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
    check("rtcNewGeometry(instance)");
    rtcSetGeometryInstancedScene(g, child);
    rtcSetGeometryTimeStepCount(g, 1);
    setTransform(g, m);
    rtcAttachGeometry(top, g);
    check("attaching an instance");
    return g;
  }

  static void setTransform(RTCGeometry g, const glm::dmat4& m) {
    float xfm[12];  // 3x4, column-major: columns 0..3 of the affine part
    for (int c = 0; c < 4; ++c) {
      for (int r = 0; r < 3; ++r) xfm[3 * c + r] = static_cast<float>(m[c][r]);
    }
    rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
    rtcCommitGeometry(g);
  }
};

VisibilityScene::VisibilityScene(const std::vector<VisibilityTriangle>& staticTriangles)
    : impl_(std::make_unique<Impl>()) {
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device) {
    throw Error(ExitCode::kEnvironment, "embree",
                std::string("rtcNewDevice: ") + embreeErrorName(rtcGetDeviceError(nullptr)));
  }
  rtcSetDeviceErrorFunction(impl_->device, &Impl::onError, impl_.get());
  if (!rtcGetDeviceProperty(impl_->device, RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED)) {
    throw Error(ExitCode::kEnvironment, "embree",
                "this Embree build has no filter-function support (needed to ignore end patches)");
  }
  impl_->top = rtcNewScene(impl_->device);
  impl_->check("rtcNewScene");
  rtcSetSceneFlags(impl_->top, RTC_SCENE_FLAG_DYNAMIC | RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(impl_->top, RTC_BUILD_QUALITY_LOW);
  impl_->boundsTest = staticTriangles.empty();
  RTCScene statics = impl_->buildMesh(staticTriangles);
  RTCGeometry g = impl_->instance(statics, glm::dmat4(1.0));
  rtcReleaseGeometry(g);  // never moves; the top scene keeps it alive
  commit();
}

VisibilityScene::~VisibilityScene() = default;
VisibilityScene::VisibilityScene(VisibilityScene&&) noexcept = default;
VisibilityScene& VisibilityScene::operator=(VisibilityScene&&) noexcept = default;

int VisibilityScene::addInstance(const std::vector<VisibilityTriangle>& localTriangles,
                                 const glm::dmat4& objectToWorld) {
  RTCScene child = impl_->buildMesh(localTriangles);
  impl_->instances.push_back(impl_->instance(child, objectToWorld));
  return static_cast<int>(impl_->instances.size()) - 1;
}

void VisibilityScene::setInstanceTransform(int id, const glm::dmat4& objectToWorld) {
  if (id < 0 || id >= instanceCount()) {
    throw Error(
        ExitCode::kInternal, "VisibilityScene",
        "no instance " + std::to_string(id) + " (have " + std::to_string(instanceCount()) + ")");
  }
  Impl::setTransform(impl_->instances[id], objectToWorld);
  impl_->check("rtcSetGeometryTransform");
}

void VisibilityScene::commit() {
  rtcCommitScene(impl_->top);
  impl_->check("building the instance BVH");
  RTCBounds b;
  rtcGetSceneBounds(impl_->top, &b);
  impl_->lo = glm::dvec3(b.lower_x, b.lower_y, b.lower_z);
  impl_->hi = glm::dvec3(b.upper_x, b.upper_y, b.upper_z);
  if (impl_->lo.x <= impl_->hi.x && impl_->lo.y <= impl_->hi.y && impl_->lo.z <= impl_->hi.z) {
    const glm::dvec3 size = impl_->hi - impl_->lo;
    const double extent = std::max({size.x, size.y, size.z});
    const glm::dvec3 far = glm::max(glm::abs(impl_->lo), glm::abs(impl_->hi));
    const double pad = 1e-3 * extent + 1e-4 * std::max({far.x, far.y, far.z}) + 1e-6;
    impl_->lo -= glm::dvec3(pad);
    impl_->hi += glm::dvec3(pad);
  }
}

// Whether the segment from a to b may meet the scene's (widened) bounds: a slab test. A segment
// that misses them cannot hit a triangle, so occluded() answers without Embree. Most of rad-movies'
// rays against the moving objects (a small car in a room) miss their box, and an rtcOccluded1 call
// through the instance costs far more than this test.
bool VisibilityScene::segmentMayHit(const glm::dvec3& a, const glm::dvec3& b) const {
  const glm::dvec3& lo = impl_->lo;
  const glm::dvec3& hi = impl_->hi;
  double t0 = 0.0, t1 = 1.0;
  for (int i = 0; i < 3; ++i) {
    const double d = b[i] - a[i];
    if (d == 0.0) {
      if (a[i] < lo[i] || a[i] > hi[i]) return false;
      continue;
    }
    double ta = (lo[i] - a[i]) / d, tb = (hi[i] - a[i]) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

int VisibilityScene::instanceCount() const {
  return static_cast<int>(impl_->instances.size());
}

bool VisibilityScene::segmentRay(const glm::dvec3& a, const glm::dvec3& b, RTCRay& ray) const {
  if (impl_->boundsTest && !segmentMayHit(a, b)) return false;
  ray = rayOf(a, b - a, 1.0 - kSegmentEpsilon);
  return ray.dir_x != 0.0f || ray.dir_y != 0.0f || ray.dir_z != 0.0f;
}

bool VisibilityScene::occluded(const glm::dvec3& from, const glm::dvec3& to, std::uint32_t ignoreA,
                               std::uint32_t ignoreB) const {
  RTCRay ray;
  if (!segmentRay(from, to, ray)) return false;
  FilterContext fc = filterContext(ignoreA, ignoreB);
  rtcOccluded1(impl_->top, &fc.context, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar = -inf on a hit
}

double VisibilityScene::visibility(const Polygon& a, const Polygon& b, int k, std::uint64_t seed,
                                   std::uint32_t ignoreA, std::uint32_t ignoreB) const {
  const std::vector<glm::dvec3> pa = samplePoints(a, k, seed), pb = pairedPoints(b, k, seed);
  const int n = int(pa.size());
  size_t unoccluded = 0;
  for (int i = 0; i < n; i += kMaxRecordedPairs)  // in packets, as weightedVisibilityFrom
    unoccluded +=
        std::bitset<64>(openSegments(&pa[size_t(i)], 1, &pb[size_t(i)], n - i, ignoreA, ignoreB))
            .count();
  return static_cast<double>(unoccluded) / static_cast<double>(n);
}

std::vector<glm::dvec3> VisibilityScene::samplePoints(const Polygon& p, int k, std::uint64_t seed) {
  k = std::max(k, 1);
  std::vector<glm::dvec2> s =
      stratified(k, streamSeed(seed, kJitterA), streamSeed(seed, kPermuteA));
  std::vector<glm::dvec3> out(static_cast<std::size_t>(k));
  for (int i = 0; i < k; ++i) out[size_t(i)] = onPolygon(p, s[size_t(i)]);
  return out;
}

std::vector<glm::dvec3> VisibilityScene::samplePointsInFront(const Polygon& p, const glm::dvec3& at,
                                                             const glm::dvec3& n, int k,
                                                             std::uint64_t seed) {
  // Behind beyond rounding (a wall's foot on the floor's plane is not behind it).
  double size = 0.0;
  for (int i = 1; i < p.count; ++i) size = std::max(size, glm::length(p.v[size_t(i)] - p.v[0]));
  bool behind = false;
  for (int i = 0; i < p.count; ++i)
    behind = behind || glm::dot(n, p.v[size_t(i)] - at) < -1e-9 * size;
  if (!behind) return samplePoints(p, k, seed);
  // The part in front: a convex polygon of up to 5 vertices.
  std::array<glm::dvec3, 5> front{};
  int m = 0;
  clipToFront(p.v.data(), size_t(p.count), n, at, 0.0,
              [&](const glm::dvec3& x) { front[size_t(m++)] = x; });
  // Its fan of triangles from front[0], chosen by area with the first coordinate (strata stay
  // strata, as onPolygon does for a quad's two halves).
  std::array<double, 4> area{};
  double total = 0.0;
  for (int i = 1; i + 1 < m; ++i) {
    area[size_t(i - 1)] =
        glm::length(glm::cross(front[size_t(i)] - front[0], front[size_t(i + 1)] - front[0]));
    total += area[size_t(i - 1)];
  }
  if (!(total > 0.0)) return samplePoints(p, k, seed);  // nothing in front: F is 0 anyway
  k = std::max(k, 1);
  const std::vector<glm::dvec2> s =
      stratified(k, streamSeed(seed, kJitterA), streamSeed(seed, kPermuteA));
  std::vector<glm::dvec3> out(static_cast<std::size_t>(k));
  for (int i = 0; i < k; ++i) {
    double u = s[size_t(i)].x * total;
    int t = 0;
    while (t + 1 < m - 2 && u >= area[size_t(t)]) u -= area[size_t(t++)];
    out[size_t(i)] = onTriangle(front[0], front[size_t(t + 1)], front[size_t(t + 2)],
                                std::clamp(u / area[size_t(t)], 0.0, 1.0), s[size_t(i)].y);
  }
  return out;
}

namespace {

// The sums of weightedVisibilityFrom's estimator over its pairs, in pair order.
struct PairTally {
  double weighted = 0.0, weight = 0.0;         // kernel x weightAtB
  double kernelOpen = 0.0, kernelTotal = 0.0;  // kernel alone
  int unoccluded = 0;
  void add(bool isOpen, double kernel, double weightAtB) {
    unoccluded += isOpen ? 1 : 0;
    kernelTotal += kernel;
    kernelOpen += isOpen ? kernel : 0.0;
    const double w = kernel * weightAtB;
    weight += w;
    weighted += isOpen ? w : 0.0;
  }
  // No weight at any pair that exchanges energy (a shooter still dark, before the first solve):
  // the kernel's fraction; no pair that exchanges energy: the area-uniform fraction.
  double visibility(int k, double* kernelMeanWeight) const {
    if (kernelMeanWeight) *kernelMeanWeight = kernelTotal > 0.0 ? weight / kernelTotal : -1.0;
    if (weight > 0.0) return weighted / weight;
    return kernelTotal > 0.0 ? kernelOpen / kernelTotal : static_cast<double>(unoccluded) / k;
  }
};

}  // namespace

double VisibilityScene::visibilityFrom(const std::vector<glm::dvec3>& aPoints,
                                       const glm::dvec3& aNormal, const Polygon& b,
                                       std::uint64_t seed, std::uint32_t ignoreA,
                                       std::uint32_t ignoreB, std::uint64_t* openPairs,
                                       std::uint64_t blockedPairs) const {
  return weightedVisibilityFrom(aPoints, aNormal, b, seed, ignoreA, ignoreB, nullptr, nullptr,
                                openPairs, nullptr, blockedPairs);
}

double VisibilityScene::weightedVisibilityFrom(
    const std::vector<glm::dvec3>& aPoints, const glm::dvec3& aNormal, const Polygon& b,
    std::uint64_t seed, std::uint32_t ignoreA, std::uint32_t ignoreB,
    const std::uint64_t* knownOpenPairs, const std::function<double(const glm::dvec3&)>& weightAtB,
    std::uint64_t* openPairs, double* kernelMeanWeight, std::uint64_t blockedPairs) const {
  const int k = int(aPoints.size());
  if (k == 0) return 1.0;
  const std::vector<glm::dvec3> bPoints = pairedPoints(b, k, seed);
  const glm::dvec3 bNormal = b.normal();
  const bool known = knownOpenPairs && k <= kMaxRecordedPairs;
  PairTally tally;
  std::uint64_t open = 0, chunk = 0;
  for (int i = 0; i < k; ++i) {
    const glm::dvec3 pa = aPoints[size_t(i)], pb = bPoints[size_t(i)];
    const int bit = i % kMaxRecordedPairs;
    if (!known && bit == 0)  // the next (up to) 64 pairs' segments, in packets
      chunk = openSegments(&aPoints[size_t(i)], 1, &bPoints[size_t(i)], k - i, ignoreA, ignoreB,
                           i == 0 ? ~blockedPairs : ~std::uint64_t(0));
    const bool blocked = i < kMaxRecordedPairs && ((blockedPairs >> i) & 1u) != 0;
    const bool isOpen =
        !blocked && (known ? ((*knownOpenPairs >> i) & 1u) != 0 : ((chunk >> bit) & 1u) != 0);
    if (isOpen && i < kMaxRecordedPairs) open |= std::uint64_t(1) << i;
    tally.add(isOpen, pairKernel(pa, aNormal, pb, bNormal),
              weightAtB ? std::max(0.0, weightAtB(pb)) : 1.0);
  }
  if (openPairs) *openPairs = open;
  return tally.visibility(k, kernelMeanWeight);
}

void VisibilityScene::pairsFrom(const std::vector<glm::dvec3>& aPoints, const glm::dvec3& aNormal,
                                const Polygon& b, std::uint64_t seed,
                                std::vector<glm::dvec3>& bPoints, std::vector<double>& kernel) {
  const int k = int(aPoints.size());
  bPoints = k > 0 ? pairedPoints(b, k, seed) : std::vector<glm::dvec3>();
  const glm::dvec3 bNormal = b.normal();
  kernel.resize(size_t(k));
  for (int i = 0; i < k; ++i)
    kernel[size_t(i)] = pairKernel(aPoints[size_t(i)], aNormal, bPoints[size_t(i)], bNormal);
}

double VisibilityScene::weightedVisibilityOfPairs(int k, const double* kernel, std::uint64_t known,
                                                  const double* weightAtB, std::uint64_t* openPairs,
                                                  double* kernelMeanWeight) {
  if (k == 0) return 1.0;
  PairTally tally;
  std::uint64_t open = 0;
  for (int i = 0; i < k; ++i) {
    const bool isOpen = ((known >> i) & 1u) != 0;
    if (isOpen) open |= std::uint64_t(1) << i;
    tally.add(isOpen, kernel[i], std::max(0.0, weightAtB[i]));
  }
  if (openPairs) *openPairs = open;
  return tally.visibility(k, kernelMeanWeight);
}

std::uint64_t VisibilityScene::openFrom(const glm::dvec3& x, const std::vector<glm::dvec3>& bPoints,
                                        std::uint32_t ignoreA, std::uint32_t ignoreB,
                                        std::uint64_t candidates) const {
  return openSegments(&x, 0, bPoints.data(), std::min(int(bPoints.size()), kMaxRecordedPairs),
                      ignoreA, ignoreB, candidates);
}

std::uint64_t VisibilityScene::openSegments(const glm::dvec3* from, size_t fromStep,
                                            const glm::dvec3* to, int k, std::uint32_t ignoreA,
                                            std::uint32_t ignoreB, std::uint64_t candidates) const {
  // Packets of 8 segments (Embree's AVX2 width), one traversal for 8 rays instead of 8: the
  // per-texel rays of one texel share their origin, and so mostly their path through the tree. Each
  // lane is the segment occluded() tests, so the answers are the same.
  std::uint64_t open = 0;
  k = std::min(k, kMaxRecordedPairs);
  FilterContext fc = filterContext(ignoreA, ignoreB);
  for (int first = 0; first < k; first += 8) {
    alignas(32) int valid[8];
    alignas(32) RTCRay8 rays;
    bool any = false;
    for (int lane = 0; lane < 8; ++lane) {
      const int i = first + lane;
      valid[lane] = 0;
      if (i >= k || !((candidates >> i) & 1u)) continue;
      RTCRay ray;
      if (!segmentRay(from[size_t(i) * fromStep], to[size_t(i)], ray)) {
        open |= std::uint64_t(1) << i;  // nothing it could hit
        continue;
      }
      rays.org_x[lane] = ray.org_x, rays.org_y[lane] = ray.org_y, rays.org_z[lane] = ray.org_z;
      rays.dir_x[lane] = ray.dir_x, rays.dir_y[lane] = ray.dir_y, rays.dir_z[lane] = ray.dir_z;
      rays.tnear[lane] = ray.tnear, rays.tfar[lane] = ray.tfar, rays.time[lane] = ray.time;
      rays.mask[lane] = ray.mask, rays.id[lane] = ray.id, rays.flags[lane] = ray.flags;
      valid[lane] = -1;
      any = true;
    }
    if (!any) continue;
    rtcOccluded8(valid, impl_->top, &fc.context, &rays);
    for (int lane = 0; lane < 8; ++lane)
      if (valid[lane] == -1 && !(rays.tfar[lane] < 0.0f))  // tfar = -inf on a hit
        open |= std::uint64_t(1) << (first + lane);
  }
  return open;
}

std::uint64_t allRaysOpen(int k) {
  return k >= 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << k) - 1;
}

double pointVisibility(const glm::dvec3& x, const glm::dvec3& n,
                       const std::vector<glm::dvec3>& bPoints, const glm::dvec3& bNormal,
                       std::uint64_t open, const double* weight) {
  const int k = std::min(int(bPoints.size()), VisibilityScene::kMaxRecordedPairs);
  if (k == 0) return 1.0;
  const std::uint64_t all = allRaysOpen(k);
  open &= all;
  if (open == all) return 1.0;  // the common cases, exact whatever the weights
  if (open == 0) return 0.0;
  std::array<double, VisibilityScene::kMaxRecordedPairs> kernel;
  pointKernels(x, n, bPoints, bNormal, k, kernel.data());
  return pointVisibilityOfKernels(kernel.data(), k, open, weight);
}

void pointKernels(const glm::dvec3& x, const glm::dvec3& n, const std::vector<glm::dvec3>& bPoints,
                  const glm::dvec3& bNormal, int k, double* kernel) {
  for (int i = 0; i < k; ++i) kernel[i] = pairKernel(x, n, bPoints[size_t(i)], bNormal);
}

double pointVisibilityOfKernels(const double* kernel, int k, std::uint64_t open,
                                const double* weight) {
  if (k == 0) return 1.0;
  const std::uint64_t all = allRaysOpen(k);
  open &= all;
  if (open == all) return 1.0;
  if (open == 0) return 0.0;
  double weighted = 0.0, total = 0.0;
  for (int i = 0; i < k; ++i) {
    double w = kernel[i];
    if (weight) w *= std::max(0.0, weight[i]);
    total += w;
    weighted += ((open >> i) & 1u) ? w : 0.0;
  }
  if (total > 0.0) return weighted / total;
  int count = 0;
  for (int i = 0; i < k; ++i) count += int((open >> i) & 1u);
  return double(count) / k;
}

namespace {
// The surface id of the first triangle of `scene` the ray hits (kNoSurface: none); `child` is the
// instanced scene for a hit without an instance (the static scene traversed directly).
VisibilityScene::Hit firstHitIn(RTCScene scene, const glm::dvec3& origin,
                                const glm::dvec3& direction, std::uint32_t ignoreA,
                                std::uint32_t ignoreB, unsigned child,
                                const std::vector<const std::vector<std::uint32_t>*>& childSurfaces,
                                double tnear = VisibilityScene::kSegmentEpsilon,
                                double tfar = std::numeric_limits<double>::infinity()) {
  VisibilityScene::Hit none;
  RTCRayHit rh;
  rh.ray = rayOf(origin, direction, tfar);
  rh.ray.tnear = float(tnear);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  if (!(rh.ray.dir_x != 0.0f || rh.ray.dir_y != 0.0f || rh.ray.dir_z != 0.0f)) return none;
  FilterContext fc = filterContext(ignoreA, ignoreB);
  rtcIntersect1(scene, &fc.context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return none;
  if (rh.hit.instID[0] != RTC_INVALID_GEOMETRY_ID) child = rh.hit.instID[0];
  if (child >= childSurfaces.size() || !childSurfaces[child]) return none;
  const std::vector<std::uint32_t>& ids = *childSurfaces[child];
  if (rh.hit.primID >= ids.size()) return none;
  return {ids[rh.hit.primID], double(rh.ray.tfar)};
}
}  // namespace

std::uint32_t VisibilityScene::firstHit(const glm::dvec3& origin, const glm::dvec3& direction,
                                        std::uint32_t ignore) const {
  return nearestHit(origin, direction, ignore).surface;
}

VisibilityScene::Hit VisibilityScene::nearestHit(const glm::dvec3& origin,
                                                 const glm::dvec3& direction, std::uint32_t ignoreA,
                                                 std::uint32_t ignoreB, double tnear,
                                                 double tfar) const {
  return firstHitIn(impl_->top, origin, direction, ignoreA, ignoreB, RTC_INVALID_GEOMETRY_ID,
                    impl_->childSurfaces, tnear, tfar);
}

std::uint32_t VisibilityScene::firstStaticHit(const glm::dvec3& origin, const glm::dvec3& direction,
                                              std::uint32_t ignore) const {
  return firstHitIn(impl_->children[0], origin, direction, ignore, ignore, 0, impl_->childSurfaces)
      .surface;
}

RayStart rayStart(const VisibilityScene& v, const glm::dvec3& origin, const glm::dvec3& direction,
                  std::uint32_t ignore, const std::function<bool(std::uint32_t)>& isBack) {
  const VisibilityScene::Hit first = v.nearestHit(origin, direction, ignore);
  if (first.surface == VisibilityScene::kNoSurface) return RayStart::kOutside;
  // The surfaces at the first hit's distance: the second ray is cut to it, so it costs little
  // more than a box test. Either order of the two gives the same answer.
  const double tol = first.t * 1e-5 + 1e-7;
  const VisibilityScene::Hit second = v.nearestHit(origin, direction, ignore, first.surface,
                                                   std::max(first.t - tol, 0.0), first.t + tol);
  const bool firstBack = isBack(first.surface);
  if (second.surface == VisibilityScene::kNoSurface || isBack(second.surface) == firstBack)
    return firstBack ? RayStart::kInside : RayStart::kOutside;
  return RayStart::kUndecided;
}

std::vector<double> VisibilityScene::visibilityBatch(const std::vector<VisibilityQuery>& queries,
                                                     int k) const {
  std::vector<double> out(queries.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queries.size(), 16),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const VisibilityQuery& q = queries[i];
                        out[i] = visibility(q.a, q.b, k, q.seed, q.ignoreA, q.ignoreB);
                      }
                    });
  return out;
}

}  // namespace rad
