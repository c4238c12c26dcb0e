// Transmittance textures by projective shadows into per-sample bit masks. Sources in
// transmittance.h.
#include "libcommon/gl/gl_api.h"
// gl_api.h first: it must define GL_GLEXT_PROTOTYPES before any GL header.
#include "libcommon/movies/transmittance.h"

#include <algorithm>
#include <bitset>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include "libcommon/core/error.h"
#include "libcommon/gl/gl_context.h"

namespace rad {
namespace {

// Kensler 2013, "Correlated Multi-Jittered Sampling", listings 3 and 4 (hash-based
// permutation of [0, l) and a hashed float in [0, 1)).
uint32_t permute(uint32_t i, uint32_t l, uint32_t p) {
  uint32_t w = l - 1;
  w |= w >> 1;
  w |= w >> 2;
  w |= w >> 4;
  w |= w >> 8;
  w |= w >> 16;
  do {
    i ^= p;
    i *= 0xe170893du;
    i ^= p >> 16;
    i ^= (i & w) >> 4;
    i ^= p >> 8;
    i *= 0x0929eb3fu;
    i ^= p >> 23;
    i ^= (i & w) >> 1;
    i *= 1u | p >> 27;
    i *= 0x6935fa69u;
    i ^= (i & w) >> 11;
    i *= 0x74dcb303u;
    i ^= (i & w) >> 2;
    i *= 0x9e501cc3u;
    i ^= (i & w) >> 2;
    i *= 0xc860a3dfu;
    i &= w;
    i ^= i >> 5;
  } while (i >= l);
  return (i + p) % l;
}

double hashedUnit(uint32_t i, uint32_t p) {
  i ^= p;
  i ^= i >> 17;
  i ^= i >> 10;
  i *= 0xb36534e5u;
  i ^= i >> 12;
  i ^= i >> 21;
  i *= 0x93fc4795u;
  i ^= 0xdf6e307fu;
  i ^= i >> 17;
  i *= 1u | p >> 18;
  return double(i) * (1.0 / 4294967296.0);
}

// Row vector acting on (y, 1), shifted so it acts on (y - origin, 1) instead.
glm::dvec4 shiftRow(const glm::dvec4& row, const glm::dvec3& origin) {
  return {row.x, row.y, row.z, row.w + glm::dot(glm::dvec3(row), origin)};
}

// The largest distance of a vertex from the centroid.
double receiverRadius(const Polygon& r) {
  const glm::dvec3 centre = r.centroid();
  double size = 0.0;
  for (int k = 0; k < r.count; ++k) size = std::max(size, glm::length(r.v[k] - centre));
  return size;
}

// Plane basis of a receiver: origin v0, unit e1 along v0->v1, e2 = n x e1.
struct PlaneFrame {
  glm::dvec3 o, n, e1, e2;
  glm::dvec2 toPlane(const glm::dvec3& x) const {
    return {glm::dot(e1, x - o), glm::dot(e2, x - o)};
  }
};

PlaneFrame planeFrame(const Polygon& r) {
  PlaneFrame f;
  f.o = r.v[0];
  f.n = r.normal();
  glm::dvec3 e = r.v[1] - r.v[0];
  f.e1 = glm::length(e) > 0.0 ? glm::normalize(e) : glm::dvec3(1, 0, 0);
  f.e2 = glm::cross(f.n, f.e1);
  return f;
}

// Homography (Heckbert 1989, square-to-quad; affine for triangles) from the receiver's (u,v)
// to its plane coordinates, inverted: plane (q, 1) -> homogeneous (U, V, C), scaled so C > 0
// inside the polygon.
glm::dmat3 uvFromPlane(const Polygon& r, const PlaneFrame& f) {
  glm::dvec2 q[4];
  for (int k = 0; k < r.count; ++k) q[k] = f.toPlane(r.v[k]);
  double a, b, c, d, e, ff, g = 0.0, h = 0.0;
  if (r.count == 3) {
    a = q[1].x - q[0].x, b = q[2].x - q[0].x, c = q[0].x;
    d = q[1].y - q[0].y, e = q[2].y - q[0].y, ff = q[0].y;
  } else {
    double sx = q[0].x - q[1].x + q[2].x - q[3].x, sy = q[0].y - q[1].y + q[2].y - q[3].y;
    double dx1 = q[1].x - q[2].x, dx2 = q[3].x - q[2].x;
    double dy1 = q[1].y - q[2].y, dy2 = q[3].y - q[2].y;
    double det = dx1 * dy2 - dx2 * dy1;
    if (det != 0.0) {
      g = (sx * dy2 - dx2 * sy) / det;
      h = (dx1 * sy - sx * dy1) / det;
    }
    a = q[1].x - q[0].x + g * q[1].x, b = q[3].x - q[0].x + h * q[3].x, c = q[0].x;
    d = q[1].y - q[0].y + g * q[1].y, e = q[3].y - q[0].y + h * q[3].y, ff = q[0].y;
  }
  // glm is column-major: m[col][row]. Rows: (a b c), (d e ff), (g h 1).
  glm::dmat3 planeFromUv(glm::dvec3(a, d, g), glm::dvec3(b, e, h), glm::dvec3(c, ff, 1.0));
  glm::dmat3 inv = glm::inverse(planeFromUv);
  glm::dvec2 qc = f.toPlane(r.centroid());
  glm::dvec3 centre = inv * glm::dvec3(qc, 1.0);
  if (centre.z < 0.0) inv = -inv;
  return inv;
}

// Rows (acting on world (y,1)) of the homogeneous projection of y from `s` onto the plane:
// Ph(y) = ds y - d(y) s (3 rows) and W(y) = ds - d(y), where d is the signed distance to the
// plane and ds = d(s). The projected point is Ph / W.
void projectionRows(const PlaneFrame& f, const glm::dvec3& s, glm::dvec4 ph[3], glm::dvec4& w) {
  double nx0 = glm::dot(f.n, f.o);
  double ds = glm::dot(f.n, s) - nx0;
  w = glm::dvec4(-f.n, ds + nx0);
  for (int k = 0; k < 3; ++k) {
    glm::dvec3 unit(0.0);
    unit[k] = 1.0;
    ph[k] = glm::dvec4(ds * unit - s[k] * f.n, s[k] * nx0);
  }
}

// Clip rows (x, y, z, w) of the sample's projective shadow transform, world coordinates.
std::array<glm::dvec4, 4> clipRows(const Polygon& receiver, const glm::dvec3& s) {
  PlaneFrame f = planeFrame(receiver);
  glm::dmat3 hinv = uvFromPlane(receiver, f);
  glm::dvec4 ph[3], w;
  projectionRows(f, s, ph, w);
  // Homogeneous plane coordinates: q_i = e_i . (Ph - o W).
  glm::dvec4 qh[2];
  const glm::dvec3 axes[2] = {f.e1, f.e2};
  for (int i = 0; i < 2; ++i) {
    qh[i] = axes[i].x * ph[0] + axes[i].y * ph[1] + axes[i].z * ph[2] - glm::dot(axes[i], f.o) * w;
  }
  glm::dvec4 uvc[3];
  for (int r = 0; r < 3; ++r) uvc[r] = hinv[0][r] * qh[0] + hinv[1][r] * qh[1] + hinv[2][r] * w;
  return {2.0 * uvc[0] - uvc[2], 2.0 * uvc[1] - uvc[2], glm::dvec4(0.0), uvc[2]};
}

constexpr const char* kVertexShader = R"(#version 450 core
layout(location = 0) in vec3 position;
// One projective shadow transform and one eye-side clip row per shooter sample (instance).
layout(std140, binding = 0) uniform Samples {
  mat4 clipFromLocal[64];
  vec4 eyeRow[64];
};
uniform vec4 planeRow;
flat out uint vSample;
out gl_PerVertex {
  vec4 gl_Position;
  float gl_ClipDistance[2];
};
void main() {
  vec4 p = vec4(position, 1.0);
  vSample = uint(gl_InstanceID);
  gl_Position = clipFromLocal[gl_InstanceID] * p;
  // Only blockers strictly in front of the receiver plane and on the receiver's side of the
  // sample cast a shadow on the receiver.
  gl_ClipDistance[0] = dot(planeRow, p);
  gl_ClipDistance[1] = dot(eyeRow[gl_InstanceID], p);
}
)";

constexpr const char* kFragmentShader = R"(#version 450 core
flat in uint vSample;
layout(location = 0) out uvec2 mask;
void main() {
  mask = vSample < 32u ? uvec2(1u << vSample, 0u) : uvec2(0u, 1u << (vSample - 32u));
}
)";

}  // namespace

