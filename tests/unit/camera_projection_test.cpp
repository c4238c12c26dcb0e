#include "libcommon/scene/camera_projection.h"

#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include "libcommon/core/error.h"

namespace rad {
namespace {

CameraView perspectiveView(double yfov, double aspect = 0.0, double zfar = 0.0) {
  CameraView v;
  v.lens.perspective = true;
  v.lens.yfov = yfov;
  v.lens.aspectRatio = aspect;
  v.lens.znear = 0.1;
  v.lens.zfar = zfar;
  return v;
}

// A camera at an angle: rotated about two axes and moved away from the origin.
glm::dmat4 tiltedCamera() {
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), glm::dvec3(1.5, -0.7, 4.0));
  m = glm::rotate(m, 0.4, glm::dvec3(0.0, 1.0, 0.0));
  m = glm::rotate(m, -0.25, glm::dvec3(1.0, 0.0, 0.0));
  return m;
}

TEST(CameraProjection, OpticalAxisMapsToImageCentre) {
  ImageSize size{352, 240};
  CameraView v = perspectiveView(0.8);
  v.worldFromCamera = tiltedCamera();
  glm::dvec3 onAxis = glm::dvec3(v.worldFromCamera * glm::dvec4(0.0, 0.0, -7.0, 1.0));
  ProjectedPoint p = projectToPixel(v, size, onAxis);
  ASSERT_TRUE(p.inFront);
  EXPECT_TRUE(p.inFrustum);
  EXPECT_NEAR(p.pixel.x, 176.0, 1e-9);
  EXPECT_NEAR(p.pixel.y, 120.0, 1e-9);
  EXPECT_NEAR(p.depth, 7.0, 1e-12);
  EXPECT_NEAR(viewDepth(v, onAxis), 7.0, 1e-12);
}

TEST(CameraProjection, VerticalFovEdgesMapToTopAndBottomRows) {
  ImageSize size{320, 200};
  CameraView v = perspectiveView(1.0);
  double d = 3.0, h = std::tan(0.5) * d;
  ProjectedPoint top = projectToPixel(v, size, glm::dvec3(0.0, h, -d));
  ProjectedPoint bottom = projectToPixel(v, size, glm::dvec3(0.0, -h, -d));
  EXPECT_NEAR(top.pixel.y, 0.0, 1e-9);  // +Y up in the world is row 0 at the top
  EXPECT_NEAR(bottom.pixel.y, 200.0, 1e-9);
  EXPECT_NEAR(top.pixel.x, 160.0, 1e-9);
}

TEST(CameraProjection, AspectFromImageOrCamera) {
  ImageSize size{200, 100};
  double d = 2.0, t = std::tan(0.4);
  // aspectRatio 0: the image's aspect (2) widens the horizontal field.
  CameraView v = perspectiveView(0.8);
  EXPECT_DOUBLE_EQ(effectiveAspect(v.lens, size), 2.0);
  EXPECT_NEAR(projectToPixel(v, size, glm::dvec3(2.0 * t * d, 0.0, -d)).pixel.x, 200.0, 1e-9);
  // An explicit aspect of the image's: the lens as written.
  v.lens.aspectRatio = 2.0;
  EXPECT_NEAR(projectToPixel(v, size, glm::dvec3(2.0 * t * d, 0.0, -d)).pixel.x, 200.0, 1e-9);
  EXPECT_NEAR(projectToPixel(v, size, glm::dvec3(0.0, t * d, -d)).pixel.y, 0.0, 1e-9);
  // Another aspect (1) does not stretch: Blender's AUTO sensor fit gives the camera frame's
  // larger side's field (tan 0.4, either side of a square) to the image's larger side (x), and
  // the image's aspect sets the other: a square stays square (issue 57).
  v.lens.aspectRatio = 1.0;
  EXPECT_NEAR(projectToPixel(v, size, glm::dvec3(t * d, 0.0, -d)).pixel.x, 200.0, 1e-9);
  EXPECT_NEAR(projectToPixel(v, size, glm::dvec3(-t * d, 0.0, -d)).pixel.x, 0.0, 1e-9);
  EXPECT_NEAR(projectToPixel(v, size, glm::dvec3(0.0, 0.5 * t * d, -d)).pixel.y, 0.0, 1e-9);
}

