#include "libcommon/gl/item_buffer.h"

#include <embree3/rtcore.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <thread>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include "libcommon/core/error.h"
#include "libcommon/intervals/projected_area.h"

namespace rad {
namespace {

constexpr ImageSize kSize{64, 48};

CameraView axisCamera() {
  CameraView v;
  v.lens.yfov = 0.8;
  v.lens.znear = 0.1;
  return v;  // at the origin, looking down -Z
}

// World point at eye depth d projecting to continuous pixel (x, y) (row 0 at the top).
glm::dvec3 atPixel(const CameraView& v, ImageSize size, double x, double y, double d) {
  Ray r = primaryRay(v, size, glm::dvec2(x, y));
  return r.origin + d * (r.tNear / v.lens.znear) * r.direction;
}

// Rectangle facing the camera covering pixels [x0, x1) x [y0, y1), CCW towards the camera.
void addRect(ItemObject& o, const CameraView& v, ImageSize size, double x0, double y0, double x1,
             double y1, double d, uint32_t id, bool frontFacing = true) {
  Polygon p;
  p.count = 4;
  p.v = {atPixel(v, size, x0, y1, d), atPixel(v, size, x1, y1, d), atPixel(v, size, x1, y0, d),
         atPixel(v, size, x0, y0, d)};
  if (!frontFacing) std::swap(p.v[1], p.v[3]);
  o.addPolygon(p, id);
}

int countId(const ItemBuffer& b, uint32_t id) {
  int n = 0;
  for (uint32_t x : b.id) n += x == id;
  return n;
}

TEST(ItemBuffer, QuadCoversExactlyItsPixels) {
  CameraView v = axisCamera();
  ItemObject o;
  addRect(o, v, kSize, 16, 12, 48, 36, 5.0, 7);
  ItemBufferRenderer r(kSize);
  r.setGeometry({o});
  ItemBuffer b = r.render(v, {glm::dmat4(1.0)});
  ASSERT_EQ(b.width, 64);
  ASSERT_EQ(b.height, 48);
  for (int row = 0; row < 48; ++row)
    for (int col = 0; col < 64; ++col) {
      bool wellInside = col >= 17 && col <= 46 && row >= 13 && row <= 34;
      bool wellOutside = col <= 14 || col >= 49 || row <= 10 || row >= 37;
      if (wellInside) {
        EXPECT_EQ(b.idAt(col, row), 7u) << col << "," << row;
        EXPECT_NEAR(b.depthAt(col, row), 5.0, 5.0 * 1e-4);
      }
      if (wellOutside) {
        EXPECT_EQ(b.idAt(col, row), kNoItem) << col << "," << row;
        EXPECT_TRUE(std::isinf(b.depthAt(col, row)));
      }
    }
  // Edges lie half a pixel from the nearest centres, so the count is exact.
  EXPECT_EQ(countId(b, 7), 32 * 24);
}

TEST(ItemBuffer, RowZeroIsTheTop) {
  CameraView v = axisCamera();
  // A triangle covering the upper half of the view (+Y world = up).
  ItemBuffer b = renderItemBuffer(
      {{{glm::dvec3(-100, 0.01, -1), glm::dvec3(100, 0.01, -1), glm::dvec3(0, 100, -1)}, 3}}, v,
      kSize);
  EXPECT_EQ(b.idAt(32, 0), 3u);
  EXPECT_EQ(b.idAt(32, 47), kNoItem);
}

TEST(ItemBuffer, NearerQuadWinsWithCorrectDepth) {
  CameraView v = axisCamera();
  v.worldFromCamera = glm::rotate(glm::translate(glm::dmat4(1.0), glm::dvec3(3, 2, 1)), 0.7,
                                  glm::normalize(glm::dvec3(1, 1, 0)));
  for (bool nearFirst : {true, false}) {
    ItemObject nearQuad, farQuad;
    addRect(nearQuad, v, kSize, 10, 10, 40, 30, 3.0, 1);
    addRect(farQuad, v, kSize, 25, 20, 60, 45, 6.0, 2);
    ItemBufferRenderer r(kSize);
    std::vector<ItemObject> objects = nearFirst ? std::vector<ItemObject>{nearQuad, farQuad}
                                                : std::vector<ItemObject>{farQuad, nearQuad};
    r.setGeometry(objects);
    ItemBuffer b = r.render(v, {glm::dmat4(1.0), glm::dmat4(1.0)});
    EXPECT_EQ(b.idAt(30, 25), 1u);  // overlap
    EXPECT_NEAR(b.depthAt(30, 25), 3.0, 3.0 * 1e-4);
    EXPECT_EQ(b.idAt(50, 40), 2u);
    EXPECT_NEAR(b.depthAt(50, 40), 6.0, 6.0 * 1e-4);
    EXPECT_EQ(b.idAt(15, 15), 1u);
    EXPECT_EQ(countId(b, 1), 30 * 20);
    EXPECT_EQ(countId(b, 2), 35 * 25 - 15 * 10);
  }
}

TEST(ItemBuffer, DepthIsExactOnASlantedPlane) {
  // Eye depth is interpolated, not reconstructed from the depth buffer: check it on a floor
  // stretching from near to far.
  CameraView v = axisCamera();
  ItemObject o;
  o.addTriangle({-50, -1, -0.5}, {50, -1, -0.5}, {0, -1, -1000}, 9);
  ItemBufferRenderer r(kSize);
  r.setGeometry({o});
  ItemBuffer b = r.render(v, {glm::dmat4(1.0)});
  int checked = 0;
  for (int row = 0; row < kSize.height; ++row)
    for (int col = 0; col < kSize.width; ++col) {
      if (b.idAt(col, row) != 9) continue;
      Ray ray = pixelCentreRay(v, kSize, col, row);
      double t = (-1.0 - ray.origin.y) / ray.direction.y;
      double expected = viewDepth(v, ray.origin + t * ray.direction);
      EXPECT_NEAR(b.depthAt(col, row), expected, expected * 1e-4) << col << "," << row;
      ++checked;
    }
  EXPECT_GT(checked, 300);
}

TEST(ItemBuffer, BackFacesAreCulledByDefault) {
  CameraView v = axisCamera();
  ItemObject o;
  addRect(o, v, kSize, 8, 8, 24, 24, 4.0, 5, /*frontFacing=*/false);
  addRect(o, v, kSize, 40, 8, 56, 24, 4.0, 6, /*frontFacing=*/true);
  ItemBufferRenderer r(kSize);
  r.setGeometry({o});
  ItemBuffer culled = r.render(v, {glm::dmat4(1.0)});
  EXPECT_EQ(countId(culled, 5), 0);
  EXPECT_EQ(countId(culled, 6), 256);
  r.setOptions({/*cullBackFaces=*/false});
  ItemBuffer both = r.render(v, {glm::dmat4(1.0)});
  EXPECT_EQ(countId(both, 5), 256);
  EXPECT_EQ(countId(both, 6), 256);
}

TEST(ItemBuffer, MovingAnObjectMovesItsPixels) {
  CameraView v = axisCamera();
  const double d = 5.0;
  ItemObject moving, still;
  addRect(moving, v, kSize, 10, 10, 20, 20, d, 1);
  addRect(still, v, kSize, 40, 30, 50, 40, d, 2);
  ItemBufferRenderer r(kSize);
  r.setGeometry({moving, still});
  // One pixel at depth d spans this many metres (perspective, on the axis plane).
  double pixel = 2.0 * d * std::tan(0.5 * v.lens.yfov) / kSize.height;
  glm::dmat4 shift = glm::translate(glm::dmat4(1.0), glm::dvec3(7 * pixel, -4 * pixel, 0.0));
  ItemBuffer before = r.render(v, {glm::dmat4(1.0), glm::dmat4(1.0)});
  ItemBuffer after = r.render(v, {shift, glm::dmat4(1.0)});
  EXPECT_EQ(before.idAt(12, 12), 1u);
  EXPECT_EQ(after.idAt(12, 12), kNoItem);
  for (int row = 11; row < 19; ++row)
    for (int col = 11; col < 19; ++col)
      EXPECT_EQ(after.idAt(col + 7, row + 4), 1u) << col << "," << row;  // -Y world = down
  EXPECT_EQ(countId(after, 1), 100);
  EXPECT_EQ(before.id.size(), after.id.size());
  for (int row = 0; row < kSize.height; ++row)
    for (int col = 0; col < kSize.width; ++col)
      if (before.idAt(col, row) == 2u) {
        EXPECT_EQ(after.idAt(col, row), 2u);
      }
}

TEST(ItemBuffer, RejectsBadInput) {
  ItemBufferRenderer r(kSize);
  ItemObject o;
  o.triangles.push_back({glm::dvec3(0), glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0)});
  EXPECT_THROW(r.setGeometry({o}), Error);  // no id
  o.ids.push_back(kNoItem);
  EXPECT_THROW(r.setGeometry({o}), Error);  // reserved id
  o.ids[0] = 1;
  r.setGeometry({o});
  EXPECT_THROW(r.render(axisCamera(), {}), Error);  // transform count
}

TEST(ItemBuffer, DepthOrderHoldsWithTinyNearPlaneAndFarObjects) {
  // Reversed-Z float depth keeps relative precision: 1 mm near plane, quads 2 m apart at 2 km.
  CameraView v = axisCamera();
  v.lens.znear = 0.001;
  ItemObject o;
  addRect(o, v, kSize, 10, 10, 40, 30, 2000.0, 1);
  addRect(o, v, kSize, 20, 15, 50, 40, 2002.0, 2);  // behind, drawn after
  addRect(o, v, kSize, 5, 30, 15, 45, 0.002, 3);    // 2 mm from the eye
  ItemBufferRenderer r(kSize);
  r.setGeometry({o});
  ItemBuffer b = r.render(v, {glm::dmat4(1.0)});
  EXPECT_EQ(countId(b, 1), 30 * 20);
  EXPECT_EQ(countId(b, 2), 30 * 25 - 20 * 15);
  EXPECT_EQ(countId(b, 3), 10 * 15);
  EXPECT_NEAR(b.depthAt(30, 20), 2000.0, 2000.0 * 1e-4);
  EXPECT_NEAR(b.depthAt(45, 35), 2002.0, 2002.0 * 1e-4);
  EXPECT_NEAR(b.depthAt(10, 40), 0.002, 0.002 * 1e-4);
}

TEST(ItemBuffer, Orthographic) {
  CameraView v;
  v.lens.perspective = false;
  v.lens.xmag = 3.2;  // 10 pixels per metre on a 64 x 48 image
  v.lens.ymag = 2.4;
  v.lens.znear = 0.5;
  v.lens.zfar = 50.0;
  ItemObject o;
  // Square [0, 1] x [0, 1] at z = -10: columns 32..41, rows 14..23 (row 0 at the top).
  o.addTriangle({0, 0, -10}, {1, 0, -10}, {1, 1, -10}, 4);
  o.addTriangle({0, 0, -10}, {1, 1, -10}, {0, 1, -10}, 4);
  o.addTriangle({0, 0, -60}, {1, 0, -60}, {1, 1, -60}, 5);  // beyond zfar
  ItemBuffer b = renderItemBuffer({{{o.triangles[0][0], o.triangles[0][1], o.triangles[0][2]}, 4},
                                   {{o.triangles[1][0], o.triangles[1][1], o.triangles[1][2]}, 4},
                                   {{o.triangles[2][0], o.triangles[2][1], o.triangles[2][2]}, 5}},
                                  v, kSize);
  EXPECT_EQ(countId(b, 4), 100);
  EXPECT_EQ(countId(b, 5), 0);
  EXPECT_EQ(b.idAt(32, 14), 4u);
  EXPECT_EQ(b.idAt(41, 23), 4u);
  EXPECT_EQ(b.idAt(31, 14), kNoItem);
  EXPECT_EQ(b.idAt(32, 24), kNoItem);
  EXPECT_NEAR(b.depthAt(35, 20), 10.0, 10.0 * 1e-4);
}

// ---------------------------------------------------------------------------------------------
// A non-trivial scene: overlapping random triangles at different depths, some facing away.

struct RandomScene {
  std::vector<ItemTriangle> triangles;
  CameraView view;
};

RandomScene randomScene(int count, uint32_t seed) {
  RandomScene s;
  std::mt19937 rng(seed);
  auto uniform = [&rng](double a, double b) {
    return a + (b - a) * (double(rng()) / double(std::mt19937::max()));
  };
  s.view.lens.yfov = 0.9;
  s.view.lens.znear = 0.05;
  const glm::dvec3 eye(3.0, 2.0, 6.0);
  s.view.worldFromCamera =
      glm::inverse(glm::lookAt(eye, glm::dvec3(0.2, -0.3, 0.0), glm::dvec3(0, 1, 0)));
  for (int i = 0; i < count; ++i) {
    glm::dvec3 c(uniform(-3, 3), uniform(-2, 2), uniform(-3, 3));
    double size = uniform(0.5, 2.5);
    ItemTriangle t;
    for (auto& p : t.p) p = c + size * glm::dvec3(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
    // Most face the camera; every fifth faces away and must be culled by both renderers.
    glm::dvec3 n = glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
    bool facing = glm::dot(n, eye - t.p[0]) > 0.0;
    if (facing != (i % 5 != 0)) std::swap(t.p[1], t.p[2]);
    t.id = uint32_t(i + 1);
    s.triangles.push_back(t);
  }
  return s;
}

struct EmbreeScene {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<glm::dvec3> normals;  // CCW front normals, for one-sided hits

  explicit EmbreeScene(const std::vector<ItemTriangle>& triangles) {
    device = rtcNewDevice(nullptr);
    scene = rtcNewScene(device);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), triangles.size() * 3));
    auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), triangles.size()));
    for (size_t i = 0; i < triangles.size(); ++i) {
      for (int k = 0; k < 3; ++k) {
        for (int c = 0; c < 3; ++c) vb[9 * i + 3 * k + c] = float(triangles[i].p[k][c]);
        ib[3 * i + k] = unsigned(3 * i + k);
      }
      const auto& p = triangles[i].p;
      normals.push_back(glm::cross(p[1] - p[0], p[2] - p[0]));
    }
    rtcSetGeometryUserData(g, &normals);
    rtcSetGeometryIntersectFilterFunction(g, &EmbreeScene::frontFacesOnly);
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);
  }
  ~EmbreeScene() {
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
  }

  // One-sided patches, as the item buffer's back-face culling.
  static void frontFacesOnly(const RTCFilterFunctionNArguments* args) {
    const auto& n = *static_cast<const std::vector<glm::dvec3>*>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
      if (args->valid[i] == 0) continue;
      unsigned prim = RTCHitN_primID(args->hit, args->N, i);
      glm::dvec3 dir(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                     RTCRayN_dir_z(args->ray, args->N, i));
      if (glm::dot(n[prim], dir) >= 0.0) args->valid[i] = 0;
    }
  }

  uint32_t cast(const Ray& r, const std::vector<ItemTriangle>& triangles) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray.org_x = float(r.origin.x);
    rh.ray.org_y = float(r.origin.y);
    rh.ray.org_z = float(r.origin.z);
    rh.ray.dir_x = float(r.direction.x);
    rh.ray.dir_y = float(r.direction.y);
    rh.ray.dir_z = float(r.direction.z);
    rh.ray.tnear = float(r.tNear);
    rh.ray.tfar = std::isinf(r.tFar) ? std::numeric_limits<float>::infinity() : float(r.tFar);
    rh.ray.time = 0.0f;
    rh.ray.mask = ~0u;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return kNoItem;
    return triangles[rh.hit.primID].id;
  }
};