int transmittanceSampleCount(double maxFormFactor, double samplesPerFormFactor, int minSamples,
                             int maxSamples) {
  maxSamples = std::clamp(maxSamples, 1, kMaxTransmittanceSamples);
  minSamples = std::clamp(minSamples, 1, maxSamples);
  double want = std::isfinite(maxFormFactor) ? std::ceil(samplesPerFormFactor * maxFormFactor)
                                             : double(maxSamples);
  int n = int(std::clamp(want, double(minSamples), double(maxSamples)));
  int m = int(std::ceil(std::sqrt(double(n)) - 1e-9));
  while (m > 1 && m * m > maxSamples) --m;
  return std::max(1, m * m);
}

std::vector<glm::dvec2> multiJitteredPoints(int n, uint32_t seed) {
  int m = std::max(1, int(std::lround(std::sqrt(double(n)))));
  if (m * m != n) throw Error(ExitCode::kInternal, "transmittance", "sample count is not a square");
  std::vector<glm::dvec2> pts(static_cast<size_t>(n));
  const uint32_t p = seed;
  for (int s = 0; s < n; ++s) {
    uint32_t sx = permute(uint32_t(s % m), uint32_t(m), p * 0xa511e9b3u);
    uint32_t sy = permute(uint32_t(s / m), uint32_t(m), p * 0x63d83595u);
    double jx = hashedUnit(uint32_t(s), p * 0xa399d265u);
    double jy = hashedUnit(uint32_t(s), p * 0x711ad6a5u);
    pts[size_t(s)] = {((s % m) + (sy + jx) / m) / m, ((s / m) + (sx + jy) / m) / m};
  }
  return pts;
}