// A sphere's outline stays round whatever the image's aspect against the camera's: equal pixel
// extents across and up for a ball straight ahead (issue 57: it became an ellipse).
TEST(CameraProjection, SensorFitNeverStretches) {
  const double r = 0.3, d = 4.0;
  for (double cameraAspect : {0.0, 0.5, 1.0, 16.0 / 9.0, 3.0})
    for (ImageSize size :
         {ImageSize{160, 90}, ImageSize{90, 160}, ImageSize{120, 120}, ImageSize{300, 100}}) {
      CameraView v = perspectiveView(0.7, cameraAspect);
      const auto px = [&](glm::dvec3 p) { return projectToPixel(v, size, p).pixel; };
      const double across = px({r, 0.0, -d}).x - px({-r, 0.0, -d}).x;
      const double up = px({0.0, -r, -d}).y - px({0.0, r, -d}).y;
      EXPECT_NEAR(across, up, 1e-9 * up) << cameraAspect << " " << size.width << "x" << size.height;
      // The rays agree with the projection.
      const Ray ray = PrimaryRays(v, size).at(px({r, r, -d}));
      EXPECT_NEAR(glm::length(glm::cross(ray.direction, glm::normalize(glm::dvec3(r, r, -d)))), 0.0,
                  1e-12);
    }
}

// Which field is kept: the camera frame's larger side's (Blender's AUTO fit), on the image's
// larger side; bit-identical to the lens as written where the aspects agree.
TEST(CameraProjection, SensorFitKeepsTheLargerSidesField) {
  const double t = std::tan(0.35);
  CameraView wide = perspectiveView(0.7, 2.0);  // horizontal half-tangent 2t
  EXPECT_NEAR(lensHalfExtents(wide.lens, {100, 100}).x, 2.0 * t, 1e-15);  // crop to a square
  EXPECT_NEAR(lensHalfExtents(wide.lens, {100, 100}).y, 2.0 * t, 1e-15);
  EXPECT_NEAR(lensHalfExtents(wide.lens, {50, 100}).y, 2.0 * t, 1e-15);  // portrait: y takes it
  EXPECT_NEAR(lensHalfExtents(wide.lens, {50, 100}).x, t, 1e-15);
  CameraView tall = perspectiveView(0.7, 0.5);  // portrait: vertical half-tangent t
  EXPECT_NEAR(lensHalfExtents(tall.lens, {200, 100}).x, t, 1e-15);
  EXPECT_NEAR(lensHalfExtents(tall.lens, {200, 100}).y, 0.5 * t, 1e-15);
  // Agreeing within Blender's float32 aspect: the lens as written, bit for bit.
  CameraView blender = perspectiveView(0.7, double(float(16.0 / 9.0)));
  EXPECT_TRUE(aspectsAgree(blender.lens, {1920, 1080}));
  EXPECT_EQ(lensHalfExtents(blender.lens, {1920, 1080}).x, double(float(16.0 / 9.0)) * t);
  EXPECT_EQ(lensHalfExtents(blender.lens, {1920, 1080}).y, t);
  // Orthographic: max(xmag, ymag) on the larger side.
  Camera ortho;
  ortho.perspective = false;
  ortho.xmag = 2.0;
  ortho.ymag = 1.0;
  ortho.zfar = 10.0;
  EXPECT_EQ(lensHalfExtents(ortho, {200, 100}), glm::dvec2(2.0, 1.0));
  EXPECT_EQ(lensHalfExtents(ortho, {100, 100}), glm::dvec2(2.0, 2.0));
  EXPECT_EQ(lensHalfExtents(ortho, {100, 200}), glm::dvec2(1.0, 2.0));
}

TEST(CameraProjection, MatchesGltfFormulas) {
  ImageSize size{150, 100};  // the camera's aspect: the lens as written
  CameraView v = perspectiveView(0.7, 1.5, 20.0);
  double a = 1.5, y = 0.7, n = 0.1, f = 20.0, t = std::tan(0.5 * y);
  glm::dmat4 p = projectionMatrix(v.lens, size);
  EXPECT_DOUBLE_EQ(p[0][0], 1.0 / (a * t));
  EXPECT_DOUBLE_EQ(p[1][1], 1.0 / t);
  EXPECT_DOUBLE_EQ(p[2][2], (f + n) / (n - f));
  EXPECT_DOUBLE_EQ(p[3][2], 2.0 * f * n / (n - f));
  EXPECT_DOUBLE_EQ(p[2][3], -1.0);
  EXPECT_DOUBLE_EQ(p[3][3], 0.0);
}