// Distance in pixels from a pixel centre to the nearest projected edge of triangle `id`
// (+inf when it has a vertex behind the eye, where projected edges mean nothing).
double edgeDistance(const RandomScene& s, ImageSize size, int col, int row, uint32_t id) {
  if (id == kNoItem) return std::numeric_limits<double>::infinity();
  const ItemTriangle& t = s.triangles[id - 1];
  glm::dvec2 c(col + 0.5, row + 0.5);
  std::array<glm::dvec2, 3> q;
  for (int k = 0; k < 3; ++k) {
    ProjectedPoint p = projectToPixel(s.view, size, t.p[k]);
    if (!p.inFront) return std::numeric_limits<double>::infinity();
    q[k] = p.pixel;
  }
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    glm::dvec2 a = q[k], e = q[(k + 1) % 3] - q[k];
    double u = glm::clamp(glm::dot(c - a, e) / glm::dot(e, e), 0.0, 1.0);
    best = std::min(best, glm::length(c - (a + u * e)));
  }
  return best;
}

// A disagreement is acceptable on an edge: the ray's id appears within one pixel in the buffer,
// or the pixel centre lies within one pixel of an edge of either triangle (also covers edges
// at the image border, whose outer neighbours are not in the buffer).
bool onAnEdge(const RandomScene& s, const ItemBuffer& b, int col, int row, uint32_t expected) {
  for (int dr = -1; dr <= 1; ++dr)
    for (int dc = -1; dc <= 1; ++dc) {
      int c = col + dc, r = row + dr;
      if (c >= 0 && r >= 0 && c < b.width && r < b.height && b.idAt(c, r) == expected) return true;
    }
  ImageSize size{b.width, b.height};
  return edgeDistance(s, size, col, row, b.idAt(col, row)) <= 1.0 ||
         edgeDistance(s, size, col, row, expected) <= 1.0;
}