glm::dvec3 samplePointOnPolygon(const Polygon& p, glm::dvec2 a) {
  if (p.count == 4) {
    return (1 - a.x) * (1 - a.y) * p.v[0] + a.x * (1 - a.y) * p.v[1] + a.x * a.y * p.v[2] +
           (1 - a.x) * a.y * p.v[3];
  }
  double r = std::sqrt(a.x);
  double u = 1.0 - r, v = a.y * r;
  return p.v[0] + u * (p.v[1] - p.v[0]) + v * (p.v[2] - p.v[0]);
}

SampleMask frontSampleMask(const Polygon& receiver, const std::vector<glm::dvec3>& samples) {
  glm::dvec3 n = receiver.normal();
  double scale = 0.0;
  for (int k = 1; k < receiver.count; ++k)
    scale = std::max(scale, glm::length(receiver.v[k] - receiver.v[0]));
  SampleMask m = 0;
  for (size_t s = 0; s < samples.size() && s < size_t(kMaxTransmittanceSamples); ++s)
    if (glm::dot(n, samples[s] - receiver.v[0]) > 1e-9 * scale) m |= SampleMask(1) << s;
  return m;
}

double transmittanceFromMask(SampleMask occluded, SampleMask valid) {
  int n = int(std::bitset<64>(valid).count());
  if (n == 0) return 1.0;
  return double(std::bitset<64>(valid & ~occluded).count()) / n;
}

namespace {

// The point-to-area kernel cos(theta_x) cos(theta_s) / r^2 of shooter sample s seen from the
// texel at x (up to the 1 / pi and the r^2 the unnormalised directions carry); 0 at s = x.
double sampleKernel(const glm::dvec3& x, const glm::dvec3& n, const glm::dvec3& sample,
                    const glm::dvec3& shooterNormal) {
  const glm::dvec3 d = sample - x;
  const double r2 = glm::dot(d, d);
  if (!(r2 > 0.0)) return 0.0;
  return std::max(0.0, glm::dot(n, d)) * std::abs(glm::dot(shooterNormal, d)) / (r2 * r2);
}

}  // namespace

