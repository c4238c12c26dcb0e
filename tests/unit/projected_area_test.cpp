#include "libcommon/intervals/projected_area.h"

#include <cmath>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

namespace rad {
namespace {

constexpr ImageSize kSize{352, 240};

CameraView camera() {
  CameraView v;
  v.lens.yfov = 0.9;
  v.lens.znear = 0.05;
  v.worldFromCamera = glm::rotate(glm::translate(glm::dmat4(1.0), glm::dvec3(2.0, 1.0, 3.0)), 0.6,
                                  glm::normalize(glm::dvec3(1.0, 2.0, 0.5)));
  return v;
}

// World point on the plane at eye depth d that projects to continuous pixel (x, y).
glm::dvec3 atPixel(const CameraView& v, double x, double y, double d) {
  Ray r = primaryRay(v, kSize, glm::dvec2(x, y));
  double cosine = r.tNear / v.lens.znear;  // ray length per unit depth
  return r.origin + d * cosine * r.direction;
}

// A square facing the camera covering pixels [x0, x1] x [y0, y1], CCW towards the camera.
Polygon facingRect(const CameraView& v, double x0, double y0, double x1, double y1, double d) {
  Polygon p;
  p.count = 4;
  p.v = {atPixel(v, x0, y1, d), atPixel(v, x1, y1, d), atPixel(v, x1, y0, d),
         atPixel(v, x0, y0, d)};
  return p;
}

TEST(ProjectedArea, FacingRectangleFillsExactPixels) {
  CameraView v = camera();
  Polygon p = facingRect(v, 100.0, 50.0, 140.0, 80.0, 6.0);  // 40 x 30 pixels
  EXPECT_NEAR(projectedAreaPixels(v, kSize, p), 1200.0, 1200.0 * 1e-6);
  // Orientation does not matter.
  std::swap(p.v[1], p.v[3]);
  EXPECT_NEAR(projectedAreaPixels(v, kSize, p), 1200.0, 1200.0 * 1e-6);
}

TEST(ProjectedArea, WholeImage) {
  CameraView v = camera();
  Polygon p = facingRect(v, -500.0, -500.0, 900.0, 900.0, 3.0);
  EXPECT_NEAR(projectedAreaPixels(v, kSize, p), 352.0 * 240.0, 352.0 * 240.0 * 1e-9);
}

TEST(ProjectedArea, HalfOutsideTheFrustumCountsHalf) {
  CameraView v = camera();
  Polygon left = facingRect(v, -20.0, 100.0, 20.0, 140.0, 4.0);
  EXPECT_NEAR(projectedAreaPixels(v, kSize, left), 800.0, 800.0 * 1e-6);
  Polygon bottom = facingRect(v, 200.0, 230.0, 210.0, 250.0, 4.0);
  EXPECT_NEAR(projectedAreaPixels(v, kSize, bottom), 100.0, 100.0 * 1e-6);
}

TEST(ProjectedArea, BehindTheCameraIsZero) {
  CameraView v = camera();
  Polygon p = facingRect(v, 100.0, 50.0, 140.0, 80.0, 6.0);
  // Mirror through the eye: same directions, behind the camera.
  glm::dvec3 eye = v.eye();
  for (int i = 0; i < 4; ++i) p.v[i] = 2.0 * eye - p.v[i];
  EXPECT_EQ(projectedAreaPixels(v, kSize, p), 0.0);
  // Outside to the side as well.
  Polygon side = facingRect(v, 400.0, 50.0, 450.0, 80.0, 6.0);
  EXPECT_EQ(projectedAreaPixels(v, kSize, side), 0.0);
}

TEST(ProjectedArea, CrossingTheEyePlaneIsClippedAtTheNearPlane) {
  // A floor under the camera from behind it to far in front: finite, and below the horizon.
  CameraView v;
  v.lens.yfov = 0.9;
  v.lens.znear = 0.05;
  Polygon floor;
  floor.count = 4;
  floor.v = {glm::dvec3(-1, -1, 5), glm::dvec3(1, -1, 5), glm::dvec3(1, -1, -1e6),
             glm::dvec3(-1, -1, -1e6)};
  double a = projectedAreaPixels(v, kSize, floor);
  EXPECT_GT(a, 0.0);
  EXPECT_LT(a, 0.5 * kSize.width * kSize.height + 1e-6);
}

TEST(ProjectedArea, Orthographic) {
  CameraView v;
  v.lens.perspective = false;
  v.lens.xmag = 3.52;
  v.lens.ymag = 2.4;
  v.lens.znear = 0.1;
  v.lens.zfar = 10.0;
  // 1 world unit = 50 pixels: a 1 x 0.5 square covers 50 x 25 pixels at any depth.
  Polygon p;
  p.count = 4;
  p.v = {glm::dvec3(0, 0, -3), glm::dvec3(1, 0, -3), glm::dvec3(1, 0.5, -3),
         glm::dvec3(0, 0.5, -3)};
  EXPECT_NEAR(projectedAreaPixels(v, kSize, p), 1250.0, 1250.0 * 1e-9);
  for (auto& q : p.v) q.z = -20.0;  // beyond zfar
  EXPECT_EQ(projectedAreaPixels(v, kSize, p), 0.0);
}

}  // namespace
}  // namespace rad
