// Item buffer rendering with OSMesa. Sources in item_buffer.h.
#include "libcommon/gl/gl_api.h"
// gl_api.h first: it must define GL_GLEXT_PROTOTYPES before any GL header.
#include "libcommon/gl/item_buffer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "libcommon/core/error.h"
#include "libcommon/gl/clip_volume_cull.h"

namespace rad {
namespace {

constexpr const char* kVertexShader = R"(#version 450 core
layout(location = 0) in vec3 position;
layout(location = 1) in uint itemId;
uniform mat4 clipFromLocal;
// Row of eye-from-local giving -z_eye: eye depth is affine in position, so perspective-correct
// interpolation reproduces it exactly across a planar triangle.
uniform vec4 depthFromLocal;
flat out uint vItemId;
out float vDepth;
void main() {
  vItemId = itemId;
  vDepth = dot(depthFromLocal, vec4(position, 1.0));
  gl_Position = clipFromLocal * vec4(position, 1.0);
}
)";

constexpr const char* kFragmentShader = R"(#version 450 core
flat in uint vItemId;
in float vDepth;
layout(location = 0) out uint outItemId;
layout(location = 1) out float outDepth;
void main() {
  outItemId = vItemId;
  outDepth = vDepth;
}
)";

// The ids alone (ItemBufferOptions::readDepth false): no depth varying to set up and interpolate
// and no second output, so llvmpipe's fragment stage does less a sample. gl_Position is computed
// as in kVertexShader, so the same samples pass the depth test and the ids are the same.
constexpr const char* kIdsOnlyVertexShader = R"(#version 450 core
layout(location = 0) in vec3 position;
layout(location = 1) in uint itemId;
uniform mat4 clipFromLocal;
flat out uint vItemId;
void main() {
  vItemId = itemId;
  gl_Position = clipFromLocal * vec4(position, 1.0);
}
)";

constexpr const char* kIdsOnlyFragmentShader = R"(#version 450 core
flat in uint vItemId;
layout(location = 0) out uint outItemId;
void main() {
  outItemId = vItemId;
}
)";

struct Vertex {
  float x, y, z;
  uint32_t id;
};
static_assert(sizeof(Vertex) == 16, "tightly packed vertex");

struct DrawRange {
  GLint first = 0;
  GLsizei count = 0;
  // Of the float vertices drawn (empty for no vertex): the object is skipped in a frame whose
  // clip volume it lies outside (clip_volume_cull.h).
  LocalBounds bounds{glm::vec3(INFINITY), glm::vec3(-INFINITY)};
};

// Flips rows in place: GL reads bottom-up, our buffers are top-down.
template <typename T>
void flipRows(std::vector<T>& data, int width, int height) {
  for (int top = 0, bottom = height - 1; top < bottom; ++top, --bottom)
    std::swap_ranges(data.begin() + size_t(top) * width, data.begin() + size_t(top + 1) * width,
                     data.begin() + size_t(bottom) * width);
}

}  // namespace

void ItemObject::addTriangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                             uint32_t id) {
  triangles.push_back({a, b, c});
  ids.push_back(id);
}

void ItemObject::addPolygon(const Polygon& polygon, uint32_t id) {
  for (int i = 1; i + 1 < polygon.count; ++i)
    addTriangle(polygon.v[0], polygon.v[i], polygon.v[i + 1], id);
}

struct ItemBufferRenderer::Impl {
  GlContext context;  // first member: destroyed last, after the GL objects below
  SampleGrid grid;    // the image the projection is of, and the samples drawn
  ImageSize size;     // grid.size(): the buffer's
  ItemBufferOptions options;
  GLuint program = 0, idsOnlyProgram = 0, vao = 0, vbo = 0, fbo = 0;
  GLuint idTexture = 0, depthTexture = 0, depthRenderbuffer = 0;
  GLint clipFromLocalLocation = -1, depthFromLocalLocation = -1;
  GLint idsOnlyClipFromLocalLocation = -1;
  std::vector<DrawRange> ranges;