TEST(ItemBuffer, AgreesWithEmbreeRayCasting) {
  const ImageSize size{352, 240};
  RandomScene s = randomScene(120, 11);
  ItemBuffer b = renderItemBuffer(s.triangles, s.view, size);
  EmbreeScene embree(s.triangles);

  std::mt19937 rng(3);
  const int samples = 1000;
  int agree = 0, hits = 0;
  for (int i = 0; i < samples; ++i) {
    int col = int(rng() % size.width), row = int(rng() % size.height);
    uint32_t expected = embree.cast(pixelCentreRay(s.view, size, col, row), s.triangles);
    hits += expected != kNoItem;
    uint32_t got = b.idAt(col, row);
    if (got == expected) {
      ++agree;
      continue;
    }
    bool nearEdge = onAnEdge(s, b, col, row, expected);
    EXPECT_TRUE(nearEdge) << "pixel " << col << "," << row << ": gl " << got << ", embree "
                          << expected;
  }
  std::printf("item buffer vs embree: %d / %d sampled pixels agree (%d hit geometry)\n", agree,
              samples, hits);
  EXPECT_GT(hits, samples / 3) << "scene should cover a good part of the image";
  EXPECT_GE(agree, int(std::ceil(0.995 * samples)));

  // Stronger: every pixel of the image, so edges are certainly exercised.
  int mismatches = 0, farFromEdge = 0;
  for (int row = 0; row < size.height; ++row)
    for (int col = 0; col < size.width; ++col) {
      uint32_t expected = embree.cast(pixelCentreRay(s.view, size, col, row), s.triangles);
      if (b.idAt(col, row) == expected) continue;
      ++mismatches;
      bool nearEdge = onAnEdge(s, b, col, row, expected);
      farFromEdge += !nearEdge;
      EXPECT_TRUE(nearEdge) << "pixel " << col << "," << row << ": gl " << b.idAt(col, row)
                            << ", embree " << expected;
    }
  std::printf("item buffer vs embree, all %d pixels: %d differ, %d of them away from an edge\n",
              size.width * size.height, mismatches, farFromEdge);
  EXPECT_EQ(farFromEdge, 0);
  EXPECT_LE(mismatches, int(0.005 * size.width * size.height));
}