TEST(CameraProjection, InfiniteFarPlane) {
  ImageSize size{64, 64};
  CameraView v = perspectiveView(0.9);  // zfar 0 = infinite
  glm::dmat4 p = projectionMatrix(v.lens, size);
  EXPECT_DOUBLE_EQ(p[2][2], -1.0);
  EXPECT_DOUBLE_EQ(p[3][2], -2.0 * v.lens.znear);
  // The finite matrix tends to the infinite one.
  CameraView far = perspectiveView(0.9, 0.0, 1e12);
  glm::dmat4 pf = projectionMatrix(far.lens, size);
  EXPECT_NEAR(pf[2][2], p[2][2], 1e-9);
  EXPECT_NEAR(pf[3][2], p[3][2], 1e-9);
  // Arbitrarily far points stay inside the frustum; points before the near plane do not.
  EXPECT_TRUE(projectToPixel(v, size, glm::dvec3(0.0, 0.0, -1e15)).inFrustum);
  EXPECT_TRUE(projectToPixel(v, size, glm::dvec3(0.0, 0.0, -0.1000001)).inFrustum);
  EXPECT_FALSE(projectToPixel(v, size, glm::dvec3(0.0, 0.0, -0.0999)).inFrustum);
  EXPECT_FALSE(projectToPixel(v, size, glm::dvec3(0.0, 0.0, 1.0)).inFront);
  Ray r = pixelCentreRay(v, size, 10, 20);
  EXPECT_TRUE(std::isinf(r.tFar));
}

TEST(CameraProjection, ReversedZSharesXYWithGltfProjection) {
  ImageSize size{64, 48};
  for (double zfar : {0.0, 50.0}) {
    CameraView v = perspectiveView(0.9, 0.0, zfar);
    glm::dmat4 p = projectionMatrix(v.lens, size), r = reversedZProjectionMatrix(v.lens, size);
    for (int c = 0; c < 4; ++c) {
      EXPECT_EQ(p[c][0], r[c][0]);
      EXPECT_EQ(p[c][1], r[c][1]);
      EXPECT_EQ(p[c][3], r[c][3]);
    }
    glm::dvec4 nearClip = r * glm::dvec4(0.0, 0.0, -v.lens.znear, 1.0);
    EXPECT_NEAR(nearClip.z / nearClip.w, 1.0, 1e-12);
    double farDepth = zfar == 0.0 ? 1e300 : zfar;
    glm::dvec4 farClip = r * glm::dvec4(0.0, 0.0, -farDepth, 1.0);
    EXPECT_NEAR(farClip.z / farClip.w, 0.0, 1e-12);
  }
  Camera ortho;
  ortho.perspective = false;
  ortho.xmag = 2.0;
  ortho.ymag = 1.0;
  ortho.znear = 0.5;
  ortho.zfar = 10.0;
  glm::dmat4 r = reversedZProjectionMatrix(ortho, size);
  EXPECT_NEAR((r * glm::dvec4(0, 0, -0.5, 1)).z, 1.0, 1e-12);
  EXPECT_NEAR((r * glm::dvec4(0, 0, -10.0, 1)).z, 0.0, 1e-12);
}

TEST(CameraProjection, Orthographic) {
  ImageSize size{200, 100};
  CameraView v;
  v.lens.perspective = false;
  v.lens.xmag = 4.0;
  v.lens.ymag = 2.0;
  v.lens.znear = 0.5;
  v.lens.zfar = 100.0;
  ProjectedPoint p = projectToPixel(v, size, glm::dvec3(4.0, 2.0, -30.0));
  EXPECT_NEAR(p.pixel.x, 200.0, 1e-9);
  EXPECT_NEAR(p.pixel.y, 0.0, 1e-9);
  Ray r = pixelCentreRay(v, size, 0, 0);
  EXPECT_NEAR(r.origin.x, -4.0 + 4.0 * (1.0 / 200.0), 1e-12);  // centre of column 0
  EXPECT_NEAR(r.direction.z, -1.0, 1e-15);
  EXPECT_DOUBLE_EQ(r.tNear, 0.5);
  EXPECT_DOUBLE_EQ(r.tFar, 100.0);
  v.lens.zfar = 0.0;
  EXPECT_THROW(projectionMatrix(v.lens, size), Error);
}

