// The one camera model shared by every stage that turns a CameraView into pixels: item
// buffers (rad-intervals), compositing (rad-compose) and CPU ray casting (Embree cross-checks,
// the reference path tracer). They must agree pixel-exactly, so nobody builds a projection
// matrix or a primary ray anywhere else.
//
// Projection follows glTF 2.0 §3.10.3 "Projection Matrices" (perspective with finite or
// infinite far plane, orthographic). The camera looks down its -Z with +Y up.
//
// Pixel convention (all CPU-side buffers): row 0 is the TOP row of the image, column 0 the
// left column; pixel (col, row) covers [col, col+1) x [row, row+1) in continuous pixel
// coordinates and its centre is (col + 0.5, row + 0.5). GL reads back bottom-up, so GL code
// flips rows on readback (item_buffer.cpp does).
//
// NDC -> pixel: x_pix = (x_ndc + 1) / 2 * width, y_pix = (1 - y_ndc) / 2 * height, which is
// exactly GL's viewport transform (glViewport(0, 0, width, height)) followed by the row flip.
#pragma once

#include <glm/glm.hpp>

#include "libcommon/scene/scene.h"

namespace rad {

struct ImageSize {
  int width = 0, height = 0;
  double aspect() const { return double(width) / double(height); }
  long long pixelCount() const { return (long long)width * height; }
  bool operator==(const ImageSize& o) const { return width == o.width && height == o.height; }
  bool operator!=(const ImageSize& o) const { return !(*this == o); }
};

// Aspect ratio (width / height) the projection uses: the camera's when it gives one (glTF
// `aspectRatio`), else the image's. A camera aspect that differs from the image's stretches
// the picture, as glTF prescribes.
double effectiveAspect(const Camera& lens, ImageSize size);

// Eye-from-world: inverse of worldFromCamera (rigid inverse, exact to rounding).
glm::dmat4 viewMatrix(const CameraView& view);

// glTF projection (OpenGL clip space, NDC z in [-1, 1]). Perspective: zfar == 0 gives the
// infinite-far-plane matrix. Orthographic needs zfar > znear (glTF requires zfar there).
// Throws rad::Error(kBadInput, "camera NAME", ...) on an unusable lens (yfov outside (0, pi),
// znear <= 0, zfar in (0, znear], non-positive xmag/ymag).
glm::dmat4 projectionMatrix(const Camera& lens, ImageSize size);

// The projection GL rasterisers use: identical x, y and w rows to projectionMatrix (so the
// same pixels are covered), but a reversed depth row mapping the near plane to NDC z = 1 and
// the far plane (or infinity) to 0. Use with glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE),
// glDepthFunc(GL_GREATER) and a 32-bit float depth buffer cleared to 0 (see
// configureReversedZ() in gl_context.h): float depth then has nearly uniform *relative*
// precision at every distance, which is what keeps occlusion right with a tiny znear and an
// infinite far plane (Reed 2015, "Depth Precision Visualized"; Upchurch & Desbrun 2012).
glm::dmat4 reversedZProjectionMatrix(const Camera& lens, ImageSize size);

// The float matrix a GL vertex shader gets for geometry in a local frame: reversed-Z
// projection x view x worldFromLocal, multiplied in double and rounded to float once. Every
// rasteriser (item buffers, rad-compose) uses exactly this so they cover the same pixels.
glm::mat4 rasterClipFromLocal(const CameraView& view, ImageSize size,
                              const glm::dmat4& worldFromLocal);
// The same with the clip x and y rows scaled by ndcScale (in double, before the rounding): the
// image's NDC times ndcScale, for a buffer that holds a margin around the image
// (sample_grid.h).
glm::mat4 rasterClipFromLocal(const CameraView& view, ImageSize size,
                              const glm::dmat4& worldFromLocal, glm::dvec2 ndcScale);

// Clip-from-world with the glTF projection.
glm::dmat4 clipFromWorld(const CameraView& view, ImageSize size);

// Eye-space depth: distance from the eye plane along the view axis (-z_eye), metres.
double viewDepth(const CameraView& view, const glm::dvec3& world);

struct ProjectedPoint {
  glm::dvec2 pixel{0.0};   // continuous pixel coordinates, row 0 at the top (see above)
  double depth = 0.0;      // eye-space depth (-z_eye)
  bool inFront = false;    // w > 0: in front of the eye plane (perspective) / always (ortho)
  bool inFrustum = false;  // inside all clip planes (near, far, sides), boundary included
};

// Maps a world point to pixel coordinates. pixel is meaningful only when inFront.
ProjectedPoint projectToPixel(const CameraView& view, ImageSize size, const glm::dvec3& world);

struct Ray {
  glm::dvec3 origin{0.0};
  glm::dvec3 direction{0.0, 0.0, -1.0};  // unit length
  // Parametric range that lies between the near and far planes; tFar is +inf for an infinite
  // far plane. A ray cast on [tNear, tFar] sees exactly what the rasteriser can see.
  double tNear = 0.0, tFar = 0.0;
};

// Primary rays of one view: the lens is validated and tan(yfov/2) evaluated once, not per pixel.
// Gives bit-identical rays to primaryRay().
class PrimaryRays {
 public:
  // Throws like projectionMatrix() on an unusable lens.
  PrimaryRays(const CameraView& view, ImageSize size);
  // Ray through a continuous pixel position (row 0 at the top). Perspective: from the eye.
  // Orthographic: from the eye plane (z_eye = 0), along the view axis.
  Ray at(const glm::dvec2& pixel) const;
  // Ray through the centre of pixel (col, row).
  Ray pixelCentre(int col, int row) const { return at(glm::dvec2(col + 0.5, row + 0.5)); }
  // The line of that ray as a point and a direction that is NOT unit length, affine in the
  // pixel position (two multiply-adds per component): for intersecting planes, where the
  // scale of the direction cancels. Same line as at() up to rounding.
  void line(const glm::dvec2& pixel, glm::dvec3& origin, glm::dvec3& direction) const {
    const double xn = 2.0 * pixel.x / size_.width - 1.0;
    const double yn = 1.0 - 2.0 * pixel.y / size_.height;
    origin = origin0_ + xn * originX_ + yn * originY_;
    direction = direction0_ + xn * directionX_ + yn * directionY_;
  }

 private:
  CameraView view_;
  ImageSize size_;
  double halfTan_ = 0.0, aspect_ = 1.0;  // perspective: tan(yfov/2), effectiveAspect()
  // line(): origin and direction as affine functions of NDC x, y.
  glm::dvec3 origin0_{0.0}, originX_{0.0}, originY_{0.0};
  glm::dvec3 direction0_{0.0}, directionX_{0.0}, directionY_{0.0};
};

// One ray, for callers that need a few: PrimaryRays(view, size).at(pixel).
Ray primaryRay(const CameraView& view, ImageSize size, const glm::dvec2& pixel);
// Ray through the centre of pixel (col, row).
inline Ray pixelCentreRay(const CameraView& view, ImageSize size, int col, int row) {
  return primaryRay(view, size, glm::dvec2(col + 0.5, row + 0.5));
}

}  // namespace rad
