// Scene model on hand-built scenes: glTF 2.0 animation sampling (§3.11, Appendix C), node
// hierarchy, static/dynamic classification, swept bounds, input polygons and cameras.
// Expected values are computed here from first principles, not by calling the model.
#include <gtest/gtest.h>

#include <cmath>

#include "libcommon/scene/scene.h"

namespace rad {
namespace {

constexpr double kPi = 3.14159265358979323846;

glm::dvec3 apply(const glm::dmat4& m, const glm::dvec3& p) {
  return glm::dvec3(m * glm::dvec4(p, 1.0));
}
glm::dvec3 origin(const Scene& s, int node, double t) {
  return apply(s.worldTransform(node, t), glm::dvec3(0.0));
}
// Angle of the image of the x axis about +z, radians in (-pi, pi].
double zAngle(const glm::dmat4& m) {
  glm::dvec3 x = glm::dvec3(m * glm::dvec4(1, 0, 0, 0));
  return std::atan2(x.y, x.x);
}

void expectNear(const glm::dvec3& a, const glm::dvec3& b, double tol = 1e-12) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

// One node, one channel.
Scene oneChannel(AnimationPath path, Interpolation interp, std::vector<double> times,
                 std::vector<double> values) {
  Scene s;
  s.nodes.resize(1);
  s.roots = {0};
  AnimationChannel ch;
  ch.node = 0;
  ch.path = path;
  ch.interpolation = interp;
  ch.times = std::move(times);
  ch.values = std::move(values);
  s.channels.push_back(ch);
  return s;
}

TEST(Animation, StepHoldsLeftKey) {
  Scene s = oneChannel(AnimationPath::kTranslation, Interpolation::kStep, {0, 1, 2},
                       {0, 0, 0, 1, 2, 3, 5, 5, 5});
  expectNear(origin(s, 0, -1.0), {0, 0, 0});
  expectNear(origin(s, 0, 0.5), {0, 0, 0});
  expectNear(origin(s, 0, 1.0), {1, 2, 3});
  expectNear(origin(s, 0, 1.999), {1, 2, 3});
  expectNear(origin(s, 0, 2.0), {5, 5, 5});
  expectNear(origin(s, 0, 10.0), {5, 5, 5});
}

TEST(Animation, LinearTranslationAndScale) {
  Scene s =
      oneChannel(AnimationPath::kTranslation, Interpolation::kLinear, {1, 3}, {0, 0, 0, 4, -2, 8});
  expectNear(origin(s, 0, 0.0), {0, 0, 0});  // held before the first key
  expectNear(origin(s, 0, 1.5), {1, -0.5, 2});
  expectNear(origin(s, 0, 2.0), {2, -1, 4});
  expectNear(origin(s, 0, 4.0), {4, -2, 8});  // held after the last key
  Scene sc = oneChannel(AnimationPath::kScale, Interpolation::kLinear, {0, 2}, {1, 1, 1, 3, 5, 1});
  glm::dmat4 m = sc.localTransform(0, 0.5);  // scale (1.5, 2, 1)
  expectNear(apply(m, {1, 1, 1}), {1.5, 2.0, 1.0});
}

TEST(Animation, CubicSplineHermite) {
  // Keys t=1 and t=3 (t_d = 2). Elements per key: in-tangent, value, out-tangent.
  // x: v0 = 0, b0 (out) = 1, v1 = 2, a1 (in) = 3; the unused tangents (a0, b1) are garbage.
  Scene s = oneChannel(AnimationPath::kTranslation, Interpolation::kCubicSpline, {1, 3},
                       {99, 99, 99, 0, 0, 0, 1, 0, 0,       // key 0
                        3, 0, 0, 2, 1, 0, -77, -77, -77});  // key 1
  auto hermite = [](double s, double v0, double b0, double v1, double a1, double td) {
    return (2 * s * s * s - 3 * s * s + 1) * v0 + td * (s * s * s - 2 * s * s + s) * b0 +
           (-2 * s * s * s + 3 * s * s) * v1 + td * (s * s * s - s * s) * a1;
  };
  // s = 0.5: 0.5*0 + 2*0.125*1 + 0.5*2 + 2*(-0.125)*3 = 0.5
  EXPECT_NEAR(origin(s, 0, 2.0).x, 0.5, 1e-12);
  EXPECT_NEAR(origin(s, 0, 2.0).y, 0.5, 1e-12);
  for (double t : {1.2, 1.7, 2.9}) {
    double sp = (t - 1.0) / 2.0;
    EXPECT_NEAR(origin(s, 0, t).x, hermite(sp, 0, 1, 2, 3, 2), 1e-12) << t;
  }
  expectNear(origin(s, 0, 0.0), {0, 0, 0});
  expectNear(origin(s, 0, 1.0), {0, 0, 0});
  expectNear(origin(s, 0, 3.0), {2, 1, 0});
  expectNear(origin(s, 0, 5.0), {2, 1, 0});
}

TEST(Animation, CubicSplineRotationIsNormalised) {
  // Zero tangents, identity -> 90 deg about z: p(s) = h00 q0 + h01 q1, then normalised.
  const double c = std::cos(kPi / 4), sn = std::sin(kPi / 4);
  Scene s = oneChannel(AnimationPath::kRotation, Interpolation::kCubicSpline, {0, 1},
                       {0, 0, 0, 0, 0, 0, 0,  1, 0, 0, 0, 0,  //
                        0, 0, 0, 0, 0, 0, sn, c, 0, 0, 0, 0});
  const double sp = 0.3, h00 = 2 * sp * sp * sp - 3 * sp * sp + 1, h01 = 1 - h00;
  double qz = h01 * sn, qw = h00 + h01 * c;
  const double len = std::hypot(qz, qw);
  qz /= len;
  qw /= len;
  const double expected = 2 * std::atan2(qz, qw);
  glm::dmat4 m = s.localTransform(0, sp);
  EXPECT_NEAR(zAngle(m), expected, 1e-12);
  EXPECT_NEAR(glm::length(glm::dvec3(m[0])), 1.0, 1e-12);  // rotation is unit: no scaling
}

TEST(Animation, SlerpTakesShortestArc) {
  const double c = std::cos(kPi / 4), sn = std::sin(kPi / 4);
  // identity -> +90 deg about z.
  Scene a = oneChannel(AnimationPath::kRotation, Interpolation::kLinear, {0, 1},
                       {0, 0, 0, 1, 0, 0, sn, c});
  // identity -> the same rotation stored negated (dot < 0): glTF negates it, so the path is
  // still +90 deg, not -270 deg.
  Scene b = oneChannel(AnimationPath::kRotation, Interpolation::kLinear, {0, 1},
                       {0, 0, 0, 1, 0, 0, -sn, -c});
  for (double t : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    EXPECT_NEAR(zAngle(a.localTransform(0, t)), t * kPi / 2, 1e-12) << t;
    EXPECT_NEAR(zAngle(b.localTransform(0, t)), t * kPi / 2, 1e-12) << t;
  }
  // Slerp moves at constant angular speed (unlike nlerp): check a non-symmetric time too.
  Scene wide = oneChannel(AnimationPath::kRotation, Interpolation::kLinear, {0, 1},
                          {0, 0, 0, 1, 0, 0, std::sin(0.8), std::cos(0.8)});  // 1.6 rad
  EXPECT_NEAR(zAngle(wide.localTransform(0, 0.3)), 0.3 * 1.6, 1e-12);
}

TEST(Animation, HierarchyComposesParentFirst) {
  Scene s;
  s.nodes.resize(2);
  s.roots = {0};
  s.nodes[0].children = {1};
  s.nodes[1].parent = 0;
  s.nodes[0].translation = {1, 0, 0};
  s.nodes[0].rotation = glm::angleAxis(kPi / 2, glm::dvec3(0, 0, 1));
  s.nodes[0].scale = {2, 2, 2};
  s.nodes[1].translation = {1, 0, 0};
  // world = T(1,0,0) R(90 z) S(2) * T(1,0,0): child origin = (1,0,0) + R(2,0,0) = (1,2,0).
  expectNear(origin(s, 1, 0.0), {1, 2, 0});
  expectNear(apply(s.worldTransform(1, 0.0), {0, 1, 0}), {1 - 2, 2, 0});
}

TEST(Animation, StartEndTime) {
  Scene s =
      oneChannel(AnimationPath::kTranslation, Interpolation::kLinear, {0.5, 2}, {0, 0, 0, 1, 1, 1});
  AnimationChannel ch = s.channels[0];
  ch.times = {0.25, 1.0};
  s.channels.push_back(ch);
  EXPECT_DOUBLE_EQ(s.startTime(), 0.25);
  EXPECT_DOUBLE_EQ(s.endTime(), 2.0);
  Scene empty;
  EXPECT_EQ(empty.startTime(), 0.0);
  EXPECT_EQ(empty.endTime(), 0.0);
}

TEST(Animation, IsDynamic) {
  // Node 0 moves on [1, 2]; node 1 is its child (static itself); node 2 is static; node 3 has a
  // channel whose keys are all equal; node 4 is linear with a flat first segment.
  Scene s;
  s.nodes.resize(5);
  s.roots = {0, 2, 3, 4};
  s.nodes[0].children = {1};
  s.nodes[1].parent = 0;
  auto add = [&](int node, Interpolation in, std::vector<double> t, std::vector<double> v) {
    AnimationChannel ch;
    ch.node = node;
    ch.interpolation = in;
    ch.times = std::move(t);
    ch.values = std::move(v);
    s.channels.push_back(ch);
  };
  add(0, Interpolation::kLinear, {1, 2}, {0, 0, 0, 1, 0, 0});
  add(3, Interpolation::kLinear, {0, 1, 2}, {3, 3, 3, 3, 3, 3, 3, 3, 3});
  add(4, Interpolation::kLinear, {0, 1, 2}, {0, 0, 0, 0, 0, 0, 1, 0, 0});
  EXPECT_TRUE(s.isDynamic(0, 0.0, 3.0));
  EXPECT_TRUE(s.isDynamic(0, 1.5, 1.6));
  EXPECT_FALSE(s.isDynamic(0, 0.0, 1.0));  // before the first key: held
  EXPECT_FALSE(s.isDynamic(0, 2.0, 5.0));  // after the last key: held
  EXPECT_FALSE(s.isDynamic(0, 1.5, 1.5));  // a single instant
  EXPECT_TRUE(s.isDynamic(1, 0.0, 3.0));   // ancestor moves
  EXPECT_FALSE(s.isDynamic(1, 2.5, 3.0));
  EXPECT_FALSE(s.isDynamic(2, 0.0, 3.0));  // no channel
  EXPECT_FALSE(s.isDynamic(3, 0.0, 3.0));  // constant keys
  EXPECT_FALSE(s.isDynamic(4, 0.0, 1.0));  // flat segment
  EXPECT_TRUE(s.isDynamic(4, 0.5, 1.5));
  EXPECT_TRUE(s.isDynamic(4, 3.0, 0.0));  // reversed range is accepted

  // STEP: the jump at t = 1 is inside [0, 1] but not inside [0, 0.99].
  Scene st =
      oneChannel(AnimationPath::kTranslation, Interpolation::kStep, {0, 1}, {0, 0, 0, 1, 0, 0});
  EXPECT_TRUE(st.isDynamic(0, 0.0, 1.0));
  EXPECT_FALSE(st.isDynamic(0, 0.0, 0.99));
  // CUBICSPLINE with equal values but a non-zero tangent overshoots: dynamic.
  Scene cu = oneChannel(AnimationPath::kTranslation, Interpolation::kCubicSpline, {0, 1},
                        {0, 0, 0, 1, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 1, 0, 0, 0});
  EXPECT_TRUE(cu.isDynamic(0, 0.0, 1.0));
  cu.channels[0].values[8] = 0.0;  // tangents all zero now
  EXPECT_FALSE(cu.isDynamic(0, 0.0, 1.0));
  // Rotation keys q and -q: slerp takes the shortest (zero) arc.
  Scene rq = oneChannel(AnimationPath::kRotation, Interpolation::kLinear, {0, 1},
                        {0, 0, 0, 1, 0, 0, 0, -1});
  EXPECT_FALSE(rq.isDynamic(0, 0.0, 1.0));
  EXPECT_NEAR(zAngle(rq.localTransform(0, 0.5)), 0.0, 1e-12);
}

Mesh unitSquare(int material = -1) {
  Mesh m;
  glm::dvec3 a(0, 0, 0), b(1, 0, 0), c(1, 1, 0), d(0, 1, 0);
  MeshTriangle t1, t2;
  t1.p = {a, b, c};
  t1.uv = {glm::dvec2(0, 0), glm::dvec2(1, 0), glm::dvec2(1, 1)};
  t2.p = {a, c, d};
  t2.uv = {glm::dvec2(0, 0), glm::dvec2(1, 1), glm::dvec2(0, 1)};
  t1.material = t2.material = material;
  m.triangles = {t1, t2};
  return m;
}

TEST(SweptBounds, ContainsSampledPositions) {
  Scene s;
  s.nodes.resize(2);
  s.roots = {0};
  s.nodes[0].children = {1};
  s.nodes[1].parent = 0;
  s.nodes[1].mesh = 0;
  s.nodes[1].translation = {2, 0, 0};
  s.meshes = {unitSquare()};
  // Parent spins 360 deg about z over [0, 1] (5 keys), child moves up with a cubic overshoot.
  AnimationChannel r;
  r.node = 0;
  r.path = AnimationPath::kRotation;
  r.times = {0, 0.25, 0.5, 0.75, 1};
  const double h = std::sqrt(0.5);
  r.values = {0, 0, 0, 1, 0, 0, h, h, 0, 0, 1, 0, 0, 0, h, -h, 0, 0, 0, 1};
  AnimationChannel t;
  t.node = 1;
  t.path = AnimationPath::kTranslation;
  t.interpolation = Interpolation::kCubicSpline;
  t.times = {0, 1};
  t.values = {0, 0, 0, 2, 0, 0, 0, 0, 9, 0, 0, 9, 2, 0, 1, 0, 0, 0};
  s.channels = {r, t};
  for (auto range : {std::array<double, 2>{0.0, 1.0}, {0.1, 0.3}, {-1.0, 0.05}}) {
    auto box = s.sweptBounds(1, range[0], range[1]);
    for (int i = 0; i <= 2000; ++i) {
      double tt = range[0] + (range[1] - range[0]) * i / 2000.0;
      glm::dmat4 m = s.worldTransform(1, tt);
      for (const MeshTriangle& tri : s.meshes[0].triangles)
        for (const glm::dvec3& p : tri.p) {
          glm::dvec3 w = apply(m, p);
          for (int k = 0; k < 3; ++k) {
            ASSERT_LE(box[0][k], w[k]) << tt;
            ASSERT_GE(box[1][k], w[k]) << tt;
          }
        }
    }
  }
  // Full turn: the box must cover the disc of radius |(3,1)| at least; not absurdly more.
  auto box = s.sweptBounds(1, 0.0, 1.0);
  EXPECT_LE(box[0].x, -3.0);
  EXPECT_GE(box[1].x, 3.0);
  EXPECT_LT(box[1].x, 3.5);

  // Static node: exact bounds of its vertices.
  Scene st;
  st.nodes.resize(1);
  st.roots = {0};
  st.nodes[0].mesh = 0;
  st.nodes[0].translation = {5, 6, 7};
  st.meshes = {unitSquare()};
  auto sb = st.sweptBounds(0, 0.0, 10.0);
  expectNear(sb[0], {5, 6, 7});
  expectNear(sb[1], {6, 7, 7});
}

Scene meshScene(Mesh mesh) {
  Scene s;
  s.nodes.resize(1);
  s.roots = {0};
  s.nodes[0].mesh = 0;
  s.meshes = {std::move(mesh)};
  return s;
}

TEST(InputPolygons, SquareMergesToOneQuad) {
  Scene s = meshScene(unitSquare());
  std::vector<InputPolygon> polys = s.inputPolygons();
  ASSERT_EQ(polys.size(), 1u);
  const InputPolygon& q = polys[0];
  EXPECT_EQ(q.local.count, 4);
  EXPECT_NEAR(q.local.area(), 1.0, 1e-15);
  expectNear(q.local.normal(), {0, 0, 1});
  EXPECT_EQ(q.node, 0);
  EXPECT_FALSE(q.backFace);
  // CCW and convex: every turn is to the left about +z.
  for (int i = 0; i < 4; ++i) {
    glm::dvec3 e0 = q.local.v[(i + 1) % 4] - q.local.v[i];
    glm::dvec3 e1 = q.local.v[(i + 2) % 4] - q.local.v[(i + 1) % 4];
    EXPECT_GT(glm::cross(e0, e1).z, 0.0);
  }
  // uv follow their vertices (here uv == xy).
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(q.uv[i].x, q.local.v[i].x);
    EXPECT_EQ(q.uv[i].y, q.local.v[i].y);
  }
}

TEST(InputPolygons, NonMergeablePairsStayTriangles) {
  {
    Mesh m = unitSquare();
    m.triangles[1].p[2].z = 0.01;  // not coplanar
    EXPECT_EQ(meshScene(m).inputPolygons().size(), 2u);
  }
  {
    Mesh m = unitSquare();
    m.triangles[1].p[2].z = 1e-12;  // coplanar within the relative tolerance
    EXPECT_EQ(meshScene(m).inputPolygons().size(), 1u);
  }
  {
    // i = (A, B, C), j = (B, A, D) with D making the quad A, D, B, C reflex at B.
    Mesh m;
    MeshTriangle i, j;
    glm::dvec3 A(0, 0, 0), B(1, 1, 0), C(0, 1, 0), D(3, 1.5, 0);
    i.p = {A, B, C};
    j.p = {B, A, D};
    m.triangles = {i, j};
    auto polys = meshScene(m).inputPolygons();
    ASSERT_EQ(polys.size(), 2u);
    EXPECT_EQ(polys[0].local.count, 3);
    EXPECT_EQ(polys[1].local.count, 3);
  }
  {
    Mesh m = unitSquare();
    m.triangles[1].material = 1;  // different material
    Scene s = meshScene(m);
    s.materials.resize(2);
    EXPECT_EQ(s.inputPolygons().size(), 2u);
  }
  {
    Mesh m = unitSquare();
    m.triangles[1].uv[2] = {0.3, 0.9};  // uv map not affine across the pair
    EXPECT_EQ(meshScene(m).inputPolygons().size(), 2u);
  }
}

TEST(InputPolygons, DoubleSidedAddsReversedCopy) {
  Scene s = meshScene(unitSquare(0));
  s.materials.resize(1);
  s.materials[0].doubleSided = true;
  auto polys = s.inputPolygons();
  ASSERT_EQ(polys.size(), 2u);
  EXPECT_FALSE(polys[0].backFace);
  EXPECT_TRUE(polys[1].backFace);
  EXPECT_EQ(polys[1].material, 0);
  expectNear(polys[1].local.normal(), -polys[0].local.normal());
  EXPECT_NEAR(polys[1].local.area(), polys[0].local.area(), 1e-15);
  // Deterministic: same output twice.
  auto again = s.inputPolygons();
  ASSERT_EQ(again.size(), polys.size());
  for (size_t i = 0; i < polys.size(); ++i)
    EXPECT_EQ(again[i].local.toString(), polys[i].local.toString());
}

TEST(InputPolygons, OrderByNodeAndUnreachableSkipped) {
  Scene s;
  s.nodes.resize(3);
  s.roots = {2, 0};  // node 1 is not in the scene
  for (int i = 0; i < 3; ++i) s.nodes[i].mesh = 0;
  s.meshes = {unitSquare()};
  EXPECT_EQ(s.meshNodes(), (std::vector<int>{0, 2}));
  auto polys = s.inputPolygons();
  ASSERT_EQ(polys.size(), 2u);
  EXPECT_EQ(polys[0].node, 0);
  EXPECT_EQ(polys[1].node, 2);
}

// glTF instancing (issue 58): a mesh many nodes share is merged once and each of its nodes gets
// the same polygons in the mesh's frame, its reversed copies included, in node order.
TEST(InputPolygons, SharedMeshGivesEachNodeTheSamePolygons) {
  Scene s;
  s.nodes.resize(4);
  s.roots = {0, 1, 2, 3};
  s.nodes[0].mesh = s.nodes[2].mesh = s.nodes[3].mesh = 0;
  s.nodes[1].mesh = 1;
  s.nodes[2].translation = {5, 0, 0};
  s.nodes[3].translation = {0, 0, 7};
  Mesh bent = unitSquare(1);
  bent.triangles[1].p[2].z = 0.5;  // two triangles, not a quad
  s.meshes = {unitSquare(0), bent};
  s.materials.resize(2);
  s.materials[0].doubleSided = true;
  const std::vector<InputPolygon> polys = s.inputPolygons();
  ASSERT_EQ(polys.size(), 8u);  // node 0: quad + back, node 1: 2 triangles, nodes 2, 3: as 0
  const std::vector<int> nodes{0, 0, 1, 1, 2, 2, 3, 3};
  for (size_t i = 0; i < polys.size(); ++i) EXPECT_EQ(polys[i].node, nodes[i]) << i;
  for (size_t first : {size_t(4), size_t(6)})
    for (size_t k = 0; k < 2; ++k) {
      EXPECT_EQ(polys[first + k].local.toString(), polys[k].local.toString());
      EXPECT_EQ(polys[first + k].backFace, polys[k].backFace);
      EXPECT_EQ(polys[first + k].uv, polys[k].uv);
    }
  EXPECT_EQ(polys[2].local.count, 3);
  EXPECT_EQ(polys[3].local.count, 3);
}

// A lamp (0.5 m square, facing +z like the ceiling it hangs in front of) `gap` in front of a
// 4 m ceiling square (node 0), at x, y in [1.5, 2].
Scene lampUnderCeiling(double gap) {
  Scene s;
  s.nodes.resize(2);
  s.roots = {0, 1};
  s.nodes[0].mesh = 0;
  s.nodes[0].scale = {4, 4, 1};
  s.nodes[1].mesh = 0;
  s.nodes[1].scale = {0.5, 0.5, 1};
  s.nodes[1].translation = {1.5, 1.5, gap};
  s.meshes = {unitSquare()};
  return s;
}

// contact_cuts.h: the ceiling is cut along the lamp's outline and along rims 2 gaps wide
// outside and inside it, each by a pinwheel of convex quads; nothing else changes.
TEST(InputPolygons, CutAlongTheOutlineOfAPolygonFlatAgainstThem) {
  const std::vector<InputPolygon> polys = lampUnderCeiling(0.001).inputPolygons();
  std::vector<InputPolygon> ceiling;
  for (const InputPolygon& p : polys)
    if (p.node == 0) ceiling.push_back(p);
  ASSERT_EQ(polys.size() - ceiling.size(), 1u);  // the lamp is not cut
  ASSERT_EQ(ceiling.size(), 13u);                // 4 + 4 outer rim + 4 inner rim + 1
  // Local frame (the node scales by 4): the lamp's outline is [0.375, 0.5]^2, the rims 0.5 mm.
  double area = 0.0;
  int underLamp = 0, rims = 0;
  for (const InputPolygon& p : ceiling) {
    EXPECT_EQ(p.local.count, 4);
    area += p.local.area();
    expectNear(p.local.normal(), {0, 0, 1});
    glm::dvec3 lo(1e9), hi(-1e9);
    for (int k = 0; k < 4; ++k) {
      lo = glm::min(lo, p.local.v[k]);
      hi = glm::max(hi, p.local.v[k]);
      // The uv map is the ceiling's own (uv = local x, y for the unit square).
      EXPECT_NEAR(p.uv[k].x, p.local.v[k].x, 1e-12);
      EXPECT_NEAR(p.uv[k].y, p.local.v[k].y, 1e-12);
    }
    // No piece straddles the outline or a rim's edge: each lies inside or outside each square.
    for (double r : {0.0, 0.0005, -0.0005}) {
      const double q0 = 0.375 - r, q1 = 0.5 + r;
      const double overlap = std::max(0.0, std::min(hi.x, q1) - std::max(lo.x, q0)) *
                             std::max(0.0, std::min(hi.y, q1) - std::max(lo.y, q0));
      const bool inside =
          lo.x >= q0 - 1e-12 && hi.x <= q1 + 1e-12 && lo.y >= q0 - 1e-12 && hi.y <= q1 + 1e-12;
      EXPECT_TRUE(overlap < 1e-12 || inside) << p.local.toString() << " square " << r;
    }
    const double width = std::min(hi.x - lo.x, hi.y - lo.y);
    if (std::abs(width - 0.0005) < 1e-12)
      ++rims;
    else  // no sliver along the lines: the other pieces are at least the core's width across
      EXPECT_GE(width, 0.124 - 1e-12) << p.local.toString();
    if (glm::length(lo - glm::dvec3(0.3755, 0.3755, 0)) < 1e-12 &&
        glm::length(hi - glm::dvec3(0.4995, 0.4995, 0)) < 1e-12)
      ++underLamp;
  }
  EXPECT_NEAR(area, 1.0, 1e-12);
  EXPECT_EQ(underLamp, 1);
  EXPECT_EQ(rims, 8);

  // Farther than kContactGap times the lamp's size, lying on it (no gap), behind the ceiling,
  // or moving: not cut.
  EXPECT_EQ(lampUnderCeiling(0.03).inputPolygons().size(), 2u);
  EXPECT_EQ(lampUnderCeiling(0.0).inputPolygons().size(), 2u);
  EXPECT_EQ(lampUnderCeiling(-0.001).inputPolygons().size(), 2u);
  Scene moving = lampUnderCeiling(0.001);
  AnimationChannel ch;
  ch.node = 1;
  ch.times = {0.0, 1.0};
  ch.values = {1.5, 1.5, 0.001, 1.6, 1.5, 0.001};
  moving.channels.push_back(ch);
  EXPECT_EQ(moving.inputPolygons().size(), 2u);
}

TEST(Camera, WorldFromCameraIsRigid) {
  Scene s;
  s.nodes.resize(2);
  s.roots = {0};
  s.nodes[0].scale = {0.001, 0.001, 0.001};
  s.nodes[0].children = {1};
  s.nodes[1].parent = 0;
  s.nodes[1].camera = 0;
  s.nodes[1].name = "cam";
  s.nodes[1].translation = {1000, 2000, 3000};
  s.nodes[1].rotation = glm::angleAxis(kPi, glm::dvec3(0, 1, 0));
  s.cameras.resize(1);
  s.cameras[0].name = "lens";
  EXPECT_EQ(s.cameraNodes(), (std::vector<int>{1}));
  EXPECT_EQ(s.cameraNode(""), 1);
  EXPECT_EQ(s.cameraNode("cam"), 1);
  EXPECT_EQ(s.cameraNode("lens"), 1);
  EXPECT_EQ(s.cameraNode("nope"), -1);
  CameraView v = s.cameraAt(1, 0.0);
  expectNear(v.eye(), {1, 2, 3}, 1e-12);
  glm::dmat3 r(v.worldFromCamera);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(glm::dot(r[i], r[j]), i == j ? 1.0 : 0.0, 1e-12);
  expectNear(r[2], {0, 0, -1}, 1e-12);  // 180 deg about y: camera looks down world +z
  expectNear(r[1], {0, 1, 0}, 1e-12);
}

}  // namespace
}  // namespace rad