TEST(CameraProjection, RayThroughPixelCentreReprojectsToIt) {
  ImageSize size{352, 240};
  std::mt19937 rng(7);
  for (bool perspective : {true, false}) {
    CameraView v = perspectiveView(0.8);
    v.lens.perspective = perspective;
    v.lens.xmag = 3.0;
    v.lens.ymag = 2.0;
    v.lens.zfar = 1000.0;
    v.worldFromCamera = tiltedCamera();
    for (int i = 0; i < 200; ++i) {
      int col = int(rng() % size.width), row = int(rng() % size.height);
      Ray r = pixelCentreRay(v, size, col, row);
      EXPECT_NEAR(glm::length(r.direction), 1.0, 1e-14);
      // The ray enters the frustum exactly at the near plane.
      EXPECT_NEAR(viewDepth(v, r.origin + r.tNear * r.direction), v.lens.znear, 1e-12);
      EXPECT_NEAR(viewDepth(v, r.origin + r.tFar * r.direction), v.lens.zfar, 1e-9);
      for (double t : {1.0, 13.0, 400.0}) {
        ProjectedPoint p = projectToPixel(v, size, r.origin + t * r.direction);
        ASSERT_TRUE(p.inFront);
        EXPECT_NEAR(p.pixel.x, col + 0.5, 1e-8);
        EXPECT_NEAR(p.pixel.y, row + 0.5, 1e-8);
      }
    }
  }
}

// rad-compose intersects planes with PrimaryRays::line (unnormalised, affine in the pixel);
// it must be the line of at(), for both projections and an aspect the camera imposes.
TEST(CameraProjection, PrimaryRaysLineIsTheRayOfAt) {
  ImageSize size{352, 240};
  std::mt19937 rng(11);
  for (bool perspective : {true, false}) {
    CameraView v = perspectiveView(0.9, perspective ? 1.7 : 0.0);
    v.lens.perspective = perspective;
    v.lens.xmag = 3.0;
    v.lens.ymag = 2.0;
    v.lens.zfar = 1000.0;
    v.worldFromCamera = tiltedCamera();
    const PrimaryRays rays(v, size);
    for (int i = 0; i < 200; ++i) {
      glm::dvec2 pixel(std::uniform_real_distribution<double>(0.0, 352.0)(rng),
                       std::uniform_real_distribution<double>(0.0, 240.0)(rng));
      Ray r = rays.at(pixel);
      glm::dvec3 o, d;
      rays.line(pixel, o, d);
      ASSERT_GT(glm::length(d), 0.0);
      // Same direction (parallel and pointing the same way) ...
      EXPECT_NEAR(glm::length(glm::cross(glm::normalize(d), r.direction)), 0.0, 1e-14);
      EXPECT_GT(glm::dot(d, r.direction), 0.0);
      // ... through the same points.
      glm::dvec3 offset = o - r.origin;
      EXPECT_NEAR(glm::length(offset - glm::dot(offset, r.direction) * r.direction), 0.0, 1e-12);
      if (perspective) {
        EXPECT_EQ(o, r.origin);  // the eye
      }
      // And bit-identical to the one-ray function.
      Ray one = primaryRay(v, size, pixel);
      EXPECT_EQ(one.origin, r.origin);
      EXPECT_EQ(one.direction, r.direction);
      EXPECT_EQ(one.tNear, r.tNear);
    }
  }
}

TEST(CameraProjection, BadLensIsRejected) {
  ImageSize size{10, 10};
  CameraView v = perspectiveView(0.8);
  v.lens.znear = 0.0;
  EXPECT_THROW(projectionMatrix(v.lens, size), Error);
  v = perspectiveView(0.8, 0.0, 0.05);  // zfar before znear
  EXPECT_THROW(projectionMatrix(v.lens, size), Error);
  v = perspectiveView(3.5);
  EXPECT_THROW(projectionMatrix(v.lens, size), Error);
}

}  // namespace
}  // namespace rad
