// Item buffers: per pixel, the id of the nearest visible patch and its depth (Martín, Pueyo,
// Tost, "Frame rate independent texture movies for animated radiosity", §4.1 and §4.3; the
// item buffer itself goes back to Weghorst, Hooper, Greenberg 1984, "Improved computational
// methods for ray tracing"). rad-intervals renders one per frame to find which patches are
// visible, at what level and resolution (docs/design.md §6.2).
//
// Rendered with OpenGL through OSMesa into an integer GL_R32UI target (ids are exact, no
// colour encoding) plus an R32F target carrying eye-space depth, with a reversed-Z
// GL_DEPTH_COMPONENT32F depth buffer for occlusion (camera_projection.h explains why). The
// projection is camera_projection.h's, so rad-compose and the CPU ray casters agree with it
// pixel-exactly.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/gl/gl_context.h"
#include "libcommon/scene/camera_projection.h"
#include "libcommon/scene/geometry.h"
#include "libcommon/scene/sample_grid.h"

namespace rad {

// Item id 0 means "nothing"; patches use 1..2^32-1.
constexpr uint32_t kNoItem = 0;

struct ItemBuffer {
  int width = 0, height = 0;
  // Row-major, row 0 = top of the image (camera_projection.h's pixel convention).
  std::vector<uint32_t> id;  // kNoItem where nothing is visible
  // Eye-space depth (distance from the eye plane along the view axis, metres) of the visible
  // surface; +inf where id is kNoItem. Empty when rendered without ItemBufferOptions::readDepth.
  std::vector<float> depth;

  uint32_t idAt(int col, int row) const { return id[size_t(row) * width + col]; }
  float depthAt(int col, int row) const { return depth[size_t(row) * width + col]; }
};

// Geometry that moves as one rigid body (one glTF mesh node): triangles in the object's local
// frame, CCW about their front face, and one item id per triangle (ids.size() ==
// triangles.size(), ids != kNoItem).
struct ItemObject {
  std::vector<std::array<glm::dvec3, 3>> triangles;
  std::vector<uint32_t> ids;

  void addTriangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, uint32_t id);
  // Adds a convex polygon (triangle or quad) as a fan from v[0], all with the same id.
  void addPolygon(const Polygon& polygon, uint32_t id);
};

struct ItemBufferOptions {
  // One-sided patches: a patch seen from behind is not visible (glTF: CCW front faces).
  // doubleSided materials get a reversed copy of each patch upstream (Scene::inputPolygons).
  bool cullBackFaces = true;
  // Read the depth target back into ItemBuffer::depth; false leaves depth empty (a caller that
  // needs only the ids saves the readback).
  bool readDepth = true;
};

// Reusable renderer: owns its GL context, FBO, shader and vertex buffer. Geometry is uploaded
// once (setGeometry); each frame only the per-object transforms change (render), so a frame
// costs one draw call per object plus the readback.
//
// Not thread-safe; use one renderer per thread (each has its own context).
class ItemBufferRenderer {
 public:
  // Throws rad::Error(kEnvironment) when no GL context can be made or the size exceeds the
  // driver's limits.
  ItemBufferRenderer(ImageSize size, ItemBufferOptions options = {});
  // Renders the samples of `grid` (sample_grid.h): a buffer of grid.size(), sample (i, j) at
  // (i, j), with grid.image's projection. ImageSize `size` above is the grid {size, 1, 0}.
  ItemBufferRenderer(const SampleGrid& grid, ItemBufferOptions options = {});
  ~ItemBufferRenderer();
  ItemBufferRenderer(const ItemBufferRenderer&) = delete;
  ItemBufferRenderer& operator=(const ItemBufferRenderer&) = delete;

  ImageSize size() const;  // of the buffer: grid().size()
  const SampleGrid& grid() const;
  const ItemBufferOptions& options() const;
  void setOptions(const ItemBufferOptions& options);

  // Uploads all objects (replacing any previous geometry). Throws rad::Error(kInternal) when
  // an object's ids and triangles differ in number or an id is kNoItem.
  void setGeometry(const std::vector<ItemObject>& objects);
  size_t objectCount() const;

  // Renders with worldFromObject[i] placing object i (objectTransforms.size() must equal
  // objectCount()). Matrices are combined in double and rounded to float once per object.
  ItemBuffer render(const CameraView& view, const std::vector<glm::dmat4>& objectTransforms);
  // Same, reusing out's storage.
  void render(const CameraView& view, const std::vector<glm::dmat4>& objectTransforms,
              ItemBuffer& out);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The samples at the pixel centres of `samples`, a buffer of `grid` (grid.size()): an item
// buffer of grid.image, pixel (col, row) = sample (grid.centre(col), grid.centre(row)), which
// lies exactly at the pixel's centre (sample_grid.h). The pixel centres' grid gives a copy.
// Depth is copied where `samples` has it (ItemBufferOptions::readDepth).
ItemBuffer pixelCentreSamples(const ItemBuffer& samples, const SampleGrid& grid);

// A world-space triangle for the one-shot helper below.
struct ItemTriangle {
  std::array<glm::dvec3, 3> p;
  uint32_t id = kNoItem;
};

// One-shot: makes a renderer, renders the triangles once. Convenient for tests and tools that
// render a single image; use ItemBufferRenderer for animations.
ItemBuffer renderItemBuffer(const std::vector<ItemTriangle>& worldTriangles, const CameraView& view,
                            ImageSize size, ItemBufferOptions options = {});

}  // namespace rad
