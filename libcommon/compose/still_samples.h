// Frame-to-frame coherence in rad-compose's shading (the paper's theme, applied to its last step,
// §3.1; docs/design.md §6.4 "Still samples"). Under a still camera, a grid sample that shows the
// same top-level patch of a still object as in the frame before meets the same point: its
// top-level (u,v) is the last frame's, and while the patch's active movies are the same set, so
// are the deepest movie's patch and the point's (u,v) in it. Those are what a sample costs to
// shade besides its texels (the ray's plane hit, the inverse (u,v) map, the descent through the
// movie tree); kept per sample, computed by the same code, a still sample costs a texel lookup
// and its frame is bit-identical to one computed from scratch.
//
// "Still" is bit-exact: the camera's lens and placement and the object's world transform equal
// the last frame's, bit for bit; nothing is reused otherwise. The cache is made on the first
// frame whose camera is still, so a moving camera costs one comparison a frame and no memory.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/scene/scene.h"

namespace rad {

class StillSamples {
 public:
  // Starts a frame of `samples` grid samples: compares the camera and the objects' transforms
  // with the last frame's, and each top's active movie patches (`moviePatchesByTop`: per top,
  // the packed PatchIds, sorted) with the last frame's. Not thread-safe; call before any lookup.
  void beginFrame(const CameraView& view, const std::vector<glm::dmat4>& transforms,
                  std::vector<std::vector<uint64_t>> moviePatchesByTop, size_t samples);

  // Whether the camera is still and the cache is in use this frame.
  bool enabled() const { return enabled_; }
  // Sample p's top-level (u,v) into `uv` when it was recorded (setTopUv) in a frame since which
  // the camera and the object have not moved, for the same item `id`; false otherwise.
  bool topUv(size_t p, uint32_t id, size_t object, glm::dvec2& uv) const {
    if (!enabled_ || ids_[p] != id || topFrame_[p] < stillSince_[object]) return false;
    uv = topUv_[p];
    return true;
  }
  // The deepest movie's packed PatchId and the (u,v) in it of sample p, when topUv(p, ...) held
  // and it was recorded (setMovie) in a frame since which the top's movies have not changed.
  bool movie(size_t p, uint32_t top, uint64_t& patch, glm::dvec2& uv) const {
    if (movieFrame_[p] < sameMoviesSince_[top] || movieFrame_[p] < topFrame_[p]) return false;
    patch = moviePatch_[p];
    uv = movieUv_[p];
    return true;
  }
  // Records sample p's values this frame (enabled() only; one thread a sample).
  void setTopUv(size_t p, uint32_t id, glm::dvec2 uv) {
    ids_[p] = id;
    topUv_[p] = uv;
    topFrame_[p] = frame_;
  }
  void setMovie(size_t p, uint64_t patch, glm::dvec2 uv) {
    moviePatch_[p] = patch;
    movieUv_[p] = uv;
    movieFrame_[p] = frame_;
  }

 private:
  uint32_t frame_ = 0;  // this frame's number, from 1; 0 marks nothing recorded
  bool enabled_ = false;
  CameraView lastView_;
  std::vector<glm::dmat4> lastTransforms_;
  std::vector<std::vector<uint64_t>> lastMovies_;
  // The first frame of the current run without change: per object (camera and transform), per
  // top (its movies). A record made in that frame or later still holds.
  std::vector<uint32_t> stillSince_, sameMoviesSince_;
  // Per sample: the item it showed, its top-level (u,v), the movie found, and the frames they
  // were recorded in.
  std::vector<uint32_t> ids_, topFrame_, movieFrame_;
  std::vector<glm::dvec2> topUv_, movieUv_;
  std::vector<uint64_t> moviePatch_;
};

}  // namespace rad