TEST(ItemBuffer, VisiblePixelsNeverExceedProjectedArea) {
  // Cross-check of projected_area against the rasteriser: an item's visible pixel count is at
  // most its unoccluded projected area plus the pixels its outline can touch.
  const ImageSize size{352, 240};
  RandomScene s = randomScene(120, 11);
  ItemBuffer b = renderItemBuffer(s.triangles, s.view, size);
  std::vector<int> counts(s.triangles.size() + 1, 0);
  for (uint32_t id : b.id) ++counts[id];
  for (const ItemTriangle& t : s.triangles) {
    Polygon p;
    p.count = 3;
    p.v = {t.p[0], t.p[1], t.p[2], glm::dvec3(0.0)};
    double area = projectedAreaPixels(s.view, size, p);
    double perimeter = 0.0;  // generous bound on the boundary pixels
    std::array<ProjectedPoint, 3> q;
    for (int k = 0; k < 3; ++k) q[k] = projectToPixel(s.view, size, t.p[k]);
    for (int k = 0; k < 3; ++k) perimeter += glm::length(q[k].pixel - q[(k + 1) % 3].pixel);
    if (!(q[0].inFront && q[1].inFront && q[2].inFront)) continue;  // perimeter meaningless
    EXPECT_LE(counts[t.id], area + perimeter + 4.0) << "item " << t.id;
  }
}