  Impl(const SampleGrid& g, ItemBufferOptions o) : grid(g), size(g.size()), options(o) {
    GLint maxTexture = 0, maxRenderbuffer = 0, maxViewport[2] = {0, 0};
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxTexture);
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &maxRenderbuffer);
    glGetIntegerv(GL_MAX_VIEWPORT_DIMS, maxViewport);
    int limit = std::min({maxTexture, maxRenderbuffer, maxViewport[0], maxViewport[1]});
    if (size.width <= 0 || size.height <= 0 || size.width > limit || size.height > limit)
      throw Error(ExitCode::kEnvironment, "osmesa",
                  "item buffer " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                      " outside 1.." + std::to_string(limit));

    program = compileProgram("item buffer", kVertexShader, kFragmentShader);
    clipFromLocalLocation = glGetUniformLocation(program, "clipFromLocal");
    depthFromLocalLocation = glGetUniformLocation(program, "depthFromLocal");
    idsOnlyProgram =
        compileProgram("item buffer (ids only)", kIdsOnlyVertexShader, kIdsOnlyFragmentShader);
    idsOnlyClipFromLocalLocation = glGetUniformLocation(idsOnlyProgram, "clipFromLocal");

    glGenVertexArrays(1, &vao);
    glGenBuffers(1, &vbo);
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), nullptr);
    glEnableVertexAttribArray(0);
    // Integer attribute: the id reaches the shader bit-exact (no float conversion).
    glVertexAttribIPointer(1, 1, GL_UNSIGNED_INT, sizeof(Vertex),
                           reinterpret_cast<const void*>(offsetof(Vertex, id)));
    glEnableVertexAttribArray(1);

    glGenTextures(1, &idTexture);
    glBindTexture(GL_TEXTURE_2D, idTexture);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_R32UI, size.width, size.height);
    glGenTextures(1, &depthTexture);
    glBindTexture(GL_TEXTURE_2D, depthTexture);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_R32F, size.width, size.height);
    glGenRenderbuffers(1, &depthRenderbuffer);
    glBindRenderbuffer(GL_RENDERBUFFER, depthRenderbuffer);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, size.width, size.height);

    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, idTexture, 0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, depthTexture, 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                              depthRenderbuffer);
    const GLenum drawBuffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glDrawBuffers(2, drawBuffers);
    GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE)
      throw Error(ExitCode::kEnvironment, "osmesa",
                  "item buffer framebuffer incomplete (status 0x" + toHex(status) + ")");
    checkGlError("item buffer: setup");
  }

  static std::string toHex(unsigned v) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "%x", v);
    return buf;
  }

  ~Impl() {
    // Deleting needs the context current; never throw from a destructor.
    try {
      context.makeCurrent();
    } catch (...) {
      return;
    }
    glDeleteFramebuffers(1, &fbo);
    glDeleteRenderbuffers(1, &depthRenderbuffer);
    glDeleteTextures(1, &depthTexture);
    glDeleteTextures(1, &idTexture);
    glDeleteBuffers(1, &vbo);
    glDeleteVertexArrays(1, &vao);
    glDeleteProgram(idsOnlyProgram);
    glDeleteProgram(program);
  }
};

ItemBufferRenderer::ItemBufferRenderer(ImageSize size, ItemBufferOptions options)
    : ItemBufferRenderer(SampleGrid{size, 1, 0}, options) {}

ItemBufferRenderer::ItemBufferRenderer(const SampleGrid& grid, ItemBufferOptions options)
    : impl_(std::make_unique<Impl>(grid, options)) {}

const SampleGrid& ItemBufferRenderer::grid() const {
  return impl_->grid;
}

ItemBufferRenderer::~ItemBufferRenderer() = default;

ImageSize ItemBufferRenderer::size() const {
  return impl_->size;
}
const ItemBufferOptions& ItemBufferRenderer::options() const {
  return impl_->options;
}
void ItemBufferRenderer::setOptions(const ItemBufferOptions& options) {
  impl_->options = options;
}
size_t ItemBufferRenderer::objectCount() const {
  return impl_->ranges.size();
}