double kernelWeightedTransmittance(const glm::dvec3& x, const glm::dvec3& n,
                                   const std::vector<glm::dvec3>& samples,
                                   const glm::dvec3& shooterNormal, SampleMask occluded,
                                   SampleMask valid) {
  const SampleMask open = valid & ~occluded;
  if (open == valid) return 1.0;
  if (open == 0) return 0.0;
  double total = 0.0, seen = 0.0;
  const size_t count = std::min(samples.size(), size_t(kMaxTransmittanceSamples));
  for (size_t s = 0; s < count; ++s) {
    if (!((valid >> s) & 1u)) continue;
    const double k = sampleKernel(x, n, samples[s], shooterNormal);
    total += k;
    if ((open >> s) & 1u) seen += k;
  }
  return total > 0.0 ? seen / total : transmittanceFromMask(occluded, valid);
}

glm::dvec3 shapedTransmittance(const glm::dvec3& x, const glm::dvec3& n,
                               const std::vector<glm::dvec3>& samples,
                               const glm::dvec3& shooterNormal, SampleMask occluded,
                               SampleMask valid, const std::vector<glm::vec3>& shape) {
  const SampleMask open = valid & ~occluded;
  if (open == 0) return glm::dvec3(0.0);
  double total = 0.0;
  glm::dvec3 seen(0.0), plainSeen(0.0);
  int plainCount = 0;
  const size_t count = std::min({samples.size(), shape.size(), size_t(kMaxTransmittanceSamples)});
  for (size_t s = 0; s < count; ++s) {
    if (!((valid >> s) & 1u)) continue;
    ++plainCount;
    const bool isOpen = (open >> s) & 1u;
    if (isOpen) plainSeen += glm::dvec3(shape[s]);
    const double k = sampleKernel(x, n, samples[s], shooterNormal);
    total += k;
    if (isOpen) seen += k * glm::dvec3(shape[s]);
  }
  if (total > 0.0) return seen / total;
  return plainCount > 0 ? plainSeen / double(plainCount) : glm::dvec3(1.0);  // no weight
}

const char* mergeModeName(MergeMode m) {
  switch (m) {
    case MergeMode::kExact:
      return "exact";
    case MergeMode::kMax:
      return "max";
    case MergeMode::kSum:
      return "sum";
    case MergeMode::kIndependent:
      return "independent";
  }
  return "?";
}

double mergeTransmittance(MergeMode mode, double ts, double td) {
  double a = 1.0 - ts, b = 1.0 - td;  // occlusions
  double o = 0.0;
  switch (mode) {
    case MergeMode::kMax:
      o = std::max(a, b);
      break;
    case MergeMode::kSum:
      o = std::min(1.0, a + b);
      break;
    case MergeMode::kIndependent:
    case MergeMode::kExact:  // without the masks, independence is the best guess
      o = 1.0 - (1.0 - a) * (1.0 - b);
      break;
  }
  return std::clamp(1.0 - o, 0.0, 1.0);
}

glm::dmat4 projectiveShadowMatrix(const Polygon& receiver, const glm::dvec3& sample) {
  std::array<glm::dvec4, 4> rows = clipRows(receiver, sample);
  glm::dmat4 m(0.0);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m[c][r] = rows[size_t(r)][c];
  return m;
}

ReceiverTextureMap::ReceiverTextureMap(const Polygon& receiver) {
  PlaneFrame f = planeFrame(receiver);
  origin_ = f.o;
  e1_ = f.e1;
  e2_ = f.e2;
  uvFromPlane_ = uvFromPlane(receiver, f);
  planeFromUv_ = glm::inverse(uvFromPlane_);
}

glm::dvec3 ReceiverTextureMap::uvHomogeneous(const glm::dvec3& x) const {
  return uvFromPlane_ * glm::dvec3(glm::dot(e1_, x - origin_), glm::dot(e2_, x - origin_), 1.0);
}

glm::dvec3 ReceiverTextureMap::planePoint(glm::dvec2 uv) const {
  glm::dvec3 q = planeFromUv_ * glm::dvec3(uv, 1.0);
  return origin_ + (q.x / q.z) * e1_ + (q.y / q.z) * e2_;
}

double receiverFrontOffset(const Polygon& receiver) {
  return 1e-6 * receiverRadius(receiver);
}

glm::dvec2 receiverPlaneUv(const Polygon& receiver, const glm::dvec3& x) {
  glm::dvec3 h = ReceiverTextureMap(receiver).uvHomogeneous(x);
  return {h.x / h.z, h.y / h.z};
}