TEST(ItemBuffer, DeterministicAcrossRendersAndRenderers) {
  const ImageSize size{352, 240};
  RandomScene s = randomScene(400, 5);
  ItemObject o;
  for (const ItemTriangle& t : s.triangles) o.addTriangle(t.p[0], t.p[1], t.p[2], t.id);
  ItemBufferRenderer r(size);
  r.setGeometry({o});
  ItemBuffer a = r.render(s.view, {glm::dmat4(1.0)});
  ItemBuffer b = r.render(s.view, {glm::dmat4(1.0)});
  ItemBuffer c = renderItemBuffer(s.triangles, s.view, size);
  ASSERT_EQ(a.id.size(), b.id.size());
  EXPECT_EQ(std::memcmp(a.id.data(), b.id.data(), a.id.size() * sizeof(uint32_t)), 0);
  EXPECT_EQ(std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)), 0);
  EXPECT_EQ(std::memcmp(a.id.data(), c.id.data(), a.id.size() * sizeof(uint32_t)), 0);
  EXPECT_EQ(std::memcmp(a.depth.data(), c.depth.data(), a.depth.size() * sizeof(float)), 0);
}

TEST(ItemBuffer, IdsWithoutDepthAreTheIdsWithDepth) {
  // readDepth false draws with a program of its own (no depth varying, no second output):
  // rad-intervals counts those ids, so they must be the same samples' ids bit for bit, on the
  // sample grid too, and switching the option on one renderer must not mix the programs.
  RandomScene s = randomScene(400, 5);
  ItemObject o;
  for (const ItemTriangle& t : s.triangles) o.addTriangle(t.p[0], t.p[1], t.p[2], t.id);
  const SampleGrid grid{{352, 240}, 3, 1};
  ItemBufferRenderer r(grid);
  r.setGeometry({o});
  const ItemBuffer withDepth = r.render(s.view, {glm::dmat4(1.0)});
  ItemBufferOptions idsOnly;
  idsOnly.readDepth = false;
  r.setOptions(idsOnly);
  const ItemBuffer ids = r.render(s.view, {glm::dmat4(1.0)});
  EXPECT_TRUE(ids.depth.empty());
  ASSERT_EQ(ids.id.size(), withDepth.id.size());
  EXPECT_TRUE(ids.id == withDepth.id);
  EXPECT_LT(countId(ids, kNoItem), int(ids.id.size()));  // the scene is in view
  r.setOptions({});
  const ItemBuffer again = r.render(s.view, {glm::dmat4(1.0)});
  EXPECT_TRUE(again.id == withDepth.id);
  EXPECT_TRUE(again.depth == withDepth.depth);
}

