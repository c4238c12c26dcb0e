// Occlusion masks by exact segment tests on the CPU, and the renderer the baker uses by
// default: these for small masks, OSMesa projective shadows (transmittance.h) for large ones.
//
// Why: a render pass through OSMesa has a fixed cost whatever it draws (state, clear, a
// 64-instance draw, read-back), and a large scene's movies are mostly tiny textures
// with one or two blocker triangles in their shaft, so the passes' fixed cost dominates. The same
// masks by segment tests are at most texels x samples x blockers tests (each blocker only over
// the texels its shadows' box covers).
//
// Same answer as the projective render (occlusion_mask_renderer.h): bit s of texel (i, j) is
// set when a blocker triangle crosses the segment from samples[s] to the texel centre's point
// on the receiver plane (the point the render's homography maps to (u,v), receiverPlanePoint),
// strictly in front of the plane (distance > 1e-6 x the receiver's size, the render's clip
// plane) and not beyond the sample. The test is exact in double precision with edges counted
// on both triangles; the rasterizer decides a texel centre within ~1/256 texel of a projected
// edge by its snapped vertices instead, so the two differ only there
// (RayCastMasks.AgreeWithTheProjectiveRender).
#pragma once

#include <memory>

#include "libcommon/movies/occlusion_mask_renderer.h"

namespace rad {

class RayCastMaskRenderer final : public OcclusionMaskRenderer {
 public:
  void render(const Polygon& receiver, int width, int height,
              const std::vector<glm::dvec3>& samples, const std::vector<BlockerTriangle>& blockers,
              std::vector<SampleMask>& out) override;
  long passes() const override { return passes_; }
  long samplePasses() const override { return samplePasses_; }
  std::string rendererName() const override { return "ray cast"; }

 private:
  long passes_ = 0, samplePasses_ = 0;
  std::vector<glm::dvec3> points_;
};

// The size of a mask: texels x samples.
double rayCastMaskCost(int width, int height, size_t samples);

// Ray-cast masks while their size (texels x samples) is at most `budget`, else the projective
// render (made on its first need, so that a run of small masks never opens a GL context). The
// choice does not depend on the blockers: a pair's static blockers rendered once and its
// dynamic ones per key take the same method as all of them at once (--no-coherence), so the
// two still OR to the same masks bit for bit; and it depends on the request only, so the same
// inputs give the same masks whatever the thread count or shard split. budget 0: always the
// projective render.
class AdaptiveMaskRenderer final : public OcclusionMaskRenderer {
 public:
  AdaptiveMaskRenderer(double budget, OcclusionMaskRendererFactory projective);
  ~AdaptiveMaskRenderer() override;
  void render(const Polygon& receiver, int width, int height,
              const std::vector<glm::dvec3>& samples, const std::vector<BlockerTriangle>& blockers,
              std::vector<SampleMask>& out) override;
  // Both methods' passes; rayCastPasses() of them were ray cast.
  long passes() const override;
  long samplePasses() const override;
  long rayCastPasses() const { return rayCast_.passes(); }
  std::string rendererName() const override;

 private:
  double budget_;
  OcclusionMaskRendererFactory makeProjective_;
  RayCastMaskRenderer rayCast_;
  std::unique_ptr<OcclusionMaskRenderer> projective_;
};

}  // namespace rad