struct TransmittanceRenderer::Impl {
  GlContext context;  // first member: destroyed last
  GLuint program = 0, vao = 0, vbo = 0, ubo = 0, fbo = 0, maskTexture = 0;
  GLint planeRowLocation = -1;
  int width = 0, height = 0, maxSize = 0;
  long passes = 0, samplePasses = 0, trianglesDrawn = 0;
  std::vector<float> vertices;
  std::vector<uint32_t> readback;

  Impl() {
    GLint maxTexture = 0, maxViewport[2] = {0, 0};
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxTexture);
    glGetIntegerv(GL_MAX_VIEWPORT_DIMS, maxViewport);
    maxSize = std::min({maxTexture, maxViewport[0], maxViewport[1]});
    program = compileProgram("transmittance", kVertexShader, kFragmentShader);
    planeRowLocation = glGetUniformLocation(program, "planeRow");
    GLuint block = glGetUniformBlockIndex(program, "Samples");
    glUniformBlockBinding(program, block, 0);
    glGenVertexArrays(1, &vao);
    glGenBuffers(1, &vbo);
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
    glEnableVertexAttribArray(0);
    glBindVertexArray(0);
    glGenBuffers(1, &ubo);
    glBindBuffer(GL_UNIFORM_BUFFER, ubo);
    glBufferData(GL_UNIFORM_BUFFER, kUboBytes, nullptr, GL_DYNAMIC_DRAW);
    glGenFramebuffers(1, &fbo);
    checkGlError("transmittance: setup");
  }

  static constexpr size_t kUboBytes = 64 * 64 + 64 * 16;

  void resize(int w, int h) {
    if (w == width && h == height) return;
    if (w < 1 || h < 1 || w > maxSize || h > maxSize)
      throw Error(ExitCode::kEnvironment, "osmesa",
                  "transmittance texture " + std::to_string(w) + "x" + std::to_string(h) +
                      " outside 1.." + std::to_string(maxSize));
    if (maskTexture) glDeleteTextures(1, &maskTexture);
    glGenTextures(1, &maskTexture);
    glBindTexture(GL_TEXTURE_2D, maskTexture);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RG32UI, w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, maskTexture, 0);
    const GLenum drawBuffer = GL_COLOR_ATTACHMENT0;
    glDrawBuffers(1, &drawBuffer);
    GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
      char buf[16];
      std::snprintf(buf, sizeof buf, "%x", status);
      throw Error(ExitCode::kEnvironment, "osmesa",
                  std::string("transmittance framebuffer incomplete (status 0x") + buf + ")");
    }
    width = w;
    height = h;
    checkGlError("transmittance: target");
  }

  ~Impl() {
    try {
      context.makeCurrent();
    } catch (...) {
      return;
    }
    glDeleteFramebuffers(1, &fbo);
    if (maskTexture) glDeleteTextures(1, &maskTexture);
    glDeleteBuffers(1, &ubo);
    glDeleteBuffers(1, &vbo);
    glDeleteVertexArrays(1, &vao);
    glDeleteProgram(program);
  }
};

TransmittanceRenderer::TransmittanceRenderer() : impl_(std::make_unique<Impl>()) {}
TransmittanceRenderer::~TransmittanceRenderer() = default;

long TransmittanceRenderer::passes() const {
  return impl_->passes;
}
long TransmittanceRenderer::samplePasses() const {
  return impl_->samplePasses;
}
long TransmittanceRenderer::trianglesDrawn() const {
  return impl_->trianglesDrawn;
}
std::string TransmittanceRenderer::rendererName() const {
  return impl_->context.renderer();
}