TEST(ItemBuffer, FrameTime352x240With400Triangles) {
  const ImageSize size{352, 240};
  RandomScene s = randomScene(400, 5);
  // Four objects so the per-object transform path is exercised.
  std::vector<ItemObject> objects(4);
  for (size_t i = 0; i < s.triangles.size(); ++i) {
    const ItemTriangle& t = s.triangles[i];
    objects[i % 4].addTriangle(t.p[0], t.p[1], t.p[2], t.id);
  }
  ItemBufferRenderer r(size);
  r.setGeometry(objects);
  ItemBuffer b;
  std::vector<glm::dmat4> transforms(4, glm::dmat4(1.0));
  r.render(s.view, transforms, b);  // warm-up (shader JIT)
  const int frames = 50;
  auto start = std::chrono::steady_clock::now();
  for (int f = 0; f < frames; ++f) {
    transforms[1] = glm::translate(glm::dmat4(1.0), glm::dvec3(0.01 * f, 0.0, 0.0));
    r.render(s.view, transforms, b);
  }
  double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() /
      frames;
  std::printf("item buffer 352x240, 400 triangles, 4 objects: %.3f ms/frame\n", ms);
  RecordProperty("ms_per_frame", std::to_string(ms));
  EXPECT_GT(countId(b, kNoItem), 0);
}

TEST(ItemBuffer, RenderersOnSeveralThreadsAgree) {
  // One renderer (and GL context) per thread, rendering concurrently.
  const ImageSize size{352, 240};
  RandomScene s = randomScene(400, 5);
  ItemBuffer reference = renderItemBuffer(s.triangles, s.view, size);
  std::vector<ItemBuffer> results(3);
  std::vector<std::thread> threads;
  for (size_t i = 0; i < results.size(); ++i)
    threads.emplace_back([&, i] {
      for (int k = 0; k < 5; ++k) results[i] = renderItemBuffer(s.triangles, s.view, size);
    });
  for (auto& t : threads) t.join();
  for (const ItemBuffer& r : results) {
    EXPECT_TRUE(r.id == reference.id);
    EXPECT_EQ(std::memcmp(r.depth.data(), reference.depth.data(), r.depth.size() * 4), 0);
  }
}

}  // namespace
}  // namespace rad