void ItemBufferRenderer::setGeometry(const std::vector<ItemObject>& objects) {
  std::vector<Vertex> vertices;
  std::vector<DrawRange> ranges;
  size_t total = 0;
  for (const ItemObject& o : objects) total += o.triangles.size();
  if (total * 3 > size_t(std::numeric_limits<GLint>::max()))
    throw Error(ExitCode::kEnvironment, "item buffer", "too many triangles");
  vertices.reserve(total * 3);
  for (size_t k = 0; k < objects.size(); ++k) {
    const ItemObject& o = objects[k];
    if (o.ids.size() != o.triangles.size())
      throw Error(ExitCode::kInternal, "item buffer",
                  "object " + std::to_string(k) + " has " + std::to_string(o.triangles.size()) +
                      " triangles but " + std::to_string(o.ids.size()) + " ids");
    DrawRange r;
    r.first = GLint(vertices.size());
    for (size_t t = 0; t < o.triangles.size(); ++t) {
      if (o.ids[t] == kNoItem)
        throw Error(ExitCode::kInternal, "item buffer",
                    "object " + std::to_string(k) + " triangle " + std::to_string(t) +
                        " has the reserved id 0");
      for (const glm::dvec3& p : o.triangles[t]) {
        vertices.push_back({float(p.x), float(p.y), float(p.z), o.ids[t]});
        const glm::vec3 v(vertices.back().x, vertices.back().y, vertices.back().z);
        r.bounds = {glm::min(r.bounds[0], v), glm::max(r.bounds[1], v)};
      }
    }
    r.count = GLsizei(vertices.size()) - r.first;
    ranges.push_back(r);
  }
  impl_->context.makeCurrent();
  glBindBuffer(GL_ARRAY_BUFFER, impl_->vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices.size() * sizeof(Vertex)), vertices.data(),
               GL_STATIC_DRAW);
  checkGlError("item buffer: geometry upload");
  impl_->ranges = std::move(ranges);
}

ItemBuffer ItemBufferRenderer::render(const CameraView& view,
                                      const std::vector<glm::dmat4>& objectTransforms) {
  ItemBuffer out;
  render(view, objectTransforms, out);
  return out;
}

