// Final frames from texture movies (paper §3.1, last step of the second pass; docs/design.md §6.4
// "rad-compose"): rasterise the scene from the camera, texture each visible patch with its
// movie's irradiance H at time t and turn it into exitant radiance
//   $L(x) = L_e + \frac{\rho(x)}{\pi} H(x)$,
// where rho(x) is the material's reflectance times its base colour texture where present.
//
// Visibility is the item buffer's (item_buffer.h) on the sample grid (sample_grid.h): the same
// renderer, the same projection (camera_projection.h) and the same samples as rad-intervals', so
// a sample is covered here exactly when rad-intervals saw it covered. Each pixel is the pixel
// filter over the samples around it (footprint_filter.h), or with filter none the sample at its
// centre alone. Shading is deferred and done on the CPU in double: the ray through each shaded
// sample is intersected with the visible top-level patch's plane, the hit's top-level (u,v) is
// found by inverting the patch's bilinear/affine map (patch_hierarchy.h), the deepest active
// movie whose patch node contains that point is sampled bilinearly between texel centres at
// ((i+.5)/w, (j+.5)/h) (GL_LINEAR's), so non-parallelogram quads are mapped exactly as
// rad-movies baked them; in the outer half texel, up to the patch's border, the two outermost
// texels of each axis are extrapolated linearly rather than held (GL's CLAMP_TO_EDGE), because
// irradiance is steepest at borders (issue 56).
//
// A covered sample that no active movie textures falls back to the global solution: the union
// leaf under the point gives $L = B(t)/\pi$ (B already holds the emission, B = B_e + rho H);
// with a base colour texture the reflected part is modulated, $L = L_e + \frac{tex(x)}{\overline
// {tex}} (B/\pi - L_e)$. The pixels that read such a sample are counted so the tool can warn:
// never silently black.
//
// Under a still camera the samples keep their (u,v) and movie from frame to frame
// (still_samples.h; bit-identical), and the filter sees coplanar patches of one material as one
// surface (smooth_surfaces.h).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/gl/item_buffer.h"
#include "libcommon/radiosity/global_solution.h"
#include "libcommon/scene/camera_projection.h"
#include "libcommon/scene/sample_grid.h"
#include "libcommon/scene/scene.h"

namespace rad {

// One texture movie's irradiance at the frame's time (TextureMovie::textureAt): W/m^2, RGB,
// width * height texels row-major from j = 0 (v = 0). Not owned; must outlive compose().
// Between two key textures (irradiance = key k0, nextIrradiance = key k1, weight = w) the texel
// is (1 - w) * k0 + w * k1 in float, TextureMovie::textureAt's arithmetic (so the frame is
// bit-identical): the composer blends each such movie once a frame into a buffer it reuses, not
// the caller into a copy of each texture.
struct MovieTexture {
  PatchId patch;
  int width = 1, height = 1;
  const float* irradiance = nullptr;
  const float* nextIrradiance = nullptr;  // null: irradiance alone
  float weight = 0.0f;                    // of nextIrradiance
};

// Where a pixel's radiance came from.
enum class PixelSource : uint8_t { kBackground = 0, kMovie = 1, kFallback = 2 };

struct ComposedFrame {
  ImageSize size;
  double time = 0.0;
  // Linear exitant radiance, W/(m^2 sr), RGB, row-major, row 0 = top of the image.
  std::vector<float> rgb;
  std::vector<PixelSource> source;  // per pixel
  long long coveredPixels = 0;      // pixels where some patch is visible
  long long moviePixels = 0;        // covered and textured by a movie
  long long fallbackPixels = 0;     // covered, no movie: global solution used
};

class FrameComposer {
 public:
  // `scene` and `solution` must outlive the composer; solution.hierarchy's top-level patches
  // are scene.inputPolygons() (readLinkHierarchy checks it). cameraNode: Scene::cameraNode().
  // Throws rad::Error(kEnvironment) when no GL context can be made, kBadInput on a camera node
  // that is not one or a top count that differs.
  // `sampling`: the pixel filter and sample grid (footprint_filter.h); the default is one sample
  // through each pixel centre, unfiltered. everySample: shade every sample of every pixel's
  // footprint (no shortcut on uniform footprints). edgeCoverage: weigh the cells an edge
  // crosses by the area each side covers (edge_cells.h); false: each cell holds its sample.
  // edgeContrast: EdgeCellInputs::minContrast.
  FrameComposer(const Scene& scene, const GlobalSolution& solution, ImageSize size, int cameraNode,
                const PixelSampling& sampling = PixelSampling::pixelCentres(),
                bool everySample = false, bool edgeCoverage = true, double edgeContrast = 0.0);
  ~FrameComposer();
  FrameComposer(const FrameComposer&) = delete;
  FrameComposer& operator=(const FrameComposer&) = delete;

  ImageSize size() const;
  // Composes the frame at time t from the movies active at it (any order; a movie whose
  // patch's top-level index is out of range is an internal error). Where two active movies'
  // patches nest, the deeper one wins. Deterministic whatever the thread count.
  void compose(double t, const std::vector<MovieTexture>& movies, ComposedFrame& out);
  ComposedFrame compose(double t, const std::vector<MovieTexture>& movies);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// --- display (PNG) encoding

// Rec. 709 luminance of linear RGB.
inline double luminance(const glm::dvec3& c) {
  return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}
// sRGB transfer function (IEC 61966-2-1) of a linear value clamped to [0, 1].
double srgbEncode(double linear);
// 8-bit sRGB of linear radiance scaled by 2^exposureEV: round(255 * srgbEncode(L * 2^EV)).
// rgb: 3 floats per pixel; returns 3 bytes per pixel in the same order.
std::vector<uint8_t> toSrgb8(const std::vector<float>& rgb, double exposureEV);
// toSrgb8 of one value at exposure 0: round(255 * srgbEncode(linear)), 0 when not finite.
uint8_t srgb8AtExposureZero(float linear);

// One exposure for a whole sequence (so it cannot flicker), from the global solution alone:
// the area-weighted `percentile` (0..1] of the luminance of B/pi over the union leaves of all
// non-emitting top-level patches at all key times is mapped to 1 (white). Returns EV =
// -log2(that luminance); 0 when the scene reflects no light at all.
double autoExposureEV(const Scene& scene, const GlobalSolution& solution, double percentile = 0.99);

}  // namespace rad
