// Ray-cast occlusion masks and the adaptive choice between them and the projective render
// (ray_cast_masks.h).
#include "libcommon/movies/ray_cast_masks.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "libcommon/core/error.h"
#include "libcommon/movies/transmittance.h"

namespace rad {
namespace {

// A blocker triangle ready for the Moller-Trumbore test (Moller & Trumbore 1997, "Fast,
// minimum storage ray-triangle intersection").
struct PreparedTriangle {
  glm::dvec3 a, e1, e2;
};

// Whether the segment P + t (s - P), tMin < t <= 1, meets the triangle (edges included).
bool crosses(const PreparedTriangle& tri, const glm::dvec3& p, const glm::dvec3& dir, double tMin) {
  const glm::dvec3 pvec = glm::cross(dir, tri.e2);
  const double det = glm::dot(tri.e1, pvec);
  if (!(std::abs(det) > 0.0)) return false;  // seen edge-on: covers no point
  const double inv = 1.0 / det;
  const glm::dvec3 tvec = p - tri.a;
  const double u = glm::dot(tvec, pvec) * inv;
  if (u < 0.0 || u > 1.0) return false;
  const glm::dvec3 qvec = glm::cross(tvec, tri.e1);
  const double v = glm::dot(dir, qvec) * inv;
  if (v < 0.0 || u + v > 1.0) return false;
  const double t = glm::dot(tri.e2, qvec) * inv;
  return t > tMin && t <= 1.0;
}

// Sets bit s of every texel whose centre lies in the convex polygon uv[0..count) of the
// texture's (u,v) square (edges included): the texels a blocker's shadow from sample s covers.
// The shadow of a convex polygon between the plane and the sample is the convex polygon of its
// vertices' shadows, and the homography keeps it one while C > 0 at its corners.
void coverConvex(const glm::dvec2* uv, int count, int s, int width, int height,
                 std::vector<SampleMask>& out) {
  double area = 0.0;
  for (int e = 0; e < count; ++e) {
    const glm::dvec2 &a = uv[e], &b = uv[(e + 1) % count];
    area += a.x * b.y - b.x * a.y;
  }
  if (!(area != 0.0)) return;  // seen edge-on: covers no point
  const double sign = area > 0.0 ? 1.0 : -1.0;
  glm::dvec2 lo = uv[0], hi = uv[0];
  for (int e = 1; e < count; ++e) {
    lo = glm::min(lo, uv[e]);
    hi = glm::max(hi, uv[e]);
  }
  // Texel i's centre is at u = (i + .5) / width.
  const int i0 = int(std::clamp(std::ceil(lo.x * width - 0.5), 0.0, double(width)));
  const int i1 = int(std::clamp(std::floor(hi.x * width - 0.5), -1.0, double(width - 1)));
  const int j0 = int(std::clamp(std::ceil(lo.y * height - 0.5), 0.0, double(height)));
  const int j1 = int(std::clamp(std::floor(hi.y * height - 0.5), -1.0, double(height - 1)));
  const SampleMask bit = SampleMask(1) << s;
  // Row by row: each edge bounds u on one side, (u - a.x) d <= c with c and d below.
  for (int j = j0; j <= j1; ++j) {
    const double v = (j + 0.5) / height;
    double uLo = -std::numeric_limits<double>::infinity(), uHi = -uLo;
    bool empty = false;
    for (int e = 0; e < count && !empty; ++e) {
      const glm::dvec2 &a = uv[e], &b = uv[(e + 1) % count];
      const double c = sign * (b.x - a.x) * (v - a.y), d = sign * (b.y - a.y);
      if (d > 0.0)
        uHi = std::min(uHi, a.x + c / d);
      else if (d < 0.0)
        uLo = std::max(uLo, a.x + c / d);
      else
        empty = c < 0.0;
    }
    if (empty || !(uLo <= uHi)) continue;
    const int first =
        std::max(i0, int(std::clamp(std::ceil(uLo * width - 0.5), -1.0, double(width))));
    const int last =
        std::min(i1, int(std::clamp(std::floor(uHi * width - 0.5), -1.0, double(width))));
    SampleMask* row = &out[size_t(j) * size_t(width)];
    for (int i = first; i <= last; ++i) row[i] |= bit;
  }
}

// Sutherland-Hodgman against one plane: keeps the part of the convex polygon p[0..count) where
// keep(h) with h its height, the cut where h = cut. Returns the new count (<= count + 1).
template <class Keep>
int clipByHeight(const glm::dvec3* p, const double* h, int count, double cut, Keep keep,
                 glm::dvec3* outP, double* outH) {
  int m = 0;
  for (int e = 0; e < count; ++e) {
    const int f = (e + 1) % count;
    const bool ke = keep(h[e]), kf = keep(h[f]);
    if (ke) {
      outP[m] = p[e];
      outH[m++] = h[e];
    }
    if (ke != kf) {
      const double t = (cut - h[e]) / (h[f] - h[e]);
      outP[m] = p[e] + t * (p[f] - p[e]);
      outH[m++] = cut;
    }
  }
  return m;
}

}  // namespace

double rayCastMaskCost(int width, int height, size_t samples) {
  return double(width) * double(height) * double(samples);
}

void RayCastMaskRenderer::render(const Polygon& receiver, int width, int height,
                                 const std::vector<glm::dvec3>& samples,
                                 const std::vector<BlockerTriangle>& blockers,
                                 std::vector<SampleMask>& out) {
  if (samples.empty() || samples.size() > size_t(kMaxTransmittanceSamples))
    throw Error(ExitCode::kInternal, "transmittance",
                std::to_string(samples.size()) + " samples; expected 1..64");
  out.assign(size_t(width) * size_t(height), 0);
  const SampleMask valid = frontSampleMask(receiver, samples);
  if (blockers.empty() || valid == 0) return;

  // The projective render's clip planes: strictly in front of the receiver plane by delta, and
  // not beyond the sample.
  const double delta = receiverFrontOffset(receiver);
  const glm::dvec3 n = receiver.normal();
  std::vector<double> sampleHeight(samples.size(), 0.0);
  for (size_t s = 0; s < samples.size(); ++s)
    if (valid >> s & 1) sampleHeight[s] = glm::dot(n, samples[s] - receiver.v[0]);
  const ReceiverTextureMap map(receiver);
  points_.clear();  // the texel centres' plane points, made for the fallback only

  for (const BlockerTriangle& b : blockers) {
    double hv[3];
    for (int c = 0; c < 3; ++c) hv[c] = glm::dot(n, b[size_t(c)] - receiver.v[0]);
    // A triangle wholly on or behind the plane's offset crosses no segment.
    if (std::max({hv[0], hv[1], hv[2]}) <= delta) continue;
    const PreparedTriangle tri{b[0], b[1] - b[0], b[2] - b[0]};
    for (SampleMask left = valid; left; left &= left - 1) {
      const int s = __builtin_ctzll(left);
      const glm::dvec3& eye = samples[size_t(s)];
      const double ds = sampleHeight[size_t(s)];
      // The part between the plane's offset and the sample (clipped when it reaches past
      // either; a point at the sample's own height could only meet the segment at the sample),
      // and its shadow in (u,v).
      glm::dvec3 p0[3] = {b[0], b[1], b[2]}, p1[4], p2[5];
      double h1[4], h2[5];
      const double top = ds * (1.0 - 1e-9);
      int count = clipByHeight(
          p0, hv, 3, delta, [delta](double h) { return h > delta; }, p1, h1);
      count = clipByHeight(
          p1, h1, count, top, [top](double h) { return h < top; }, p2, h2);
      if (count < 3) continue;
      bool projectable = true;
      glm::dvec2 uv[5];
      for (int c = 0; c < count && projectable; ++c) {
        const glm::dvec3 onPlane = eye + (p2[c] - eye) * (ds / (ds - h2[c]));
        const glm::dvec3 h = map.uvHomogeneous(onPlane);
        projectable = h.z > 0.0;
        uv[c] = glm::dvec2(h.x, h.y) / h.z;
      }
      if (projectable) {
        coverConvex(uv, count, s, width, height, out);
        continue;
      }
      // Else (a quad receiver's homography turns over within the shadow): the segment test at
      // every texel.
      if (points_.empty())
        for (int j = 0; j < height; ++j)
          for (int i = 0; i < width; ++i)
            points_.push_back(map.planePoint({(i + 0.5) / width, (j + 0.5) / height}));
      const SampleMask bit = SampleMask(1) << s;
      for (size_t x = 0; x < out.size(); ++x)
        if (!(out[x] & bit) && crosses(tri, points_[x], eye - points_[x], delta / ds))
          out[x] |= bit;
    }
  }
  ++passes_;
  samplePasses_ += long(samples.size());
}

AdaptiveMaskRenderer::AdaptiveMaskRenderer(double budget, OcclusionMaskRendererFactory projective)
    : budget_(budget), makeProjective_(std::move(projective)) {}
AdaptiveMaskRenderer::~AdaptiveMaskRenderer() = default;

void AdaptiveMaskRenderer::render(const Polygon& receiver, int width, int height,
                                  const std::vector<glm::dvec3>& samples,
                                  const std::vector<BlockerTriangle>& blockers,
                                  std::vector<SampleMask>& out) {
  if (budget_ > 0.0 && rayCastMaskCost(width, height, samples.size()) <= budget_) {
    rayCast_.render(receiver, width, height, samples, blockers, out);
    return;
  }
  if (!projective_) projective_ = makeProjective_();
  projective_->render(receiver, width, height, samples, blockers, out);
}

long AdaptiveMaskRenderer::passes() const {
  return rayCast_.passes() + (projective_ ? projective_->passes() : 0);
}
long AdaptiveMaskRenderer::samplePasses() const {
  return rayCast_.samplePasses() + (projective_ ? projective_->samplePasses() : 0);
}
std::string AdaptiveMaskRenderer::rendererName() const {
  if (!projective_) return rayCast_.rendererName();
  return projective_->rendererName() + " + " + rayCast_.rendererName();
}

}  // namespace rad