void ItemBufferRenderer::render(const CameraView& view,
                                const std::vector<glm::dmat4>& objectTransforms, ItemBuffer& out) {
  Impl& m = *impl_;
  if (objectTransforms.size() != m.ranges.size())
    throw Error(ExitCode::kInternal, "item buffer",
                std::to_string(objectTransforms.size()) + " transforms for " +
                    std::to_string(m.ranges.size()) + " objects");
  const ImageSize size = m.size;
  // Validates the lens before any GL state changes.
  const glm::dmat4 eyeFromWorld = viewMatrix(view);
  (void)reversedZProjectionMatrix(view.lens, m.grid.image);

  m.context.makeCurrent();
  glBindFramebuffer(GL_FRAMEBUFFER, m.fbo);
  // Without readDepth the depth target is not drawn at all (the depth buffer still decides
  // occlusion): half the colour writes.
  const GLenum drawBuffers[2] = {
      GL_COLOR_ATTACHMENT0, m.options.readDepth ? GLenum(GL_COLOR_ATTACHMENT1) : GLenum(GL_NONE)};
  glDrawBuffers(2, drawBuffers);
  glViewport(0, 0, size.width, size.height);
  configureReversedZ();
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
  glDisable(GL_DITHER);
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_COLOR_LOGIC_OP);
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  glFrontFace(GL_CCW);
  if (m.options.cullBackFaces) {
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
  } else {
    glDisable(GL_CULL_FACE);
  }

  const GLuint noItem[4] = {kNoItem, 0, 0, 0};
  const GLfloat farDepth[4] = {std::numeric_limits<float>::infinity(), 0, 0, 0};
  const GLfloat clearDepth = 0.0f;  // reversed Z: 0 is infinitely far
  glClearBufferuiv(GL_COLOR, 0, noItem);
  if (m.options.readDepth) glClearBufferfv(GL_COLOR, 1, farDepth);
  glClearBufferfv(GL_DEPTH, 0, &clearDepth);

  const bool depth = m.options.readDepth;
  glUseProgram(depth ? m.program : m.idsOnlyProgram);
  const GLint clipLocation = depth ? m.clipFromLocalLocation : m.idsOnlyClipFromLocalLocation;
  glBindVertexArray(m.vao);
  for (size_t k = 0; k < m.ranges.size(); ++k) {
    const DrawRange& r = m.ranges[k];
    if (r.count == 0) continue;
    const glm::dmat4& worldFromLocal = objectTransforms[k];
    glm::mat4 clip =
        m.grid.isPixelCentres()
            ? rasterClipFromLocal(view, size, worldFromLocal)
            : rasterClipFromLocal(view, m.grid.image, worldFromLocal, m.grid.ndcScale());
    if (outsideClipVolume(clip, r.bounds)) continue;
    glUniformMatrix4fv(clipLocation, 1, GL_FALSE, &clip[0][0]);
    if (depth) {
      glm::dmat4 eyeFromLocal = eyeFromWorld * worldFromLocal;
      // Row 2 of eyeFromLocal (glm is column-major), negated: depth = -z_eye.
      glm::vec4 depthRow(-eyeFromLocal[0][2], -eyeFromLocal[1][2], -eyeFromLocal[2][2],
                         -eyeFromLocal[3][2]);
      glUniform4fv(m.depthFromLocalLocation, 1, &depthRow[0]);
    }
    glDrawArrays(GL_TRIANGLES, r.first, r.count);
  }

  out.width = size.width;
  out.height = size.height;
  out.id.resize(size_t(size.pixelCount()));
  out.depth.resize(m.options.readDepth ? size_t(size.pixelCount()) : 0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, size.width, size.height, GL_RED_INTEGER, GL_UNSIGNED_INT, out.id.data());
  if (m.options.readDepth) {
    glReadBuffer(GL_COLOR_ATTACHMENT1);
    glReadPixels(0, 0, size.width, size.height, GL_RED, GL_FLOAT, out.depth.data());
  }
  glBindVertexArray(0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  checkGlError("item buffer: render");
  flipRows(out.id, size.width, size.height);
  if (m.options.readDepth) flipRows(out.depth, size.width, size.height);
}

ItemBuffer pixelCentreSamples(const ItemBuffer& samples, const SampleGrid& grid) {
  const ImageSize g = grid.size();
  if (samples.width != g.width || samples.height != g.height)
    throw Error(ExitCode::kInternal, "item buffer", "not the sample grid's size");
  if (grid.isPixelCentres()) return samples;
  ItemBuffer out;
  out.width = grid.image.width;
  out.height = grid.image.height;
  out.id.resize(size_t(grid.image.pixelCount()));
  const bool depth = !samples.depth.empty();  // readDepth
  out.depth.resize(depth ? out.id.size() : 0);
  for (int row = 0; row < out.height; ++row)
    for (int col = 0; col < out.width; ++col) {
      const size_t p = size_t(row) * out.width + col;
      const size_t q = size_t(grid.centre(row)) * g.width + size_t(grid.centre(col));
      out.id[p] = samples.id[q];
      if (depth) out.depth[p] = samples.depth[q];
    }
  return out;
}

ItemBuffer renderItemBuffer(const std::vector<ItemTriangle>& worldTriangles, const CameraView& view,
                            ImageSize size, ItemBufferOptions options) {
  ItemObject object;
  object.triangles.reserve(worldTriangles.size());
  object.ids.reserve(worldTriangles.size());
  for (const ItemTriangle& t : worldTriangles) object.addTriangle(t.p[0], t.p[1], t.p[2], t.id);
  ItemBufferRenderer renderer(size, options);
  renderer.setGeometry({object});
  return renderer.render(view, {glm::dmat4(1.0)});
}

}  // namespace rad