void TransmittanceRenderer::render(const Polygon& receiver, int width, int height,
                                   const std::vector<glm::dvec3>& samples,
                                   const std::vector<BlockerTriangle>& blockers,
                                   std::vector<SampleMask>& out) {
  Impl& m = *impl_;
  if (samples.empty() || samples.size() > size_t(kMaxTransmittanceSamples))
    throw Error(ExitCode::kInternal, "transmittance",
                std::to_string(samples.size()) + " samples; expected 1..64");
  out.assign(size_t(width) * height, 0);
  SampleMask valid = frontSampleMask(receiver, samples);
  if (blockers.empty() || valid == 0) return;

  // Coordinates relative to the receiver's centroid keep float precision at any scene scale.
  const glm::dvec3 origin = receiver.centroid();
  const double size = receiverRadius(receiver);
  const glm::dvec3 n = receiver.normal();

  // Per-sample transforms (std140: mat4[64] then vec4[64]).
  std::vector<float> ubo(Impl::kUboBytes / sizeof(float), 0.0f);
  for (size_t s = 0; s < samples.size(); ++s) {
    float* mat = &ubo[s * 16];
    float* eye = &ubo[64 * 16 + s * 4];
    if (!(valid >> s & 1)) {
      eye[3] = -1.0f;  // clips everything: this sample sees the receiver's back
      continue;
    }
    std::array<glm::dvec4, 4> rows = clipRows(receiver, samples[s]);
    // Normalise the rows (a common positive factor leaves the projection unchanged).
    double scale = 0.0;
    for (const glm::dvec4& r : rows)
      scale = std::max(scale, glm::length(glm::dvec3(r)) * std::max(size, 1e-300));
    for (int r = 0; r < 4; ++r) {
      glm::dvec4 row = shiftRow(rows[size_t(r)], origin) / scale;
      for (int c = 0; c < 4; ++c) mat[c * 4 + r] = float(row[c]);
    }
    // W(y) = ds - d(y) >= 0: the blocker is not behind the sample (as seen from the plane).
    double ds = glm::dot(n, samples[s] - receiver.v[0]);
    glm::dvec4 eyeRow = shiftRow(glm::dvec4(-n, ds + glm::dot(n, receiver.v[0])), origin) / ds;
    for (int c = 0; c < 4; ++c) eye[c] = float(eyeRow[c]);
  }
  // d(y) > delta: strictly in front of the receiver plane.
  const double delta = receiverFrontOffset(receiver);
  glm::dvec4 planeRow = shiftRow(glm::dvec4(n, -glm::dot(n, receiver.v[0]) - delta), origin);
  planeRow /= std::max(size, 1e-300);

  m.vertices.clear();
  m.vertices.reserve(blockers.size() * 9);
  for (const BlockerTriangle& t : blockers)
    for (const glm::dvec3& p : t)
      for (int c = 0; c < 3; ++c) m.vertices.push_back(float(p[c] - origin[c]));

  m.context.makeCurrent();
  m.resize(width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, m.fbo);
  glViewport(0, 0, width, height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glDisable(GL_DITHER);
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_DEPTH_CLAMP);
  glEnable(GL_CLIP_DISTANCE0);
  glEnable(GL_CLIP_DISTANCE1);
  glEnable(GL_COLOR_LOGIC_OP);
  glLogicOp(GL_OR);
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  const GLuint zero[4] = {0, 0, 0, 0};
  glClearBufferuiv(GL_COLOR, 0, zero);

  glUseProgram(m.program);
  glBindBuffer(GL_UNIFORM_BUFFER, m.ubo);
  glBufferSubData(GL_UNIFORM_BUFFER, 0, GLsizeiptr(Impl::kUboBytes), ubo.data());
  glBindBufferBase(GL_UNIFORM_BUFFER, 0, m.ubo);
  glm::vec4 pr(planeRow);
  glUniform4fv(m.planeRowLocation, 1, &pr[0]);
  glBindVertexArray(m.vao);
  glBindBuffer(GL_ARRAY_BUFFER, m.vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(m.vertices.size() * sizeof(float)), m.vertices.data(),
               GL_STREAM_DRAW);
  glDrawArraysInstanced(GL_TRIANGLES, 0, GLsizei(blockers.size() * 3), GLsizei(samples.size()));

  m.readback.resize(size_t(width) * height * 2);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, width, height, GL_RG_INTEGER, GL_UNSIGNED_INT, m.readback.data());
  glDisable(GL_COLOR_LOGIC_OP);
  glDisable(GL_CLIP_DISTANCE0);
  glDisable(GL_CLIP_DISTANCE1);
  glBindVertexArray(0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  checkGlError("transmittance: render");
  // GL row 0 is window y = 0, i.e. v = 0: the texture's row j = 0. No flip.
  for (size_t i = 0; i < out.size(); ++i)
    out[i] = (SampleMask(m.readback[2 * i + 1]) << 32 | m.readback[2 * i]) & valid;
  ++m.passes;
  m.samplePasses += long(samples.size());
  m.trianglesDrawn += long(blockers.size() * samples.size());
}

}  // namespace rad
