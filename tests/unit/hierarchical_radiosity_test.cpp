// Hierarchical radiosity at one time against tests/data/reference/furnace.json (see the README
// there): uniform furnaces up to rho = 0.999, the exact one-emitter discrete systems, the
// two-squares system, energy balance with refinement, and the shaft test.
#include "libcommon/radiosity/hierarchical_radiosity.h"
#include "libcommon/core/error.h"
#include "libcommon/radiosity/form_factor.h"
#include "libcommon/radiosity/shaft.h"

#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace rad {
namespace {

using Json = nlohmann::json;

const Json& furnace() {
  static Json j = [] {
    std::ifstream in(std::string(RAD_TEST_DATA) + "/reference/furnace.json");
    return Json::parse(in);
  }();
  return j;
}

Polygon polygonOf(const Json& verts) {
  Polygon p;
  p.count = int(verts.size());
  for (int i = 0; i < p.count; ++i)
    p.v[size_t(i)] = {verts[i][0].get<double>(), verts[i][1].get<double>(),
                      verts[i][2].get<double>()};
  return p;
}

PatchHierarchy hierarchyOf(const std::vector<Polygon>& polys) {
  std::vector<InputPolygon> tops;
  for (const Polygon& p : polys) {
    InputPolygon ip;
    ip.local = p;
    tops.push_back(ip);
  }
  return PatchHierarchy(tops);
}

// The quads as Embree triangles, each tagged with its index (the top-level patch id).
std::vector<VisibilityTriangle> visibilityTrianglesOf(const std::vector<Polygon>& quads) {
  std::vector<VisibilityTriangle> tris;
  for (size_t i = 0; i < quads.size(); ++i) {
    const Polygon& p = quads[i];
    tris.push_back({{p.v[0], p.v[1], p.v[2]}, uint32_t(i)});
    tris.push_back({{p.v[0], p.v[2], p.v[3]}, uint32_t(i)});
  }
  return tris;
}

std::vector<Polygon> geometry(const std::string& name) {
  std::vector<Polygon> out;
  for (const Json& p : furnace()["geometries"][name]["patches"]) out.push_back(polygonOf(p));
  return out;
}

// The quad a, b, c, d (counter-clockwise about its front normal).
Polygon quad(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d) {
  Polygon p;
  p.count = 4;
  p.v = {a, b, c, d};
  return p;
}

KeySolveInput identityInput(const PatchHierarchy& h) {
  KeySolveInput in;
  in.topToWorld.assign(size_t(h.topCount()), glm::dmat4(1.0));
  return in;
}

// max_p |1 - sum_q F_pq| over the gathered top-level links (refinement off).
double rowSumError(const KeySolution& s, int tops) {
  std::vector<double> sum(size_t(tops), 0.0);
  for (const SolverLink& l : s.links)
    if (!l.refined) sum[size_t(l.receiver)] += l.fv();
  double e = 0;
  for (double x : sum) e = std::max(e, std::abs(1.0 - x));
  return e;
}

const char* kGeometries[] = {"unit_cube_6", "box_1x2x3_6", "unit_cube_24", "icosahedron_20"};

// B = E / (1 - rho) on every patch. With one fixed quadrature rule per receiver the row sums
// are exact (the point factors of a closed enclosure sum to 1 at every point), so the
// reference's tight tolerance applies; with the per-pair automatic order, the reference's
// general bound rho * rowsum_error / (1 - rho) + stop tolerance.
TEST(HierarchicalRadiosity, UniformFurnace) {
  for (const Json& c : furnace()["cases"]) {
    std::string name = c["name"];
    if (name.rfind("uniform_furnace", 0) != 0) continue;
    double rho = c["rho"], E = c["E"], exact = c["exact_B"]["value"];
    for (const char* g : kGeometries) {
      for (int order : {16, kAutoOrder}) {
        PatchHierarchy h = hierarchyOf(geometry(g));
        std::vector<SurfaceProperties> surf(size_t(h.topCount()));
        for (auto& s : surf) s.reflectance = glm::dvec3(rho), s.emission = glm::dvec3(E);
        RadiosityOptions o;
        o.refine = false;
        o.tol = 1e-7;
        o.quadratureOrder = order;
        KeySolution s = solveKeyTime(h, surf, identityInput(h), o);
        double rowErr = rowSumError(s, h.topCount());
        double tol = order == kAutoOrder ? rho * rowErr / (1 - rho) + 2e-7 + 1e-12 : 1e-6;
        // A fixed rule on a triangle fan (icosahedron) is still exact per point: row sums exact.
        if (order != kAutoOrder) {
          EXPECT_LT(rowErr, 1e-10) << g;
        }
        double worst = 0;
        for (int t = 0; t < h.topCount(); ++t)
          for (int ch = 0; ch < 3; ++ch)
            worst = std::max(worst, std::abs(s.radiosity[size_t(t)][ch] / exact - 1.0));
        EXPECT_LE(worst, tol) << name << " " << g << " order " << order;
        std::cout << name << " " << g << " order " << order << ": " << s.iterations
                  << " sweeps, max rel err " << worst << " (row-sum err " << rowErr << ")\n";
      }
    }
  }
}

// Exact solutions of the discrete systems (refinement off): |dB/B| ~ |dF| / (1 - rho).
TEST(HierarchicalRadiosity, OneEmitterDiscreteSystems) {
  for (const Json& c : furnace()["cases"]) {
    std::string name = c["name"];
    if (name.rfind("one_emitter", 0) != 0) continue;
    double rho = c["rho"];
    PatchHierarchy h = hierarchyOf(geometry(c["geometry"]));
    std::vector<SurfaceProperties> surf(size_t(h.topCount()));
    for (int t = 0; t < h.topCount(); ++t) {
      surf[size_t(t)].reflectance = glm::dvec3(rho);
      surf[size_t(t)].emission = glm::dvec3(c["E"][t].get<double>());
    }
    RadiosityOptions o;
    o.refine = false;
    o.tol = 1e-7;
    KeySolution s = solveKeyTime(h, surf, identityInput(h), o);
    double tol = rho <= 0.9 ? 1e-5 : rho <= 0.99 ? 1e-4 : 1e-3;
    double worst = 0;
    for (int t = 0; t < h.topCount(); ++t) {
      double exact = c["exact_B"][t];
      double err = std::abs(s.radiosity[size_t(t)].x - exact) / std::max(exact, 1e-300);
      if (exact == 0) err = std::abs(s.radiosity[size_t(t)].x);
      worst = std::max(worst, err);
    }
    EXPECT_LE(worst, tol) << name;
    // Energy balance of the discrete system: sum A B = sum A E / (1 - rho).
    double sumAB = 0, sumAE = 0;
    for (int t = 0; t < h.topCount(); ++t) {
      sumAB += s.area[size_t(t)] * s.radiosity[size_t(t)].x;
      sumAE += s.area[size_t(t)] * surf[size_t(t)].emission.x;
    }
    EXPECT_NEAR(sumAB / (sumAE / (1 - rho)), 1.0, tol) << name;
    std::cout << name << ": " << s.iterations << " sweeps, max rel err " << worst << "\n";
  }
}

Polygon square(double z, bool up) {
  Polygon p;
  p.count = 4;
  if (up)
    p.v = {glm::dvec3(0, 0, z), glm::dvec3(1, 0, z), glm::dvec3(1, 1, z), glm::dvec3(0, 1, z)};
  else
    p.v = {glm::dvec3(0, 0, z), glm::dvec3(0, 1, z), glm::dvec3(1, 1, z), glm::dvec3(1, 0, z)};
  return p;
}

// Two opposed unit squares, nothing else: the exact two-patch system of furnace.json.
TEST(HierarchicalRadiosity, TwoSquaresDiscrete) {
  const Json* c = nullptr;
  for (const Json& x : furnace()["cases"])
    if (x["name"] == "two_squares_discrete") c = &x;
  ASSERT_NE(c, nullptr);
  for (const Json& v : (*c)["values"]) {
    double d = v["d"];
    PatchHierarchy h = hierarchyOf({square(0, true), square(d, false)});
    std::vector<SurfaceProperties> surf(2);
    surf[0] = {glm::dvec3(v["rho1"].get<double>()), glm::dvec3(v["E1"].get<double>())};
    surf[1] = {glm::dvec3(v["rho2"].get<double>()), glm::dvec3(v["E2"].get<double>())};
    RadiosityOptions o;
    o.refine = false;
    o.tol = 1e-9;
    o.quadratureOrder = d < 0.05 ? 64 : kAutoOrder;  // near contact (README: 16x16 is off 2e-4)
    KeySolution s = solveKeyTime(h, surf, identityInput(h), o);
    EXPECT_NEAR(s.radiosity[0].x / v["B1"].get<double>(), 1.0, 1e-5) << "d " << d;
    EXPECT_NEAR(s.radiosity[1].x / v["B2"].get<double>(), 1.0, 1e-5) << "d " << d;
  }
}

// Refinement: the area-weighted sum of the leaf links between the two squares converges to
// the exact C-11 form factor, and subdividing moves it towards it.
TEST(HierarchicalRadiosity, TwoSquaresRefinedFormFactor) {
  const double exact = 0.19982489569838738304;  // formfactors.json par_unit_squares_d1
  PatchHierarchy h = hierarchyOf({square(0, true), square(1, false)});
  std::vector<SurfaceProperties> surf(2);
  surf[0] = {glm::dvec3(0.5), glm::dvec3(0.0)};
  surf[1] = {glm::dvec3(0.5), glm::dvec3(1.0)};
  RadiosityOptions o;
  o.eps = 1e-3;
  o.minArea = 1e-3;
  KeySolution s = solveKeyTime(h, surf, identityInput(h), o);
  double f = 0;  // F(square 0 -> square 1) from the leaf links gathered by square 0's subtree
  size_t leafLinks = 0;
  for (const SolverLink& l : s.links)
    if (!l.refined && h.node(l.receiver).id.top == 0) {
      f += s.area[size_t(l.receiver)] * l.fv();
      ++leafLinks;
    }
  EXPECT_GT(leafLinks, 4u);  // it did refine
  EXPECT_NEAR(f, exact, 1e-6);
  std::cout << "refined two squares: " << leafLinks << " leaf links, F = " << f << " (exact "
            << exact << ")\n";
}

// The rectangle [u0, u1] x [v0, v1] of a parallelogram face, in its (v1 - v0, v3 - v0) frame:
// same plane, same winding.
Polygon subRectangle(const Polygon& f, double u0, double u1, double v0, double v1) {
  glm::dvec3 du = f.v[1] - f.v[0], dv = f.v[3] - f.v[0];
  Polygon p;
  p.count = 4;
  p.v = {f.v[0] + u0 * du + v0 * dv, f.v[0] + u1 * du + v0 * dv, f.v[0] + u1 * du + v1 * dv,
         f.v[0] + u0 * du + v1 * dv};
  return p;
}

// Closed box, small light flush with the ceiling, refinement on: absorbed = emitted power.
// The enclosure is exactly closed (the ceiling is cut into a 3 x 3 grid whose centre cell is
// the light), so every point sees exactly one hemisphere of patches and the only imbalance
// left is hierarchical radiosity's own: a link gathers its shooter's mean radiosity through
// the shooter's mean form factor. (An earlier version hung the light 1 mm below the ceiling
// with visibility off: the floor then saw both the light and the ceiling behind it, an excess
// of F(floor -> light) per bounce, amplified by 1 / (1 - rho) to 9-13 % at rho = 0.9.)
// With visibility, as rad-global always runs, the closed-room rows and the closure's per-top
// ratios balance it to 0.1-0.5 % (one ratio for a leaf's whole row had left 2.2-5.1 %); without
// visibility (plain hierarchical radiosity with the closure) 1.7-4.1 %.
TEST(HierarchicalRadiosity, EnergyBalanceWithRefinement) {
  for (bool visible : {true, false})
    for (RefinementOracle oracle : {RefinementOracle::kPower, RefinementOracle::kError})
      for (double rho : {0.5, 0.9}) {
        for (double eps : {1e-3, 3e-4}) {
          std::vector<Polygon> cube = geometry("unit_cube_6"), polys;
          int ceiling = -1;
          for (int i = 0; i < int(cube.size()); ++i) {
            bool top = true;
            for (int k = 0; k < cube[size_t(i)].count; ++k)
              top &= cube[size_t(i)].v[size_t(k)].z == 1.0;
            if (top)
              ceiling = i;
            else
              polys.push_back(cube[size_t(i)]);
          }
          ASSERT_GE(ceiling, 0);
          const double cut[4] = {0.0, 0.4, 0.6, 1.0};
          int lightIndex = -1;
          for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) {
              if (a == 1 && b == 1) lightIndex = int(polys.size());
              polys.push_back(
                  subRectangle(cube[size_t(ceiling)], cut[a], cut[a + 1], cut[b], cut[b + 1]));
            }
          PatchHierarchy h = hierarchyOf(polys);
          std::vector<SurfaceProperties> surf(size_t(h.topCount()));
          for (auto& s : surf) s.reflectance = glm::dvec3(rho);
          surf[size_t(lightIndex)].emission = glm::dvec3(1.0, 2.0, 3.0);
          RadiosityOptions o;
          o.eps = eps;
          o.oracle = oracle;
          o.minArea = 1e-3;
          o.tol = 1e-7;
          VisibilityScene vis(visibilityTrianglesOf(polys));
          KeySolveInput in = identityInput(h);
          if (visible) in.visibility = &vis;
          KeySolution s = solveKeyTime(h, surf, in, o);
          glm::dvec3 absorbed = s.absorbedPower(h, surf), emitted = s.emittedPower(h, surf);
          double imbalance = std::abs(absorbed.x / emitted.x - 1.0);
          std::cout << "closed box, " << (visible ? "visibility, " : "no visibility, ")
                    << (oracle == RefinementOracle::kPower ? "power" : "error") << " oracle, rho "
                    << rho << ", eps " << eps << ": " << h.size() << " nodes, " << s.links.size()
                    << " links, " << s.iterations << " sweeps, absorbed/emitted "
                    << absorbed.x / emitted.x << "\n";
          for (int c = 0; c < 3; ++c)  // the channels scale together: E is (1, 2, 3), rho grey
            EXPECT_NEAR(absorbed[c] / emitted[c], absorbed.x / emitted.x, 1e-9);
          // Without visibility the imbalance is amplified by 1 / (1 - rho) (at rho = 0.99 it
          // is 20-47 %): tighten eps and minArea for bright, closed interiors.
          if (visible)  // measured 0.17-0.52 % at eps 1e-3, 0.09-0.37 % at 3e-4
            EXPECT_LT(imbalance, eps > 5e-4 ? 0.006 : 0.004) << rho << " " << eps;
          else
            EXPECT_LT(imbalance, rho <= 0.5 ? 0.025 : 0.08) << rho << " " << eps;
          EXPECT_GT(h.size(), 14 * 5);  // it did refine
        }
      }
}

// An axis-aligned box's six faces, facing out (inward = false) or in.
std::vector<Polygon> boxFaces(glm::dvec3 lo, glm::dvec3 hi, bool inward) {
  double x0 = lo.x, y0 = lo.y, z0 = lo.z, x1 = hi.x, y1 = hi.y, z1 = hi.z;
  std::vector<std::array<glm::dvec3, 4>> q = {
      {{{x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0}}},   // -z
      {{{x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}}},   // +z
      {{{x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1}}},   // -y
      {{{x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0}}},   // +y
      {{{x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0}}},   // -x
      {{{x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1}}}};  // +x
  std::vector<Polygon> out;
  for (auto& f : q) {
    Polygon p;
    p.count = 4;
    for (int i = 0; i < 4; ++i) p.v[size_t(i)] = f[size_t(inward ? 3 - i : i)];
    out.push_back(p);
  }
  return out;
}

// Issue 3 item 9, extremes: a room scaled to 1 mm and to 10 km, emission 1e-6 and 1e6,
// reflectance 0 and 0.999, a block standing on the floor (its bottom face touches the floor,
// coplanar and facing it; its sides meet the floor along an edge), visibility by Embree.
// Radiosity stays finite and non-negative, is linear in the emission and does not depend on
// the scene's scale.
TEST(HierarchicalRadiosity, ExtremesStayFiniteLinearAndScaleFree) {
  auto solve = [](double scale, double emission, double rho, double* seconds) {
    std::vector<Polygon> polys = boxFaces({0, 0, 0}, {1, 1, 1}, true);
    for (const Polygon& p : boxFaces({0.3, 0.3, 0.0}, {0.6, 0.5, 0.4}, false)) polys.push_back(p);
    int light = int(polys.size());
    Polygon l;  // facing down, 1 mm below the ceiling
    l.count = 4;
    double z = 1 - 1e-3;
    l.v = {glm::dvec3(0.4, 0.4, z), glm::dvec3(0.4, 0.6, z), glm::dvec3(0.6, 0.6, z),
           glm::dvec3(0.6, 0.4, z)};
    polys.push_back(l);
    std::vector<VisibilityTriangle> tris;
    for (Polygon& p : polys) {
      for (auto& v : p.v) v *= scale;
      tris.push_back({{p.v[0], p.v[1], p.v[2]}, uint32_t(tris.size() / 2)});
      tris.push_back({{p.v[0], p.v[2], p.v[3]}, uint32_t(tris.size() / 2)});
    }
    PatchHierarchy h = hierarchyOf(polys);
    VisibilityScene vis(tris);
    KeySolveInput in = identityInput(h);
    in.visibility = &vis;
    std::vector<SurfaceProperties> surf(polys.size());
    for (auto& sp : surf) sp.reflectance = glm::dvec3(rho);
    surf[size_t(light)].emission = glm::dvec3(emission);
    RadiosityOptions o;
    o.eps = 2e-2;
    o.minArea = 1e-3 * scale * scale;
    o.tol = 1e-6;
    auto t0 = std::chrono::steady_clock::now();
    KeySolution s = solveKeyTime(h, surf, in, o);
    *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::vector<double> top;
    for (int i = 0; i < h.size(); ++i) {
      if (!s.inTree(i, h)) continue;
      for (int c = 0; c < 3; ++c) {
        EXPECT_TRUE(std::isfinite(s.radiosity[size_t(i)][c])) << scale << " " << emission;
        EXPECT_GE(s.radiosity[size_t(i)][c], 0.0) << scale << " " << emission;
      }
    }
    // Mean irradiance per top-level patch (radiosity is 0 off the light at rho = 0).
    top.assign(size_t(h.topCount()), 0.0);
    for (int i = 0; i < h.size(); ++i)
      if (s.inTree(i, h) && !s.split[size_t(i)])
        top[h.node(i).id.top] += s.area[size_t(i)] * s.irradiance[size_t(i)].x;
    for (int t = 0; t < h.topCount(); ++t) top[size_t(t)] /= s.area[size_t(t)] * emission;
    return top;
  };
  for (double rho : {0.0, 0.999}) {
    double sec = 0, worstEmission = 0, worstScale = 0;
    std::vector<double> ref = solve(1.0, 1.0, rho, &sec);
    EXPECT_GT(ref[0], 0.0);     // the floor is lit
    EXPECT_LT(ref[6], ref[0]);  // under the block: its bottom face, touching the floor
    for (double e : {1e-6, 1e6}) {
      std::vector<double> b = solve(1.0, e, rho, &sec);
      for (size_t t = 0; t < b.size(); ++t)
        worstEmission = std::max(worstEmission, std::abs(b[t] - ref[t]) / std::max(ref[t], 1e-300));
    }
    for (double scale : {1e-3, 1e4}) {
      std::vector<double> b = solve(scale, 1.0, rho, &sec);
      for (size_t t = 0; t < b.size(); ++t)
        worstScale = std::max(worstScale, std::abs(b[t] - ref[t]) / std::max(ref[t], 1e-300));
    }
    std::cout << "extremes rho " << rho << ": relative change with emission " << worstEmission
              << ", with scale " << worstScale << " (last solve " << sec << " s)\n";
    EXPECT_LT(worstEmission, 1e-9) << rho;
    // Measured: identical to 1e-15 at rho = 0 and at 10 km. At 1 mm and rho = 0.999 the
    // refinement takes other decisions (2413 instead of 2837 nodes: some test at the eps
    // threshold comes out the other way in rounding) and 1 / (1 - rho) = 1000 amplifies what
    // that moves to 2.3 %.
    EXPECT_LT(worstScale, rho < 0.5 ? 1e-9 : 5e-2) << rho;
  }
}

// Visibility in a convex enclosure is 1 for every link; an inner blocker lowers it.
TEST(HierarchicalRadiosity, VisibilityInsideEnclosure) {
  std::vector<Polygon> polys = geometry("unit_cube_6");
  PatchHierarchy h = hierarchyOf(polys);
  VisibilityScene vis(visibilityTrianglesOf(polys));
  KeySolveInput in = identityInput(h);
  in.visibility = &vis;
  std::vector<SurfaceProperties> surf(6);
  surf[0].emission = glm::dvec3(1.0);
  RadiosityOptions o;
  o.refine = false;
  KeySolution s = solveKeyTime(h, surf, in, o);
  for (const SolverLink& l : s.links) EXPECT_EQ(l.visibility, 1.0f);
  EXPECT_EQ(s.links.size(), 30u);  // every ordered pair of distinct faces
}

TEST(HierarchicalRadiosity, ShaftMeetsBox) {
  Polygon a = square(0, true), b = square(1, false);
  // Inside the shaft, outside it beside it, and beyond the ends.
  EXPECT_TRUE(shaftMeetsBox(a, b, {0.4, 0.4, 0.4}, {0.6, 0.6, 0.6}));
  EXPECT_FALSE(shaftMeetsBox(a, b, {1.1, 0.4, 0.4}, {1.3, 0.6, 0.6}));
  EXPECT_FALSE(shaftMeetsBox(a, b, {0.4, 0.4, 1.1}, {0.6, 0.6, 1.3}));
  // Two small squares far apart along a diagonal: a box near the missing corner of their
  // bounding box is outside the hull though inside the bounding box.
  Polygon c = a, d = b;
  for (auto& v : c.v) v *= 0.1;
  for (auto& v : d.v) v = v * 0.1 + glm::dvec3(2, 2, 2);
  EXPECT_FALSE(shaftMeetsBox(c, d, {1.8, 0.0, 0.0}, {2.1, 0.3, 0.3}));
  EXPECT_TRUE(shaftMeetsBox(c, d, {0.95, 0.95, 0.95}, {1.15, 1.15, 1.15}));
}

}  // namespace
}  // namespace rad

namespace rad {
namespace {

std::vector<SurfaceProperties> furnaceSurfaces(const PatchHierarchy& h, double rho) {
  std::vector<SurfaceProperties> surf(size_t(h.topCount()));
  for (auto& s : surf) s.reflectance = glm::dvec3(rho), s.emission = glm::dvec3(0.5);
  return surf;
}

// The closed furnace at rho = 0.999 with refinement at the default eps: the refined links'
// form factors sum to a little more than 1 (the row-sum error), so rho x rowsum > 1 and the
// Gauss-Seidel sweeps grow without bound. The solve must stop with one error, not hand back
// NaN radiosity as converged (it did: NaN hid from the stop rule's std::max).
TEST(HierarchicalRadiosity, DivergingSolveIsAnErrorNotNaN) {
  PatchHierarchy h = hierarchyOf(geometry("unit_cube_6"));
  std::vector<SurfaceProperties> surf = furnaceSurfaces(h, 0.999);
  RadiosityOptions o;
  o.closure = false;  // refined row sums above 1 / rho: diverges
  o.oracle = RefinementOracle::kPower;
  try {
    KeySolution s = solveKeyTime(h, surf, identityInput(h), o);
    for (const glm::dvec3& b : s.radiosity)
      ASSERT_TRUE(std::isfinite(b.x) && std::isfinite(b.y) && std::isfinite(b.z));
    SUCCEED() << "converged to finite values";
  } catch (const Error& e) {
    // The scene's reflectance or the flags' refinement cause it: bad input (exit 1), not a bug.
    EXPECT_EQ(e.code(), ExitCode::kBadInput);
    EXPECT_NE(std::string(e.what()).find("diverges"), std::string::npos) << e.what();
  }
}

// The link bound: refinement stops at maxLinks, says so, and the solve still converges on the
// links it has (the furnace at rho = 0.5 refines far past 200 links at eps 1e-5).
TEST(HierarchicalRadiosity, LinkBoundStopsRefiningAndSaysSo) {
  PatchHierarchy h = hierarchyOf(geometry("unit_cube_6"));
  std::vector<SurfaceProperties> surf = furnaceSurfaces(h, 0.5);
  RadiosityOptions o;
  o.eps = 1e-5;
  o.maxLinks = 200;
  KeySolution s = solveKeyTime(h, surf, identityInput(h), o);
  EXPECT_TRUE(s.linkCapReached);
  EXPECT_LE(s.links.size(), o.maxLinks);
  for (const glm::dvec3& b : s.radiosity) {
    ASSERT_TRUE(std::isfinite(b.x));
    EXPECT_NEAR(b.x, 1.0, 0.05);  // E / (1 - rho) = 1, coarse links
  }
  PatchHierarchy h2 = hierarchyOf(geometry("unit_cube_6"));
  o.maxLinks = RadiosityOptions().maxLinks;
  KeySolution unbounded = solveKeyTime(h2, surf, identityInput(h2), o);
  EXPECT_FALSE(unbounded.linkCapReached);
  EXPECT_GT(unbounded.links.size(), size_t(200));
}

// Energy conservation with refinement on (docs/design.md §6.1 "Energy"): the closed furnaces at the
// default settings, every leaf at E / (1 - rho) to 1e-3 up to rho = 0.999, with as many links at
// rho = 0.999 as at 0.5 (the oracle relative to the power carried). Without the closure factor
// the refined row sums range over 0.86 .. 1.23 and B is several per cent off at rho = 0.9.
TEST(HierarchicalRadiosity, RefinedFurnaceConservesEnergy) {
  for (const char* g : {"unit_cube_6", "box_1x2x3_6", "icosahedron_20"}) {
    size_t linksAtHalf = 0;
    for (double rho : {0.5, 0.9, 0.99, 0.999}) {
      PatchHierarchy h = hierarchyOf(geometry(g));
      std::vector<SurfaceProperties> surf = furnaceSurfaces(h, rho);
      KeySolution s = solveKeyTime(h, surf, identityInput(h), RadiosityOptions());
      const double exact = surf[0].emission.x / (1.0 - rho);
      double worst = 0;
      size_t leaves = 0;
      for (int i = 0; i < h.size(); ++i) {
        if (!s.inTree(i, h) || s.split[size_t(i)]) continue;
        ++leaves;
        worst = std::max(worst, std::abs(s.radiosity[size_t(i)].x / exact - 1.0));
      }
      EXPECT_GT(leaves, size_t(h.topCount())) << g << ": refinement is on";
      EXPECT_LT(worst, 1e-3) << g << " rho " << rho;
      if (rho == 0.5) linksAtHalf = s.links.size();
      EXPECT_LE(s.links.size(), 2 * linksAtHalf) << g << " rho " << rho;
      std::cout << g << " rho " << rho << ": " << leaves << " leaves, " << s.links.size()
                << " links, worst leaf " << worst << "\n";
    }
  }
  PatchHierarchy h = hierarchyOf(geometry("unit_cube_6"));
  RadiosityOptions plain;  // HSA'91's power oracle without the closure
  plain.closure = false;
  plain.oracle = RefinementOracle::kPower;
  KeySolution s = solveKeyTime(h, furnaceSurfaces(h, 0.9), identityInput(h), plain);
  double mean = 0, area = 0;
  for (int i = 0; i < h.size(); ++i)
    if (s.inTree(i, h) && !s.split[size_t(i)]) {
      mean += s.area[size_t(i)] * s.radiosity[size_t(i)].x;
      area += s.area[size_t(i)];
    }
  const double exact = furnaceSurfaces(h, 0.9)[0].emission.x / 0.1;
  EXPECT_GT(std::abs(mean / area / exact - 1.0), 0.01) << "the plain gather is what failed";
}

// The closed furnace with a slab floating inside it: every link that the slab occludes has a
// visibility estimated from 16 ray pairs, whose error does not cancel within one receiver, and
// at rho = 0.99 the row-sum error is amplified a hundredfold (the whole pipeline's frames were
// 18 % too dark). Inside a closed room a leaf's row sum is exactly 1, and the closure makes it
// so: every leaf within 1 % of L_e / (1 - rho); without the closed-room rows, more than 5 % off.
TEST(HierarchicalRadiosity, OccludedFurnaceRowsSumToOneInAClosedRoom) {
  // A 2 m cube facing inwards, and a slab 0.1 x 1.6 x 1.4 facing outwards, 0.2 m from the floor
  // and the ceiling and 0.3 m from the walls.
  std::vector<Polygon> polys = boxFaces({0, 0, 0}, {2, 2, 2}, true);
  for (const Polygon& p : boxFaces({1.45, 0.2, 0.3}, {1.55, 1.8, 1.7}, false)) polys.push_back(p);
  ASSERT_GT(glm::dot(polys[2].normal(), glm::dvec3(0, 1, 0)), 0.0) << "the floor faces inwards";
  ASSERT_LT(glm::dot(polys[8].normal(), glm::dvec3(0, 1, 0)), 0.0) << "the slab faces outwards";
  VisibilityScene vis(visibilityTrianglesOf(polys));
  const double rho = 0.99;
  PatchHierarchy h = hierarchyOf(polys);
  std::vector<SurfaceProperties> surf = furnaceSurfaces(h, rho);
  const double exact = surf[0].emission.x / (1.0 - rho);
  auto worstLeaf = [&](bool closedRooms) {
    KeySolveInput in = identityInput(h);
    in.visibility = &vis;
    RadiosityOptions o;
    o.closedRooms = closedRooms;
    KeySolution s = solveKeyTime(h, surf, in, o);
    double worst = 0;
    for (int i = 0; i < h.size(); ++i)
      if (s.inTree(i, h) && !s.split[size_t(i)] && s.exposure[size_t(i)] > 0.0)
        worst = std::max(worst, std::abs(s.radiosity[size_t(i)].x / exact - 1.0));
    std::cout << (closedRooms ? "closed-room rows" : "without them") << ": worst leaf " << worst
              << "\n";
    return worst;
  };
  EXPECT_LT(worstLeaf(true), 0.01);
  EXPECT_GT(worstLeaf(false), 0.05) << "what failed";
}

// One key time of `polys` with visibility between them, at the default options.
KeySolution solveWithVisibility(PatchHierarchy& h, const std::vector<Polygon>& polys,
                                const std::vector<SurfaceProperties>& surf) {
  VisibilityScene vis(visibilityTrianglesOf(polys));
  KeySolveInput in = identityInput(h);
  in.visibility = &vis;
  return solveKeyTime(h, surf, in, RadiosityOptions());
}

// Every patch white (reflectance 0.5), patch 1 a light of emission 1.
std::vector<SurfaceProperties> whiteUnderALight(size_t patches) {
  std::vector<SurfaceProperties> surf(patches);
  for (auto& sp : surf) sp.reflectance = glm::dvec3(0.5);
  surf[1].emission = glm::dvec3(1.0);
  return surf;
}

// Exposure (the darkening at contacts): a box standing on a floor covers a quadrant of it. The
// floor's links from under the box are blocked, so without exposure the floor's radiosity (the
// area average) is pulled down by the dark covered part, which nothing sees. With it, the
// covered quadrant has exposure ~0, the rest 1, and the floor's B is the average over what is
// exposed: within the exposed children's range, not a quarter below it.
TEST(HierarchicalRadiosity, CoveredAreaDoesNotDarkenWhatIsExposed) {
  std::vector<Polygon> polys = {
      quad({0, 0, 0}, {0, 0, 2}, {2, 0, 2}, {2, 0, 0}),      // floor, +y
      quad({0, 1, 0}, {2, 1, 0}, {2, 1, 2}, {0, 1, 2}),      // light, -y
      quad({0, .5, 0}, {0, .5, 1}, {1, .5, 1}, {1, .5, 0}),  // box top, +y
      quad({1, 0, 0}, {1, .5, 0}, {1, .5, 1}, {1, 0, 1}),    // +x
      quad({0, 0, 0}, {0, 0, 1}, {0, .5, 1}, {0, .5, 0}),    // -x
      quad({0, 0, 1}, {1, 0, 1}, {1, .5, 1}, {0, .5, 1}),    // +z
      quad({0, 0, 0}, {0, .5, 0}, {1, .5, 0}, {1, 0, 0})};   // -z
  PatchHierarchy h = hierarchyOf(polys);
  KeySolution s = solveWithVisibility(h, polys, whiteUnderALight(polys.size()));
  ASSERT_TRUE(s.split[0]) << "the floor is subdivided";
  const int first = h.node(0).firstChild;
  double lo = 1e300, hi = 0;
  int covered = -1;
  for (int c = 0; c < 4; ++c) {
    glm::dvec3 centre = s.world[size_t(first + c)].centroid();
    bool under = centre.x < 1 && centre.z < 1;
    double e = s.exposure[size_t(first + c)];
    if (under) {
      covered = first + c;
      EXPECT_LT(e, 0.1) << "the quadrant under the box";
    } else {
      EXPECT_EQ(e, 1.0) << "child " << c;
      lo = std::min(lo, s.radiosity[size_t(first + c)].x);
      hi = std::max(hi, s.radiosity[size_t(first + c)].x);
    }
  }
  ASSERT_GE(covered, 0);
  EXPECT_GE(s.radiosity[0].x, lo * (1 - 1e-9));
  EXPECT_LE(s.radiosity[0].x, hi * (1 + 1e-9));
  EXPECT_LT(s.radiosity[size_t(covered)].x, 0.2 * lo) << "the covered part stays dark";
  EXPECT_EQ(s.exposure[1], 1.0) << "the light is exposed";
}

// The radiosity of the floor's leaf at point p (the deepest node of the key's tree holding it).
double floorLeafRadiosityAt(const PatchHierarchy& h, const KeySolution& s, glm::dvec3 p) {
  int n = 0;
  while (s.split[size_t(n)]) {
    int next = -1;
    for (int c = 0; c < 4; ++c) {
      const Polygon& w = s.world[size_t(h.node(n).firstChild + c)];
      glm::dvec3 lo = w.v[0], hi = w.v[0];
      for (int i = 1; i < w.count; ++i)
        lo = glm::min(lo, w.v[size_t(i)]), hi = glm::max(hi, w.v[size_t(i)]);
      if (p.x >= lo.x && p.x <= hi.x && p.z >= lo.z && p.z <= hi.z) next = h.node(n).firstChild + c;
    }
    if (next < 0) break;
    n = next;
  }
  return s.radiosity[size_t(n)].x;
}

// A shadow boundary across the floor (issue 56): a low wall stands on it between a small light
// and the strip behind it. The floor leaf there holds one radiosity; rad-movies gathers it
// wherever a near surface sees that floor (the bundled scene's short box over the floor in its
// own shadow, which came out too bright). A partly visible link is refined while the light its
// one V misplaces exceeds --shadow-eps-share x eps, so the leaf behind the wall carries the
// shadow's radiosity, as a far finer solve does, and not the mean of the lit and shadowed sides.
TEST(HierarchicalRadiosity, AFloorLeafInAShadowCarriesTheShadowsRadiosity) {
  std::vector<Polygon> polys = {
      quad({0, 0, 0}, {0, 0, 2}, {2, 0, 2}, {2, 0, 0}),              // floor, +y
      quad({.8, 1, .8}, {1.2, 1, .8}, {1.2, 1, 1.2}, {.8, 1, 1.2}),  // light, -y
      quad({0, 0, 1.3}, {0, .3, 1.3}, {2, .3, 1.3}, {2, 0, 1.3}),    // low wall, -z
      quad({0, 0, 1.3}, {2, 0, 1.3}, {2, .3, 1.3}, {0, .3, 1.3})};   // its back, +z
  std::vector<SurfaceProperties> surf = whiteUnderALight(polys.size());
  auto solve = [&](double eps, double share) {
    PatchHierarchy h = hierarchyOf(polys);
    VisibilityScene vis(visibilityTrianglesOf(polys));
    KeySolveInput in = identityInput(h);
    in.visibility = &vis;
    RadiosityOptions o;
    o.eps = eps;
    o.shadowEpsShare = share;
    KeySolution s = solveKeyTime(h, surf, in, o);
    std::vector<double> b;
    for (double z : {1.35, 1.45, 1.6}) b.push_back(floorLeafRadiosityAt(h, s, {1.0, 0.0, z}));
    return b;
  };
  const RadiosityOptions defaults;
  const std::vector<double> fine = solve(defaults.eps / 16, 0.0);
  const std::vector<double> got = solve(defaults.eps, defaults.shadowEpsShare);
  // Behind the wall (z 1.35: nearly all of the light hidden; 1.45: half) within a tenth of the
  // lit floor's radiosity (z 1.6) of the finer solve; without the rule the leaf at 1.35 held
  // the mean of both sides, several times the shadow's radiosity.
  for (size_t i = 0; i < 2; ++i) EXPECT_NEAR(got[i], fine[i], 0.1 * fine[2]) << "z index " << i;
  EXPECT_LT(got[0], 0.5 * got[2]) << "the leaf behind the wall is in the shadow";
}

// A thin sheet made of two back-to-back one-sided patches (the table scene's car fins) standing
// on a floor: a floor point's ray into it meets a front and a back at one distance. It is not
// inside a solid: every floor node stays wholly exposed. Counting such a ray as covered (the
// first answer to a partition flush with the ceiling) took 4-5 % of the light off the car.
TEST(HierarchicalRadiosity, ASheetOfTwoBackToBackPatchesCoversNothing) {
  std::vector<Polygon> polys = {
      quad({0, 0, 0}, {0, 0, 2}, {2, 0, 2}, {2, 0, 0}),     // floor, +y
      quad({0, 1, 0}, {2, 1, 0}, {2, 1, 2}, {0, 1, 2}),     // light, -y
      quad({1, 0, 0}, {1, .5, 0}, {1, .5, 2}, {1, 0, 2}),   // sheet, +x
      quad({1, 0, 0}, {1, 0, 2}, {1, .5, 2}, {1, .5, 0})};  // its back, -x
  PatchHierarchy h = hierarchyOf(polys);
  KeySolution s = solveWithVisibility(h, polys, whiteUnderALight(polys.size()));
  int floorNodes = 0;
  for (int i = 0; i < h.size(); ++i)
    if (h.node(i).id.top == 0 && s.inTree(i, h)) {
      EXPECT_EQ(s.exposure[size_t(i)], 1.0) << "floor node " << i;
      ++floorNodes;
    }
  EXPECT_GT(floorNodes, 4) << "the floor is subdivided beside the sheet";
}

// The closure factor corrects a leaf's row where its ancestor's links average a top's form
// factor over more than the leaf (a floor leaf beside a wall sees much more of the wall than its
// parent does). That correction belongs to the wall's share alone: applied to the whole row it
// multiplied the light as well, and the bundled scene's floor strip in front of the tall box came
// out 1.8x too bright (its closure was 1.85). Here the wall is black, so no floor leaf may gather
// more than the light's unoccluded point irradiance at its centre.
TEST(HierarchicalRadiosity, ClosureOfADimWallDoesNotScaleTheLight) {
  std::vector<Polygon> polys = {
      quad({0, 0, 0}, {0, 0, 2}, {2, 0, 2}, {2, 0, 0}),     // floor, +y
      quad({0, 1, 0}, {2, 1, 0}, {2, 1, 2}, {0, 1, 2}),     // light, -y
      quad({1, 0, 0}, {1, .5, 0}, {1, .5, 2}, {1, 0, 2})};  // black wall across it, +x
  PatchHierarchy h = hierarchyOf(polys);
  std::vector<SurfaceProperties> surf(polys.size());
  surf[0].reflectance = glm::dvec3(0.5);
  surf[1].emission = glm::dvec3(1.0);
  KeySolution s = solveWithVisibility(h, polys, surf);
  int checked = 0;
  double worst = 0.0;
  for (int i = 0; i < h.size(); ++i) {
    if (h.node(i).id.top != 0 || s.split[size_t(i)] || !(s.exposure[size_t(i)] > 0.0)) continue;
    const Polygon& leaf = s.world[size_t(i)];
    const glm::dvec3 c = leaf.centroid();
    if (c.x < 1.0 || c.x > 1.5) continue;  // the strip in front of the wall
    const double direct = pointToPolygonFormFactor(c, glm::dvec3(0, 1, 0), polys[1]);
    worst = std::max(worst, s.radiosity[size_t(i)].x / (0.5 * direct));
    ++checked;
  }
  ASSERT_GT(checked, 4) << "the strip beside the wall is refined";
  EXPECT_LT(worst, 1.05) << "a floor leaf beside the black wall gathers more than the light";
}

// The box's faces, each tiled n x n (a room of many small top-level patches, as real scenes
// have, where clustering has something to do).
std::vector<Polygon> tiledBoxFaces(glm::dvec3 lo, glm::dvec3 hi, bool inward, int n) {
  std::vector<Polygon> out;
  for (const Polygon& f : boxFaces(lo, hi, inward))
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        auto at = [&](double u, double v) {
          return (1 - u) * (1 - v) * f.v[0] + u * (1 - v) * f.v[1] + u * v * f.v[2] +
                 (1 - u) * v * f.v[3];
        };
        Polygon p;
        p.count = 4;
        p.v = {at(double(i) / n, double(j) / n), at(double(i + 1) / n, double(j) / n),
               at(double(i + 1) / n, double(j + 1) / n), at(double(i) / n, double(j + 1) / n)};
        out.push_back(p);
      }
  return out;
}

// Issue 16, the cluster hierarchy: every top-level patch is in it once, a cluster's members are
// its children's, sub-clusters come after their parent, and no cluster below the root mixes a
// moving node's patches with static ones or with another node's.
TEST(ClusterTree, CoversEveryTopOnceAndNeverMixesStaticAndMoving) {
  std::vector<Polygon> polys = tiledBoxFaces({0, 0, 0}, {4, 3, 5}, true, 5);
  const size_t staticCount = polys.size();
  for (const Polygon& p : tiledBoxFaces({1, 0, 1}, {1.5, 0.5, 1.5}, false, 2)) polys.push_back(p);
  for (const Polygon& p : tiledBoxFaces({2, 1, 3}, {2.4, 1.2, 3.3}, false, 1)) polys.push_back(p);
  std::vector<InputPolygon> tops;
  std::vector<char> moving;
  for (size_t i = 0; i < polys.size(); ++i) {
    InputPolygon ip;
    ip.local = polys[i];
    ip.node = i < staticCount ? 0 : i < staticCount + 24 ? 1 : 2;
    tops.push_back(ip);
    moving.push_back(i >= staticCount);
  }
  PatchHierarchy h(tops);
  ClusterTree tree(h, polys, moving);
  ASSERT_FALSE(tree.empty());
  std::vector<int> seen(polys.size(), 0);
  for (uint32_t t : tree.members()) seen[t]++;
  for (size_t t = 0; t < polys.size(); ++t) EXPECT_EQ(seen[t], 1) << "top " << t;
  EXPECT_EQ(tree.node(tree.root()).count, polys.size());
  for (int c = 0; c < tree.size(); ++c) {
    const ClusterNode& n = tree.node(c);
    ASSERT_GE(n.children.size(), 2u);
    uint32_t count = 0;
    for (ClusterRef r : n.children) {
      if (isCluster(r)) {
        EXPECT_GT(clusterIndex(r), c);
        EXPECT_EQ(tree.node(clusterIndex(r)).parent, c);
        count += tree.node(clusterIndex(r)).count;
      } else {
        EXPECT_EQ(tree.parentOfTop(r), c);
        ++count;
      }
    }
    EXPECT_EQ(count, n.count) << "cluster " << c;
    if (c == tree.root()) continue;
    std::set<int> nodes;
    for (uint32_t i = n.first; i < n.first + n.count; ++i)
      nodes.insert(h.top(int(tree.members()[i])).node);
    EXPECT_EQ(nodes.size(), 1u) << "cluster " << c << " mixes mesh nodes";
  }
}

KeySolution solveTiled(PatchHierarchy& h, const std::vector<Polygon>& polys,
                       const std::vector<SurfaceProperties>& surf, const VisibilityScene& vis,
                       bool clustering, const RadiosityOptions& o = {}) {
  ClusterTree tree(h, polys, std::vector<char>(polys.size(), 0));
  KeySolveInput in = identityInput(h);
  in.visibility = &vis;
  if (clustering) in.clusters = &tree;
  return solveKeyTime(h, surf, in, o);
}

KeySolution solveTiled(const std::vector<Polygon>& polys,
                       const std::vector<SurfaceProperties>& surf, const VisibilityScene& vis,
                       bool clustering, const RadiosityOptions& o = {}) {
  PatchHierarchy h = hierarchyOf(polys);
  return solveTiled(h, polys, surf, vis, clustering, o);
}

// Issue 16, energy: clustering must keep the closed-room balance. In a closed room every watt
// emitted is absorbed, $\sum A e (1 - \rho) H = \sum A E$ (a closed form for any geometry). A
// 2 m room tiled 6 x 6 per wall (216 top-level patches), one ceiling tile emitting, rho = 0.9,
// a slab floating in it: the far pairs of tiles are cluster links, whose share the closed-room
// rows take as it is; absorbed power stays within 1 % of emitted as without clustering.
TEST(ClusterLinks, ClosedRoomAbsorbsWhatItEmits) {
  std::vector<Polygon> polys = tiledBoxFaces({0, 0, 0}, {2, 2, 2}, true, 6);
  for (const Polygon& p : boxFaces({1.45, 0.2, 0.3}, {1.55, 1.8, 1.7}, false)) polys.push_back(p);
  VisibilityScene vis(visibilityTrianglesOf(polys));
  std::vector<SurfaceProperties> surf(polys.size());
  for (auto& s : surf) s.reflectance = glm::dvec3(0.9);
  const size_t light = 3 * 36 + 14;  // a tile of the +y face (the ceiling), off its centre
  ASSERT_LT(glm::dot(polys[light].normal(), glm::dvec3(0, 1, 0)), 0.0) << "faces down";
  surf[light].emission = glm::dvec3(10.0);
  for (bool clustering : {true, false}) {
    PatchHierarchy h = hierarchyOf(polys);
    KeySolution s = solveTiled(h, polys, surf, vis, clustering);
    if (clustering) {
      EXPECT_GT(s.clusterLinks, 100u) << "the far tiles are linked as clusters";
    }
    const double balance = s.absorbedPower(h, surf).x / s.emittedPower(h, surf).x;
    std::cout << (clustering ? "clustering" : "all pairs") << ": " << s.links.size()
              << " patch links, " << s.clusterLinks << " cluster links, absorbed / emitted "
              << balance << "\n";
    EXPECT_NEAR(balance, 1.0, 0.01) << (clustering ? "clustering" : "all pairs");
  }
}

// Issue 16, accuracy and cost in an open room: a 6 x 3 x 5 m room tiled 6 x 6 per wall (216
// top-level patches), one ceiling light, two boxes, one wall open. With clustering the tops'
// radiosity stays within 2 % RMS / mean of the all-pairs answer, with fewer links.
TEST(ClusterLinks, OpenRoomMatchesAllPairsWithFewerLinks) {
  std::vector<Polygon> room = tiledBoxFaces({0, 0, 0}, {6, 3, 5}, true, 6);
  std::vector<Polygon> polys(room.begin(), room.end() - 36);  // +x wall open
  const size_t lightIndex = polys.size();
  polys.push_back(boxFaces({2.5, 2.9, 2.0}, {3.5, 3.0, 3.0}, false)[0]);  // faces down
  for (const Polygon& p : tiledBoxFaces({1, 0, 1}, {2, 1, 2}, false, 2)) polys.push_back(p);
  for (const Polygon& p : tiledBoxFaces({4, 0, 3}, {4.6, 1.6, 3.6}, false, 2)) polys.push_back(p);
  VisibilityScene vis(visibilityTrianglesOf(polys));
  PatchHierarchy h = hierarchyOf(polys);
  std::vector<SurfaceProperties> surf(polys.size());
  for (auto& s : surf) s.reflectance = glm::dvec3(0.7);
  surf[lightIndex].emission = glm::dvec3(10.0);
  surf[lightIndex].reflectance = glm::dvec3(0.0);
  const KeySolution all = solveTiled(polys, surf, vis, false);
  const KeySolution clustered = solveTiled(polys, surf, vis, true);
  double sq = 0, mean = 0, area = 0;
  for (size_t t = 0; t < polys.size(); ++t) {
    if (t == lightIndex) continue;
    const double a = polys[t].area(), d = clustered.radiosity[t].x - all.radiosity[t].x;
    sq += a * d * d, mean += a * all.radiosity[t].x, area += a;
  }
  const double rms = std::sqrt(sq / area) / (mean / area);
  std::cout << "all pairs " << all.links.size() << " links; clustering " << clustered.links.size()
            << " patch links + " << clustered.clusterLinks << " cluster links; RMS / mean " << rms
            << "\n";
  EXPECT_GT(clustered.clusterLinks, 0u);
  EXPECT_LT(clustered.links.size() + clustered.clusterLinks, all.links.size());
  EXPECT_LT(rms, 0.02);
  EXPECT_FALSE(clustered.topClusterIrradiance.empty());
}

// A quad with corners a, b, c, d in order appended to `polys`.
void addQuad(std::vector<Polygon>& polys, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d) {
  Polygon p;
  p.count = 4;
  p.v = {a, b, c, d};
  polys.push_back(p);
}

// A grid of nu x nv quads appended to `polys`: tile (i, j) from a = origin + i du + j dv, its
// corners a, a + du, a + du + dv, a + dv (facing du x dv), or in the other turn when
// `alongDvFirst` (facing dv x du).
void addTileGrid(std::vector<Polygon>& polys, glm::dvec3 origin, glm::dvec3 du, glm::dvec3 dv,
                 int nu, int nv, bool alongDvFirst) {
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const glm::dvec3 a = origin + double(i) * du + double(j) * dv;
      if (alongDvFirst)
        addQuad(polys, a, a + dv, a + du + dv, a + du);
      else
        addQuad(polys, a, a + du, a + du + dv, a + dv);
    }
}

std::vector<double> areasOf(const std::vector<Polygon>& polys) {
  std::vector<double> a;
  for (const Polygon& p : polys) a.push_back(p.area());
  return a;
}

// Refines at eps 1 (the separation decides) until no link changes, then evaluates; the patch
// pairs handed over go to `pairs`.
void refineUntilNoLinkChanges(ClusterLinks& links, std::vector<std::pair<int, int>>& pairs) {
  bool over = false;
  while (links.refine(1.0, false, 1u << 20, pairs, over) > 0) links.evaluate();
  links.evaluate();
}

// The cluster links of static tops `polys`, none of them a light, refined (separation 2, eps
// 1: the separation decides) until no link changes, and evaluated: what the tests of the
// cluster transfer read. Built in place (its members refer to each other).
struct SeparatedClusterLinks {
  SeparatedClusterLinks(const std::vector<Polygon>& polys, const VisibilityScene* visibility,
                        int rays)
      : h(hierarchyOf(polys)),
        tree(h, polys, std::vector<char>(polys.size(), 0)),
        area(areasOf(polys)),
        emission(polys.size(), 0.0),
        links(tree, polys, area, emission, visibility, rays, 2.0, 0.1,
              RadiosityOptions{}.clusterMemberRays, false) {
    std::vector<std::pair<int, int>> pairs;
    refineUntilNoLinkChanges(links, pairs);
  }
  PatchHierarchy h;
  ClusterTree tree;
  std::vector<double> area, emission;
  ClusterLinks links;
};

// A cluster link's form factor at each receiver top against the exact point-to-polygon sum over
// the shooter's tiles: two walls of 4 x 4 tiles, the second 8 m along and perpendicular to the
// first (each sees the other at a grazing angle). One point and one direction for the whole
// shooter, from the receiver's centre, put the worst top 2.93 times off its exact sum; the
// shooter's facing groups, seen from each top, 3.8 %. (Without cluster links the row sums are
// 0 and the test fails too.)
TEST(ClusterLinks, FormFactorsFollowEachReceiverTopAtGrazingAngles) {
  std::vector<Polygon> polys;
  const double s = 0.5;
  addTileGrid(polys, {0, 0, 0}, {0, s, 0}, {0, 0, s}, 4, 4, false);  // x = 0, facing +x
  addTileGrid(polys, {8, 0, 0}, {s, 0, 0}, {0, s, 0}, 4, 4, false);  // z = 0, facing +z
  ASSERT_NEAR(polys[0].normal().x, 1.0, 1e-12);
  ASSERT_NEAR(polys[16].normal().z, 1.0, 1e-12);
  SeparatedClusterLinks separated(polys, nullptr, 4);
  ClusterLinks& links = separated.links;
  const std::vector<double> row = links.rowSums({});
  double worst = 0.0;
  for (size_t t = 0; t < polys.size(); ++t) {
    const size_t first = t < 16 ? 16 : 0;  // the other wall's tiles
    double exact = 0.0;
    for (size_t j = first; j < first + 16; ++j)
      exact += pointToPolygonFormFactor(polys[t].centroid(), polys[t].normal(), polys[j]);
    ASSERT_GT(exact, 0.0);
    worst = std::max(worst, std::abs(row[t] / exact - 1.0));
  }
  std::cout << "worst cluster row sum against the exact sums: " << worst << "\n";
  EXPECT_LT(worst, 0.05);
}

// Links only where energy can pass: a floor and a ceiling of 8 x 8 tiles each, 2 m apart, the
// floor's tiles at two heights (a step of 1 mm: parallel, not coplanar), and a wall of 4 x 4
// tiles facing away from both. No cluster link joins two tops of one plane or reaches the
// wall's back (their transfer is 0: before clusters of parallel tops were tested against each
// other's planes, two halves of the ceiling were linked and refined down to their tiles), while
// each ceiling tile's row sum still matches its exact sum over the floor.
TEST(ClusterLinks, NoLinkJoinsTopsThatCannotSeeEachOther) {
  std::vector<Polygon> polys;
  const double s = 0.5;
  addTileGrid(polys, {0, 0, 0}, {s, 0, 0}, {0, 0, s}, 8, 4, true);     // floor y = 0, facing +y
  addTileGrid(polys, {0, 1e-3, 2}, {s, 0, 0}, {0, 0, s}, 8, 4, true);  // floor y = 1 mm
  addTileGrid(polys, {0, 2, 0}, {s, 0, 0}, {0, 0, s}, 8, 8, false);    // ceiling, facing -y
  addTileGrid(polys, {9, 0, 0}, {0, s, 0}, {0, 0, s}, 4, 4, false);    // wall x = 9, facing +x
  ASSERT_NEAR(polys[0].normal().y, 1.0, 1e-12);
  ASSERT_NEAR(polys[64].normal().y, -1.0, 1e-12);
  ASSERT_NEAR(polys[128].normal().x, 1.0, 1e-12);
  // The tops' plane: 0 and 1 the floor's two heights, 2 the ceiling, 3 the wall.
  auto plane = [](size_t t) { return t < 32 ? 0 : t < 64 ? 1 : t < 128 ? 2 : 3; };
  PatchHierarchy h = hierarchyOf(polys);
  ClusterTree tree(h, polys, std::vector<char>(polys.size(), 0));
  std::vector<double> area = areasOf(polys), emission(polys.size(), 0.0);
  ClusterLinks links(tree, polys, area, emission, nullptr, 4, 4.0, 0.1, 4, false);
  std::vector<std::pair<int, int>> pairs;
  bool over = false;
  // A tiny threshold: every link is refined until the separation holds.
  while (links.refine(1e-12, false, 1u << 20, pairs, over) > 0) links.evaluate();
  links.evaluate();
  // One plane (or -1: several) and the wall's part of each end's tops.
  auto planeOf = [&](ClusterRef r) {
    if (!isCluster(r)) return plane(size_t(r));
    const ClusterNode& n = tree.node(clusterIndex(r));
    const int first = plane(tree.members()[n.first]);
    for (uint32_t i = n.first; i < n.first + n.count; ++i)
      if (plane(tree.members()[i]) != first) return -1;
    return first;
  };
  // (Pairs of tops are the patch links' to drop by their own facing test.)
  for (const ClusterLink& l : links.links()) {
    const int a = planeOf(l.receiver), b = planeOf(l.shooter);
    EXPECT_FALSE(a >= 0 && a == b) << "a link within plane " << a;
    EXPECT_FALSE(a == 3 || b == 3) << "a link to the wall's back";
  }
  EXPECT_GT(links.size(), 16u);
  // Each ceiling tile's row over the floor: its cluster links' part plus its pairs' (exact
  // point-to-polygon form factors, as the patch links start from) against the exact sum.
  std::vector<double> row = links.rowSums({}), fromClusters = row;
  for (const auto& [r, q] : pairs)
    row[size_t(r)] += pointToPolygonFormFactor(polys[size_t(r)].centroid(),
                                               polys[size_t(r)].normal(), polys[size_t(q)]);
  double worst = 0.0, clusterShare = 0.0;
  for (size_t t = 64; t < 128; ++t) {
    double exact = 0.0;
    for (size_t j = 0; j < 64; ++j)
      exact += pointToPolygonFormFactor(polys[t].centroid(), polys[t].normal(), polys[j]);
    worst = std::max(worst, std::abs(row[t] / exact - 1.0));
    clusterShare = std::max(clusterShare, fromClusters[t] / exact);
  }
  std::cout << "worst ceiling row sum against the exact sums: " << worst
            << " (cluster links' share up to " << clusterShare << ")\n";
  EXPECT_GT(clusterShare, 0.05);
  EXPECT_LT(worst, 0.05);
}

// A cluster's B as the receiver sees it: a shooter of two facing groups, a floor of 4 x 4 tiles
// (B = 1, facing up) and a wall of 4 x 4 tiles standing on its edge (B = 0.1, facing +x), seen
// from a 1 m wall of tiles 8 m along +x and above them, which sees the wall face on and the
// floor at a slant. The gathered irradiance at each receiver top against the exact sum over the
// shooter's tiles of B F (point to polygon, no occluder): the groups weighed by their projected
// areas towards the link's direction put the worst top 6.9 % off (the direction is the receiver
// cluster's; across the receiver the floor's projection differs by +-20 %, and the floor carries
// most of the light); six axis bins with squared direction weights, 46 % (the floor's share
// counted at about 0.3^2 of its projection).
TEST(ClusterLinks, ShooterRadiosityWeighsItsFacingGroupsAsTheTransferDoes) {
  std::vector<Polygon> polys;
  const double s = 0.5;
  addTileGrid(polys, {0, 0, 0}, {s, 0, 0}, {0, 0, s}, 4, 4, true);   // floor y = 0, facing +y
  addTileGrid(polys, {2, 0, 0}, {0, s, 0}, {0, 0, s}, 4, 4, false);  // wall x = 2, facing +x
  const double r = 0.25;  // receiver x = 10, facing -x, y in [2.5, 3.5], z in [0.5, 1.5]
  addTileGrid(polys, {10, 2.5, 0.5}, {0, r, 0}, {0, 0, r}, 4, 4, true);
  ASSERT_NEAR(polys[0].normal().y, 1.0, 1e-12);
  ASSERT_NEAR(polys[16].normal().x, 1.0, 1e-12);
  ASSERT_NEAR(polys[32].normal().x, -1.0, 1e-12);
  SeparatedClusterLinks separated(polys, nullptr, 4);
  ClusterLinks& links = separated.links;
  std::vector<glm::dvec3> B(polys.size(), glm::dvec3(0.0)), H;
  for (size_t t = 0; t < 32; ++t) B[t] = glm::dvec3(t < 16 ? 1.0 : 0.1);
  links.gather(B, {}, H);
  double worst = 0.0;
  for (size_t t = 32; t < polys.size(); ++t) {
    double exact = 0.0;
    for (size_t j = 0; j < 32; ++j)
      exact += B[j].x * pointToPolygonFormFactor(polys[t].centroid(), polys[t].normal(), polys[j]);
    ASSERT_GT(exact, 0.0);
    worst = std::max(worst, std::abs(H[t].x / exact - 1.0));
  }
  std::cout << "worst gathered irradiance against the exact sums: " << worst << "\n";
  EXPECT_LT(worst, 0.08);
}

// A cluster link's V from 16 ray pairs against the kernel-weighted share of 4096 pairs: two
// boxes of 2 x 2 tiles a face (24 tops each), 6 m apart, and a wall between them that hides the
// lower half of each from the other. Drawn by area over a whole box, most pairs hold a face
// turned away (kernel 0: at most one face of each sees the other) and the few left estimate V:
// the links between the boxes' clusters came out 0.42 off on average; with each end's member
// drawn among those that may face the other end, 0.085.
TEST(ClusterLinks, VisibilityIsEstimatedFromPairsThatFaceEachOther) {
  std::vector<Polygon> polys = tiledBoxFaces({0, 0, 0}, {1, 1, 1}, false, 2);
  for (const Polygon& p : tiledBoxFaces({7, 0, 0}, {8, 1, 1}, false, 2)) polys.push_back(p);
  const size_t boxTops = 24;
  {  // the wall: x = 4, y up to 0.5, facing -x
    Polygon w;
    w.count = 4;
    w.v = {glm::dvec3(4, -1, -1), glm::dvec3(4, -1, 2), glm::dvec3(4, 0.5, 2),
           glm::dvec3(4, 0.5, -1)};
    polys.push_back(w);
  }
  VisibilityScene vis(visibilityTrianglesOf(polys));
  SeparatedClusterLinks separated(polys, &vis, 16);
  const ClusterLinks& links = separated.links;
  const ClusterTree& tree = separated.tree;
  auto membersOf = [&](ClusterRef r) {
    std::vector<uint32_t> m;
    if (!isCluster(r)) return std::vector<uint32_t>{uint32_t(r)};
    const ClusterNode& n = tree.node(clusterIndex(r));
    for (uint32_t i = n.first; i < n.first + n.count; ++i) m.push_back(tree.members()[i]);
    return m;
  };
  auto box = [&](const std::vector<uint32_t>& m) {  // 0, 1, or -1 when mixed or the wall
    int b = -2;
    for (uint32_t t : m) {
      const int bt = t < boxTops ? 0 : t < 2 * boxTops ? 1 : -1;
      b = b == -2 || b == bt ? bt : -1;
    }
    return b;
  };
  double error = 0.0;
  int count = 0;
  for (const ClusterLink& l : links.links()) {
    const std::vector<uint32_t> r = membersOf(l.receiver), sh = membersOf(l.shooter);
    const int br = box(r), bs = box(sh);
    if (!isCluster(l.receiver) || !isCluster(l.shooter) || br < 0 || bs < 0 || br == bs) continue;
    double sumK = 0.0, openK = 0.0;
    for (int i = 0; i < 4096; ++i) {
      const uint32_t a = r[size_t(i) % r.size()], b = sh[size_t(i / 64) % sh.size()];
      const glm::dvec3 x = pointOnPolygon(polys[a], uniformOpen01(7, 4 * uint64_t(i)),
                                          uniformOpen01(7, 4 * uint64_t(i) + 1));
      const glm::dvec3 y = pointOnPolygon(polys[b], uniformOpen01(7, 4 * uint64_t(i) + 2),
                                          uniformOpen01(7, 4 * uint64_t(i) + 3));
      const glm::dvec3 xy = y - x;
      const double len2 = glm::dot(xy, xy);
      const double k = std::max(0.0, glm::dot(polys[a].normal(), xy)) *
                       std::max(0.0, -glm::dot(polys[b].normal(), xy)) / (len2 * len2) *
                       polys[a].area() * polys[b].area();
      if (!(k > 0.0)) continue;
      sumK += k;
      if (!vis.occluded(x, y, a, b)) openK += k;
    }
    if (!(sumK > 0.0)) continue;  // the ends do not face each other: no V to estimate
    error += std::abs(double(l.visibility) - openK / sumK);
    ++count;
  }
  ASSERT_GT(count, 0) << "no cluster link between the boxes";
  std::cout << count << " links between the boxes' clusters, mean |V - V_ref| " << error / count
            << "\n";
  EXPECT_LT(error / count, 0.1);
}

// A receiver cluster of two facing groups that see a shooter differently: a floor of 2 x 2
// tiles (facing +y) behind a panel of 2 x 2 tiles (facing +x, 0.2 m in front of it), and a wall
// of 2 x 8 tiles 6.8 m along +x (facing -x, B = 1) that the panel sees whole and the floor not
// at all (the panel's back hides it). Against the exact sums over the wall's tiles (point to
// polygon, nothing between): one V per cluster link, kernel-weighted over both groups' pairs,
// put the panel's worst tile 48 % off and gave the floor 0.43 of its unoccluded sum; V per
// facing group of the receiver, 5.2 % and 0.03.
TEST(ClusterLinks, VisibilityIsTakenPerFacingGroupOfTheReceiver) {
  std::vector<Polygon> polys;
  const double s = 0.5;
  addTileGrid(polys, {0, 0, 0}, {s, 0, 0}, {0, 0, s}, 2, 2, true);     // floor y = 0, facing +y
  addTileGrid(polys, {1.2, 0, 0}, {0, s, 0}, {0, 0, s}, 2, 2, false);  // panel x = 1.2, +x
  addTileGrid(polys, {8, 0, 0}, {0, s, 0}, {0, 0, s}, 8, 2, true);     // wall x = 8, facing -x
  ASSERT_NEAR(polys[0].normal().y, 1.0, 1e-12);
  ASSERT_NEAR(polys[4].normal().x, 1.0, 1e-12);
  ASSERT_NEAR(polys[8].normal().x, -1.0, 1e-12);
  VisibilityScene vis(visibilityTrianglesOf(polys));
  SeparatedClusterLinks separated(polys, &vis, 16);
  ClusterLinks& links = separated.links;
  int clusterToCluster = 0;
  for (const ClusterLink& l : links.links())
    clusterToCluster += isCluster(l.receiver) && isCluster(l.shooter) ? 1 : 0;
  ASSERT_GT(clusterToCluster, 0) << "no link between the clusters";
  std::vector<glm::dvec3> B(polys.size(), glm::dvec3(0.0)), H;
  for (size_t t = 8; t < polys.size(); ++t) B[t] = glm::dvec3(1.0);
  links.gather(B, {}, H);
  auto unoccluded = [&](size_t t) {
    double sum = 0.0;
    for (size_t j = 8; j < polys.size(); ++j)
      sum += pointToPolygonFormFactor(polys[t].centroid(), polys[t].normal(), polys[j]);
    return sum;
  };
  double panelWorst = 0.0, floorWorst = 0.0;
  for (size_t t = 0; t < 8; ++t) {
    const double exact = unoccluded(t);
    ASSERT_GT(exact, 0.0);
    if (t < 4)
      floorWorst = std::max(floorWorst, H[t].x / exact);
    else
      panelWorst = std::max(panelWorst, std::abs(H[t].x / exact - 1.0));
  }
  std::cout << "panel: worst |H / exact - 1| " << panelWorst
            << "; floor: largest H / unoccluded sum " << floorWorst << "\n";
  EXPECT_LT(panelWorst, 0.08);
  EXPECT_LT(floorWorst, 0.1);
}

// A receiver cluster of one facing group whose tops see a shooter differently: a wall of 8 x 2
// tiles (x = 0, facing +x, 4 m high) whose lower half a panel 0.6 m in front of it hides from a
// lit wall 8 m away (B = 1). One V per facing group (member rays 0) spreads the light of the
// open upper tiles over the hidden lower ones: every tile is off its exact F V (point-to-polygon
// sums over the lit tiles, V from 256 ray pairs each) by 0.47 of its unoccluded sum on average.
// Each member's own V from 4 ray pairs (the default) brings that to 0.02.
TEST(ClusterLinks, EachMemberOfAReceiverClusterTakesItsOwnVisibility) {
  std::vector<Polygon> polys;
  const double s = 0.5;
  addTileGrid(polys, {0, 0, 0}, {0, s, 0}, {0, 0, s}, 8, 2, false);     // the wall, facing +x
  addTileGrid(polys, {0.6, 0, -1}, {0, 2, 0}, {0, 0, 3}, 1, 1, false);  // the panel
  addTileGrid(polys, {8, 0, 0}, {0, s, 0}, {0, 0, s}, 8, 2, true);      // lit, facing -x
  const size_t wall = 16, lit = 17;
  ASSERT_NEAR(polys[0].normal().x, 1.0, 1e-12);
  ASSERT_NEAR(polys[wall].normal().x, 1.0, 1e-12);
  ASSERT_NEAR(polys[lit].normal().x, -1.0, 1e-12);
  VisibilityScene vis(visibilityTrianglesOf(polys));
  PatchHierarchy h = hierarchyOf(polys);
  ClusterTree tree(h, polys, std::vector<char>(polys.size(), 0));
  std::vector<double> area, emission(polys.size(), 0.0);
  for (const Polygon& p : polys) area.push_back(p.area());
  std::vector<glm::dvec3> B(polys.size(), glm::dvec3(0.0));
  for (size_t t = lit; t < polys.size(); ++t) B[t] = glm::dvec3(1.0);
  // Each wall tile's exact F V and unoccluded F from the lit tiles.
  std::vector<double> exactFV(wall, 0.0), exactF(wall, 0.0);
  for (size_t t = 0; t < wall; ++t)
    for (size_t j = lit; j < polys.size(); ++j) {
      const double f = pointToPolygonFormFactor(polys[t].centroid(), polys[t].normal(), polys[j]);
      int open = 0;
      for (int i = 0; i < 256; ++i) {
        const uint64_t c = (t * 64 + j) * 1024 + uint64_t(i) * 4;
        const glm::dvec3 x = pointOnPolygon(polys[t], uniformOpen01(3, c), uniformOpen01(3, c + 1));
        const glm::dvec3 y =
            pointOnPolygon(polys[j], uniformOpen01(3, c + 2), uniformOpen01(3, c + 3));
        open += vis.occluded(x, y, uint32_t(t), uint32_t(j)) ? 0 : 1;
      }
      exactF[t] += f;
      exactFV[t] += f * open / 256.0;
    }
  auto meanError = [&](int memberRays) {
    ClusterLinks links(tree, polys, area, emission, &vis, 16, 2.0, 0.1, memberRays, false);
    std::vector<std::pair<int, int>> pairs;
    bool over = false;
    int clusterReceivers = 0;
    while (links.refine(1.0, false, 1u << 20, pairs, over) > 0) links.evaluate();
    links.evaluate();
    for (const ClusterLink& l : links.links()) clusterReceivers += isCluster(l.receiver) ? 1 : 0;
    EXPECT_GT(clusterReceivers, 0) << "no link gathered at a cluster";
    std::vector<glm::dvec3> H;
    links.gather(B, {}, H);
    double error = 0.0;
    for (size_t t = 0; t < wall; ++t) error += std::abs(H[t].x - exactFV[t]) / exactF[t];
    return error / double(wall);
  };
  const double byGroup = meanError(0), byMember = meanError(RadiosityOptions{}.clusterMemberRays);
  std::cout << "mean |H - exact F V| / unoccluded F: one V per facing group " << byGroup
            << ", each member's own " << byMember << "\n";
  EXPECT_GT(byGroup, 0.2);  // what the test tells apart
  EXPECT_LT(byMember, 0.1);
}

// A small tile (the last polygon) gathering every other polygon (B = 1) through the cluster
// links, refined to the end at eps 1, and the exact point-to-polygon form factor from them all.
struct TileGatheringAShooter {
  std::vector<Polygon> polys;
  size_t tile;
  PatchHierarchy h;
  ClusterTree tree;
  std::vector<double> area, emission;
  std::vector<glm::dvec3> B;
  double exact = 0.0;
  ClusterLinks links;
  std::vector<std::pair<int, int>> pairs;  // the patch pairs the refinement handed over
  TileGatheringAShooter(const std::vector<Polygon>& all, bool isotropic)
      : polys(all),
        tile(all.size() - 1),
        h(hierarchyOf(polys)),
        tree(h, polys, std::vector<char>(polys.size(), 0)),
        area(areasOf(polys)),
        emission(polys.size(), 0.0),
        B(polys.size(), glm::dvec3(1.0)),
        links(tree, polys, area, emission, nullptr, 4, 4.0, 0.1, 0, isotropic) {
    B[tile] = glm::dvec3(0.0);
    for (size_t j = 0; j < tile; ++j)
      exact += pointToPolygonFormFactor(polys[tile].centroid(), polys[tile].normal(), polys[j]);
    refineUntilNoLinkChanges(links, pairs);
  }
};

// A sphere about the origin of 512 triangles facing out: the octahedron's faces split 3 times.
std::vector<Polygon> tessellatedSphere(double radius) {
  std::vector<Polygon> sphere;
  std::function<void(glm::dvec3, glm::dvec3, glm::dvec3, int)> facet =
      [&](glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, int level) {
        if (level == 0) {
          Polygon p;
          p.count = 3;
          p.v = {radius * a, radius * b, radius * c, glm::dvec3(0.0)};
          if (glm::dot(p.normal(), p.centroid()) < 0.0) std::swap(p.v[1], p.v[2]);
          sphere.push_back(p);
          return;
        }
        const glm::dvec3 ab = glm::normalize(a + b), bc = glm::normalize(b + c),
                         ca = glm::normalize(c + a);
        facet(a, ab, ca, level - 1);
        facet(ab, b, bc, level - 1);
        facet(ca, bc, c, level - 1);
        facet(ab, bc, ca, level - 1);
      };
  for (int sx : {-1, 1})
    for (int sy : {-1, 1})
      for (int sz : {-1, 1}) facet({double(sx), 0, 0}, {0, double(sy), 0}, {0, 0, double(sz)}, 3);
  return sphere;
}

// Isotropic clusters (--isotropic-clusters): a cluster shows A / 4 in every direction. A sphere
// does (Cauchy: its projected area is pi r^2 = A / 4); a flat panel seen face-on shows all of
// A. Seen by a small tile 10 m away, the tile's irradiance through its cluster link against the
// exact point-to-polygon sum over the shooter's tops: a sphere of 512 triangles (radius 0.5)
// within 2 % either way; a panel of 8 x 8 tiles (1 m^2) face-on within 4 % oriented (the point
// approximation at 10 times its radius), isotropic a quarter of that.
TEST(ClusterLinks, IsotropicClustersShowAQuarterOfTheirAreaInEveryDirection) {
  const double radius = 0.5;
  const std::vector<Polygon> sphere = tessellatedSphere(radius);
  ASSERT_EQ(sphere.size(), 512u);
  std::vector<Polygon> panel;  // x = 0, facing +x
  addTileGrid(panel, {0, -0.5, -0.5}, {0, 0.125, 0}, {0, 0, 0.125}, 8, 8, false);
  ASSERT_NEAR(panel[0].normal().x, 1.0, 1e-12);
  // The tile's irradiance from `shooter` (B = 1) through the cluster links, over the exact sum.
  auto ratio = [&](std::vector<Polygon> polys, bool isotropic) {
    const size_t tile = polys.size();
    addQuad(polys, {10, -0.05, -0.05}, {10, -0.05, 0.05}, {10, 0.05, 0.05}, {10, 0.05, -0.05});
    EXPECT_NEAR(polys[tile].normal().x, -1.0, 1e-12);
    TileGatheringAShooter g(polys, isotropic);
    ClusterLinks& links = g.links;
    const double exact = g.exact;
    std::vector<glm::dvec3>& B = g.B;
    bool linked = false;
    for (const ClusterLink& l : links.links())
      linked = linked || (l.receiver == ClusterRef(tile) && isCluster(l.shooter));
    EXPECT_TRUE(linked) << "the tile gathers the shooter through no cluster link";
    std::vector<glm::dvec3> H;
    links.gather(B, {}, H);
    return H[tile].x / exact;
  };
  const double sphereIsotropic = ratio(sphere, true), sphereOriented = ratio(sphere, false);
  const double panelIsotropic = ratio(panel, true), panelOriented = ratio(panel, false);
  std::cout << "over the exact sum: sphere isotropic " << sphereIsotropic << ", oriented "
            << sphereOriented << "; panel face-on isotropic " << panelIsotropic << ", oriented "
            << panelOriented << "\n";
  EXPECT_NEAR(sphereIsotropic, 1.0, 0.02);
  EXPECT_NEAR(sphereOriented, 1.0, 0.02);
  EXPECT_NEAR(panelOriented, 1.0, 0.04);
  EXPECT_NEAR(panelIsotropic / panelOriented, 0.25, 1e-3);  // A / 4 against all of A
}

// A shooter cluster shows a receiver its projected area, the sum over its members of A_j max(0,
// -n_j . d). The signed normal sum of members grouped by their normal's dominant axis alone
// cancels where some of a group's members face the receiver and others face away: small boxes
// turned 0, 35 and -35 degrees about z, seen from +y (their faces 35 degrees either side of +x
// cancel along y), and a tessellated sphere seen from a direction off its axes. A small tile 20 m
// away gathers them (B = 1) through its cluster links; against the exact point-to-polygon sum
// over the shooter's tops, within 2 % (issue 58: graz's turned chairs and curved parts; the
// figures before and after the facing cells: docs/results.md, "Cluster shooters' projected area").
TEST(ClusterLinks, TurnedAndCurvedShootersShowTheirWholeProjectedArea) {
  std::vector<Polygon> boxes;
  for (int i = 0; i < 25; ++i)  // a 5 x 5 grid of small boxes turned 0, 35, -35 degrees in turn
    for (Polygon p : boxFaces({-0.05, -0.05, -0.05}, {0.05, 0.05, 0.05}, false)) {
      const double a = glm::radians(35.0 * double(i % 3 == 2 ? -1 : i % 3));
      const double c = std::cos(a), s = std::sin(a);
      const glm::dvec3 at(0.2 * double(i % 5 - 2), 0.2 * double(i / 5 - 2), 0.0);
      for (int k = 0; k < p.count; ++k) {
        const glm::dvec3 v = p.v[size_t(k)];
        p.v[size_t(k)] = at + glm::dvec3(c * v.x - s * v.y, s * v.x + c * v.y, v.z);
      }
      boxes.push_back(p);
    }
  const std::vector<Polygon> sphere = tessellatedSphere(0.5);
  // The irradiance of a 0.1 m tile at `at`, facing the origin, from `shooter` (B = 1) through
  // the cluster links, over the exact sum.
  auto ratio = [&](std::vector<Polygon> polys, glm::dvec3 at) {
    const size_t tile = polys.size();
    const glm::dvec3 w = -glm::normalize(at);
    const glm::dvec3 u = 0.05 * glm::normalize(glm::cross(w, glm::dvec3(0.3, 0.2, 1.0)));
    const glm::dvec3 v = glm::cross(w, u);
    addQuad(polys, at - u - v, at + u - v, at + u + v, at - u + v);
    if (glm::dot(polys[tile].normal(), w) < 0.0) std::swap(polys[tile].v[1], polys[tile].v[3]);
    EXPECT_NEAR(glm::dot(polys[tile].normal(), w), 1.0, 1e-9);
    TileGatheringAShooter g(polys, false);
    ClusterLinks& links = g.links;
    const double exact = g.exact;
    std::vector<glm::dvec3>& B = g.B;
    const std::vector<std::pair<int, int>>& pairs = g.pairs;
    std::vector<glm::dvec3> H;
    links.gather(B, {}, H);
    // Pairs of top-level patches go to the patch links: their exact share is added, so that the
    // ratio is the cluster links' alone.
    double patchShare = 0.0;
    for (const auto& [r, q] : pairs)
      if (size_t(r) == tile)
        patchShare += pointToPolygonFormFactor(polys[tile].centroid(), polys[tile].normal(),
                                               polys[size_t(q)]);
    EXPECT_LT(patchShare, 0.5 * exact) << "the cluster links carry most of the light";
    return (H[tile].x + patchShare) / exact;
  };
  const double boxesFromY = ratio(boxes, {0.0, 20.0, 0.0});
  const double sphereOffAxis = ratio(sphere, 20.0 * glm::normalize(glm::dvec3(1.0, 0.55, 0.3)));
  const double sphereOnAxis = ratio(sphere, {20.0, 0.0, 0.0});
  std::cout << "over the exact sum: turned boxes seen from +y " << boxesFromY
            << ", sphere off its axes " << sphereOffAxis << ", on its x axis " << sphereOnAxis
            << "\n";
  EXPECT_NEAR(boxesFromY, 1.0, 0.02);
  EXPECT_NEAR(sphereOffAxis, 1.0, 0.02);
  EXPECT_NEAR(sphereOnAxis, 1.0, 0.02);
}

// The gather lists after a refinement round take over the entries of the tops whose links did
// not change (the links renumbered) and make the others anew: the row sums and the gathered
// irradiance must be the very values of lists made anew for the same links. Rounds at three
// thresholds in a room of 384 tiles, once with the lists made between the rounds (taken over)
// and once without (made anew at the end).
TEST(ClusterLinks, ListsTakenOverAfterARoundAreThoseMadeAnew) {
  const std::vector<Polygon> polys = tiledBoxFaces({0, 0, 0}, {12, 3, 4}, true, 8);
  PatchHierarchy h = hierarchyOf(polys);
  ClusterTree tree(h, polys, std::vector<char>(polys.size(), 0));
  std::vector<double> area, emission(polys.size(), 0.0);
  for (const Polygon& p : polys) area.push_back(p.area());
  emission[0] = 1.0;
  std::vector<glm::dvec3> B(polys.size());
  for (size_t t = 0; t < polys.size(); ++t) B[t] = glm::dvec3(0.1 + 0.01 * double(t % 7), 0.2, 0.3);
  auto run = [&](bool listsBetweenRounds, size_t& refined) {
    ClusterLinks links(tree, polys, area, emission, nullptr, 4, 2.0, 0.1, 4, false);
    std::vector<std::pair<int, int>> pairs;
    bool over = false;
    std::vector<double> rows;
    std::vector<glm::dvec3> H;
    refined = 0;
    for (const double eps : {1e-2, 1e-3, 1e-4}) {
      refined += links.refine(eps, false, 1u << 20, pairs, over);
      links.evaluate();
      if (listsBetweenRounds) links.rowSums({});  // makes the lists; the B bounds stay
    }
    rows = links.rowSums({});
    links.gather(B, {}, H);
    for (size_t t = 0; t < H.size(); ++t) rows.push_back(H[t].x + H[t].y + H[t].z);
    return rows;
  };
  size_t refinedA = 0, refinedB = 0;
  const std::vector<double> takenOver = run(true, refinedA), anew = run(false, refinedB);
  EXPECT_GT(refinedA, 0u);
  EXPECT_EQ(refinedA, refinedB);
  ASSERT_EQ(takenOver.size(), anew.size());
  for (size_t i = 0; i < anew.size(); ++i) ASSERT_EQ(takenOver[i], anew[i]) << i;
}

// Surfaces of reflectance 0.7, but `light`, which emits 50 and reflects nothing.
std::vector<SurfaceProperties> greyWithOneLight(size_t count, size_t light) {
  std::vector<SurfaceProperties> surf(count);
  for (auto& s : surf) s.reflectance = glm::dvec3(0.7);
  surf[light].emission = glm::dvec3(50.0);
  surf[light].reflectance = glm::dvec3(0.0);
  return surf;
}

// The point approximation of a cluster link holds only for well separated ends. An open room
// 12 m long, a light at one end, two tables at the other: the floor tiles there take the far
// walls' light through cluster links. Against all pairs, the floor beside the tables came out
// 1.6 % dark with links kept from 3 times the radii's sum apart and 0.7 % from 4 times, when
// each link took one point and one direction for its whole shooter (first order wrong at
// grazing angles); with the shooter's facing groups, each seen from each receiver top, 0.6 %
// and 0.4 %.
//
// Issue 58: with the weak near links kept (RadiosityOptions::keepWeakNearLinks, the default
// since) the test failed while the first round judged them by the lights' B alone
// (KeptWeakNearLinksLetTheRefinementSettle; docs/results.md, "Weak near links kept by default").
struct ExposedFloorRoom {
  std::vector<Polygon> polys;
  size_t light = 0, firstTable = 0;
  ExposedFloorRoom() {
    std::vector<Polygon> room = tiledBoxFaces({0, 0, 0}, {12, 3, 4}, true, 8);
    polys.assign(room.begin(), room.end() - 64);  // +x wall open
    light = polys.size();
    polys.push_back(boxFaces({10.5, 2.9, 1.5}, {11.5, 3.0, 2.5}, false)[0]);  // faces down
    firstTable = polys.size();
    for (double x : {0.4, 2.2})
      for (const Polygon& p : tiledBoxFaces({x, 0.7, 0.5}, {x + 1.2, 0.75, 3.0}, false, 2))
        polys.push_back(p);
  }
};

TEST(ClusterLinks, ExposedFloorMatchesAllPairsAtTheDefaultSeparation) {
  const ExposedFloorRoom room;
  const std::vector<Polygon>& polys = room.polys;
  const size_t light = room.light, firstTable = room.firstTable;
  VisibilityScene vis(visibilityTrianglesOf(polys));
  const std::vector<SurfaceProperties> surf = greyWithOneLight(polys.size(), light);
  const KeySolution all = solveTiled(polys, surf, vis, false);
  // Floor tiles at the tables' end that no table covers.
  auto exposedBias = [&](const KeySolution& s) {
    double d = 0.0, ref = 0.0;
    for (size_t t = 0; t < firstTable; ++t) {
      const glm::dvec3 c = polys[t].centroid();
      const bool floor = polys[t].normal().y > 0.9 && c.y < 1e-9;
      const bool covered =
          c.z > 0.5 && c.z < 3.0 && ((c.x > 0.4 && c.x < 1.6) || (c.x > 2.2 && c.x < 3.4));
      if (!floor || covered || c.x > 4.0) continue;
      d += polys[t].area() * (s.radiosity[t].x - all.radiosity[t].x);
      ref += polys[t].area() * all.radiosity[t].x;
    }
    return d / ref;
  };
  auto clustered = [&](double separation) {
    RadiosityOptions o;
    if (separation > 0.0) o.clusterSeparation = separation;
    return solveTiled(polys, surf, vis, true, o);
  };
  const KeySolution near = clustered(3.0), byDefault = clustered(0.0);
  std::cout << "exposed floor tiles against all pairs: separation 3: " << exposedBias(near) << " ("
            << near.clusterLinks << " cluster links), default: " << exposedBias(byDefault) << " ("
            << byDefault.clusterLinks << ")\n";
  EXPECT_GT(byDefault.clusterLinks, 1000u);
  EXPECT_LT(std::abs(exposedBias(near)), 0.01);
  EXPECT_LT(std::abs(exposedBias(byDefault)), 0.005);
}

// Issue 58: a key's first round knows only the lights' B. Judged by it, every near cluster link
// without a light is weak and kept; each solve then makes the shooters the light reached
// bright, the next round refines their links, and the refinement follows the light one bounce
// a round: in the exposed-floor room it was still refining at the last round
// (RadiosityOptions::maxRefineRounds), where the rule off settles in a few, and the floor came
// out darker than ExposedFloorMatchesAllPairsAtTheDefaultSeparation's bound. Judged by a share
// of the ambient B (ClusterLinks::estimateRadiosity, RadiosityOptions::weakNearAmbientShare),
// the first round keeps few of the near links that the light makes strong.
TEST(ClusterLinks, KeptWeakNearLinksLetTheRefinementSettle) {
  const ExposedFloorRoom room;
  VisibilityScene vis(visibilityTrianglesOf(room.polys));
  const std::vector<SurfaceProperties> surf = greyWithOneLight(room.polys.size(), room.light);
  RadiosityOptions weak, refined;
  refined.keepWeakNearLinks = false;
  ASSERT_TRUE(weak.keepWeakNearLinks) << "the default";
  const KeySolution w = solveTiled(room.polys, surf, vis, true, weak);
  const KeySolution r = solveTiled(room.polys, surf, vis, true, refined);
  std::cout << "rounds kept " << w.refineRounds << " refined " << r.refineRounds
            << "; cluster links " << w.clusterLinks << " / " << r.clusterLinks << "\n";
  EXPECT_LT(w.refineRounds, weak.maxRefineRounds);
  EXPECT_LE(w.refineRounds, r.refineRounds + 1);
  EXPECT_GT(w.clusterLinks, r.clusterLinks) << "weak near links kept";
}

// A ceiling tile mostly behind a light (2 mm below the ceiling, facing down: the 10k-triangle
// hall's lights) has a small exposure. The irradiance of its own links is divided by it (their
// V came from points all over the tile, the covered ones included), that of its ancestor
// clusters' links is not (their V came from points all over the cluster). Dividing both had
// made the hall's tiles behind its lights gather up to 6 times their neighbours' cluster light.
// Against all pairs, in a 12 x 3 x 4 m room tiled 8 x 8 per wall with a light over 90 % of one
// ceiling tile, the tile's B stays within 5 % (-10.6 % before: the closure, taking the inflated
// cluster row as it is, had scaled the tile's other links down).
TEST(ClusterLinks, ATileMostlyBehindALightGathersTheClusterLightOfItsExposedPart) {
  std::vector<Polygon> polys = tiledBoxFaces({0, 0, 0}, {12, 3, 4}, true, 8);
  size_t tile = polys.size();
  for (size_t t = 0; t < polys.size(); ++t) {
    const glm::dvec3 c = polys[t].centroid();
    if (polys[t].normal().y < -0.9 && std::abs(c.x - 0.75) < 0.01 && std::abs(c.z - 1.75) < 0.01)
      tile = t;
  }
  ASSERT_LT(tile, polys.size());
  const size_t light = polys.size();
  Polygon l;
  l.count = 4;
  l.v = {glm::dvec3(0.0, 2.998, 1.5), glm::dvec3(1.35, 2.998, 1.5), glm::dvec3(1.35, 2.998, 2.0),
         glm::dvec3(0.0, 2.998, 2.0)};
  ASSERT_LT(l.normal().y, -0.9) << "faces down";
  polys.push_back(l);
  VisibilityScene vis(visibilityTrianglesOf(polys));
  const std::vector<SurfaceProperties> surf = greyWithOneLight(polys.size(), light);
  const KeySolution all = solveTiled(polys, surf, vis, false);
  const KeySolution clustered = solveTiled(polys, surf, vis, true);
  ASSERT_GT(clustered.clusterLinks, 100u);
  const double bias = clustered.radiosity[tile].x / all.radiosity[tile].x - 1.0;
  std::cout << "tile behind the light: B " << clustered.radiosity[tile].x << " clustered, "
            << all.radiosity[tile].x << " all pairs (" << bias << ")\n";
  EXPECT_LT(std::abs(bias), 0.05);
}

// A hall 24 x 3 x 8 m tiled 6 x 6 per wall, two rows of twelve 0.5 m lights facing down 5 cm
// below its ceiling, 24 boxes of 0.4 m on its floor.
struct LongHall {
  std::vector<Polygon> polys;
  std::vector<SurfaceProperties> surf;
  size_t firstLight = 0, lightEnd = 0;
};
LongHall longHall() {
  LongHall r;
  r.polys = tiledBoxFaces({0, 0, 0}, {24, 3, 8}, true, 6);
  r.firstLight = r.polys.size();
  for (double z : {2.5, 5.5})
    for (double x = 1.0; x < 24.0; x += 2.0) {
      Polygon p;
      p.count = 4;
      p.v = {glm::dvec3(x - 0.25, 2.95, z - 0.25), glm::dvec3(x + 0.25, 2.95, z - 0.25),
             glm::dvec3(x + 0.25, 2.95, z + 0.25), glm::dvec3(x - 0.25, 2.95, z + 0.25)};
      r.polys.push_back(p);
    }
  r.lightEnd = r.polys.size();
  for (double x = 1.5; x < 24.0; x += 3.0)  // small boxes on the floor: the far lights' receivers
    for (double z : {1.5, 4.0, 6.5})
      for (const Polygon& p : boxFaces({x - 0.2, 0.0, z - 0.2}, {x + 0.2, 0.4, z + 0.2}, false))
        r.polys.push_back(p);
  r.surf.resize(r.polys.size());
  for (auto& s : r.surf) s.reflectance = glm::dvec3(0.7);
  for (size_t l = r.firstLight; l < r.lightEnd; ++l) {
    r.surf[l].emission = glm::dvec3(100.0);
    r.surf[l].reflectance = glm::dvec3(0.0);
  }
  return r;
}

// Area-weighted bias of `s`'s radiosity over the hall's tops that do not emit, against `ref`'s.
double surfaceBias(const LongHall& hall, const KeySolution& s, const KeySolution& ref) {
  double d = 0.0, mean = 0.0;
  for (size_t t = 0; t < hall.polys.size(); ++t) {
    if (t >= hall.firstLight && t < hall.lightEnd) continue;
    d += hall.polys[t].area() * (s.radiosity[t].x - ref.radiosity[t].x);
    mean += hall.polys[t].area() * ref.radiosity[t].x;
  }
  return d / mean;
}

// The pairs (receiver top, light) that patch links join.
size_t topsLinkedToLights(const PatchHierarchy& h, const KeySolution& s, const LongHall& hall) {
  std::set<std::pair<uint32_t, uint32_t>> pairs;
  for (const SolverLink& l : s.links) {
    const uint32_t q = h.node(l.shooter).id.top;
    if (q >= hall.firstLight && q < hall.lightEnd) pairs.emplace(h.node(l.receiver).id.top, q);
  }
  return pairs.size();
}

// --light-cluster-share: a light's links that carry little stay cluster links, so the lights'
// links no longer grow as the tops times the lights (the 100k-triangle hall had 19.8 M). In a
// 24 m hall with 24 lights the tops that patch links join to a light drop by 2 % at the
// default share (the share of the power a link may carry falls with the lights' number: the
// 10k-triangle hall's bad pairs drop by half) and by 31 % at share 1, and the radiosity stays
// within 0.1 % and 0.2 % of the all-pairs answer.
TEST(ClusterLinks, FarLightsThroughClusterLinksMatchAllPairs) {
  const LongHall hall = longHall();
  ASSERT_LT(hall.polys[hall.firstLight].normal().y, -0.99) << "lights face down";
  VisibilityScene vis(visibilityTrianglesOf(hall.polys));
  const KeySolution all = solveTiled(hall.polys, hall.surf, vis, false);
  auto clustered = [&](double share, size_t& lightLinks) {
    PatchHierarchy h = hierarchyOf(hall.polys);
    RadiosityOptions o;
    o.lightClusterShare = share;
    KeySolution s = solveTiled(h, hall.polys, hall.surf, vis, true, o);
    lightLinks = topsLinkedToLights(h, s, hall);
    return s;
  };
  size_t everyLink = 0, byDefault = 0, atOne = 0;
  const KeySolution refined = clustered(0.0, everyLink);
  const KeySolution s = clustered(RadiosityOptions().lightClusterShare, byDefault);
  const KeySolution one = clustered(1.0, atOne);
  const double biasRefined = surfaceBias(hall, refined, all);
  const double bias = surfaceBias(hall, s, all), biasOne = surfaceBias(hall, one, all);
  std::cout << "tops linked to a light by patch links: share 0 " << everyLink << ", default "
            << byDefault << ", 1 " << atOne << "; bias against all pairs: share 0 " << biasRefined
            << ", default " << bias << ", 1 " << biasOne << "\n";
  EXPECT_LT(byDefault, everyLink);
  EXPECT_LT(double(atOne), 0.75 * double(everyLink));
  EXPECT_LT(std::abs(biasRefined), 0.001);
  EXPECT_LT(std::abs(bias), 0.001);
  EXPECT_LT(std::abs(biasOne), 0.002);
}

// A light reached through a cluster link is seen through the visibility of its cluster's
// points, which are taken by emitted power. Taken by area, they had been mostly on the ceiling
// around the light (the 10k-triangle hall's light through cluster links came out 2.4 % dark
// at share 1). Here a floor patch 20 m below a small light and a large tile beside it, which
// a plate hides from the floor: by area the floor would see 6 % of the light.
TEST(ClusterLinks, LightsInClustersAreSeenWhereTheyEmit) {
  auto quad = [](double x0, double x1, double y, double z0, double z1, bool up) {
    Polygon p;
    p.count = 4;
    p.v = {glm::dvec3(x0, y, z0), glm::dvec3(x1, y, z0), glm::dvec3(x1, y, z1),
           glm::dvec3(x0, y, z1)};
    if (up) std::swap(p.v[1], p.v[3]);
    return p;
  };
  std::vector<Polygon> polys = {
      quad(-0.25, 0.25, 0.0, -0.25, 0.25, true),    // 0: the floor patch, facing up
      quad(-0.25, 0.25, 20.0, -0.25, 0.25, false),  // 1: the light, facing down
      quad(0.5, 2.5, 20.0, -1.0, 1.0, false),       // 2: the tile beside it, facing down
      quad(0.4, 2.6, 19.8, -1.1, 1.1, true)};       // 3: the plate under the tile, facing up
  ASSERT_GT(polys[0].normal().y, 0.99);
  ASSERT_LT(polys[1].normal().y, -0.99);
  ASSERT_GT(polys[3].normal().y, 0.99);
  VisibilityScene vis(visibilityTrianglesOf(polys));
  std::vector<SurfaceProperties> surf(polys.size());
  for (auto& s : surf) s.reflectance = glm::dvec3(0.5);
  surf[1].emission = glm::dvec3(100.0);
  surf[1].reflectance = glm::dvec3(0.0);
  auto floorB = [&](double share, size_t& clusterLinks) {
    RadiosityOptions o;
    o.lightClusterShare = share;
    const KeySolution s = solveTiled(polys, surf, vis, true, o);
    clusterLinks = 0;
    for (const ClusterLink& l : s.clusterLinkValues)
      clusterLinks += l.receiver == 0 && isCluster(l.shooter) ? 1 : 0;
    return s.radiosity[0].x;
  };
  size_t refinedLinks = 0, clusteredLinks = 0;
  const double refined = floorB(0.0, refinedLinks), clustered = floorB(1e3, clusteredLinks);
  std::cout << "floor B: light links refined " << refined << ", through a cluster link "
            << clustered << " (" << clusteredLinks << " cluster links to it)\n";
  EXPECT_EQ(refinedLinks, 0u);
  EXPECT_GT(clusteredLinks, 0u);
  EXPECT_NEAR(clustered / refined, 1.0, 0.05);
}

// A 6 x 3 x 5 m room tiled 6 x 6 per wall, a 1 m ceiling light facing down and a tiled box on
// the floor (the link-bound tests' scene).
struct LitRoom {
  std::vector<Polygon> polys;
  std::vector<SurfaceProperties> surf;
  int light = 0;
};
LitRoom litRoom() {
  LitRoom r;
  r.polys = tiledBoxFaces({0, 0, 0}, {6, 3, 5}, true, 6);
  r.light = int(r.polys.size());
  r.polys.push_back(boxFaces({2.5, 2.9, 2.0}, {3.5, 3.0, 3.0}, false)[0]);  // faces down
  for (const Polygon& p : tiledBoxFaces({1, 0, 1}, {2, 1, 2}, false, 2)) r.polys.push_back(p);
  r.surf.resize(r.polys.size());
  for (auto& s : r.surf) s.reflectance = glm::dvec3(0.7);
  r.surf[size_t(r.light)].emission = glm::dvec3(10.0);
  r.surf[size_t(r.light)].reflectance = glm::dvec3(0.0);
  return r;
}

// At the link bound, refinement goes on for the lights' links only: every top that sees the
// light keeps its own link to it (the second pass's per-texel shadows), and the bound is
// reported. It had stopped wherever it was and not said so: the 30k-triangle hall lost 92 % of
// its bad pairs, its lights reaching whole clusters unshadowed.
TEST(ClusterLinks, LightsKeepTheirLinksAtTheLinkBound) {
  const LitRoom room = litRoom();
  const std::vector<Polygon>& polys = room.polys;
  const std::vector<SurfaceProperties>& surf = room.surf;
  const int light = room.light;
  VisibilityScene vis(visibilityTrianglesOf(polys));
  auto lit = [&](size_t maxLinks, bool& capped) {
    PatchHierarchy h = hierarchyOf(polys);
    RadiosityOptions o;
    o.maxLinks = maxLinks;
    KeySolution s = solveTiled(h, polys, surf, vis, true, o);
    capped = s.linkCapReached;
    std::set<int> tops;
    for (const SolverLink& l : s.links)
      if (h.node(l.shooter).id.top == uint32_t(light)) tops.insert(int(h.node(l.receiver).id.top));
    return tops;
  };
  bool cappedFree = true, capped = false;
  const std::set<int> free = lit(4000000, cappedFree), bounded = lit(3000, capped);
  EXPECT_FALSE(cappedFree);
  EXPECT_TRUE(capped);
  EXPECT_GT(free.size(), 100u);
  EXPECT_EQ(bounded, free);
}

// The link bound counts the links in use. A cluster link refined within a round is replaced by
// its children, but the bound still counted it until the round ended: the 10k-triangle hall
// reported the bound at every key time with a quarter of it in use. A bound a little above what
// an unbounded solve holds must now leave that solve as it was.
TEST(ClusterLinks, LinkBoundCountsOnlyTheLinksInUse) {
  const LitRoom room = litRoom();
  const std::vector<Polygon>& polys = room.polys;
  const std::vector<SurfaceProperties>& surf = room.surf;
  VisibilityScene vis(visibilityTrianglesOf(polys));
  auto solve = [&](size_t maxLinks) {
    PatchHierarchy h = hierarchyOf(polys);
    RadiosityOptions o;
    o.maxLinks = maxLinks;
    return solveTiled(h, polys, surf, vis, true, o);
  };
  const KeySolution free = solve(4000000);
  ASSERT_FALSE(free.linkCapReached);
  const size_t held = free.links.size() + free.clusterLinks;
  const KeySolution bounded = solve(held + held / 20);
  EXPECT_FALSE(bounded.linkCapReached) << "bound " << held + held / 20 << ", held " << held;
  EXPECT_EQ(bounded.links.size(), free.links.size());
  EXPECT_EQ(bounded.clusterLinks, free.clusterLinks);
}

// Issue 58: near cluster links between rooms behind a wall. Two 4 x 3 x 4 m rooms 0.2 m apart
// (each tiled 4 x 4 a face, closed), six tiled boxes in each along the wall between them, a
// light in the first room's ceiling. The furniture clusters of the two rooms are near by their
// spheres and cannot see each other; with more facing member pairs than blocked() tests one by
// one they were refined untested down to every pair of their members (the 10^5 floor filled the
// link bound so). The sampled test (cluster_links.h, sampledBlocked) drops them: few near links
// refined untested, no bound reached at a lowered bound, and the lit room's floor as without it.
TEST(ClusterLinks, NearLinksBehindAWallAreDroppedNotRefined) {
  std::vector<Polygon> polys = tiledBoxFaces({0, 0, 0}, {4, 3, 4}, true, 4);
  const size_t roomA = polys.size();
  for (const Polygon& p : tiledBoxFaces({4.2, 0, 0}, {8.2, 3, 4}, true, 4)) polys.push_back(p);
  const size_t light = polys.size();
  polys.push_back(boxFaces({1.5, 2.9, 1.5}, {2.5, 3.0, 2.5}, false)[0]);  // faces down
  for (double side : {0.0, 1.0})
    for (int k = 0; k < 6; ++k) {
      const double x = side == 0.0 ? 3.2 : 4.4, z = 0.2 + 0.62 * k;
      for (const Polygon& p :
           tiledBoxFaces({x, 0.0, z}, {x + 0.6, 0.4 + 0.1 * k, z + 0.5}, false, 2))
        polys.push_back(p);
    }
  VisibilityScene vis(visibilityTrianglesOf(polys));
  const std::vector<SurfaceProperties> surf = greyWithOneLight(polys.size(), light);
  auto solve = [&](int nearBlockRays, size_t maxLinks) {
    RadiosityOptions o;
    o.nearBlockRays = nearBlockRays;
    o.maxLinks = maxLinks;
    return solveTiled(polys, surf, vis, true, o);
  };
  auto untested = [](const KeySolution& s) {
    size_t n = 0;
    for (size_t v : s.linkCensus.nearUntested) n += v;
    return n;
  };
  auto dropped = [](const KeySolution& s) {
    size_t n = 0;
    for (size_t v : s.linkCensus.nearDropped) n += v;
    return n;
  };
  const RadiosityOptions defaults;
  const KeySolution off = solve(0, defaults.maxLinks),
                    on = solve(defaults.nearBlockRays, defaults.maxLinks);
  double floorOn = 0.0, floorOff = 0.0, area = 0.0;
  for (size_t t = 0; t < roomA; ++t)
    if (polys[t].normal().y > 0.9) {
      floorOn += polys[t].area() * on.radiosity[t].x;
      floorOff += polys[t].area() * off.radiosity[t].x;
      area += polys[t].area();
    }
  std::cout << "near links refined untested: off " << untested(off) << ", on " << untested(on)
            << "; dropped off " << dropped(off) << ", on " << dropped(on) << "; links off "
            << off.links.size() << " + " << off.clusterLinks << ", on " << on.links.size() << " + "
            << on.clusterLinks << "; lit floor B on / off " << floorOn / floorOff << "\n";
  EXPECT_GT(floorOff / area, 0.05);
  EXPECT_NEAR(floorOn / floorOff, 1.0, 0.005);
  EXPECT_LT(untested(on) * 3, untested(off));
}

// Issue 58, the closed-room test (key_time_closure.cpp): a leaf counts as inside a closed room
// when none of its escape rays leaves the scene, and the closure then fills its row to 1. The
// room of ExposedFloorMatchesAllPairsAtTheDefaultSeparation is open at its +x end, 8 to 12 m
// from most of its floor; 64 rays a leaf missed that opening on most floor leaves there, even
// on leaves that see it with a form factor of 5 % or more (the contract: such a leaf goes
// unnoticed with probability 4 %; among hundreds of leaves, some do). With the rays of a leaf
// and of its ancestors pooled, no floor leaf that sees 5 % of the opening counts as closed.
TEST(ClosedRooms, FloorLeavesThatSeeTheOpeningAreNotClosed) {
  const std::vector<Polygon> room = tiledBoxFaces({0, 0, 0}, {12, 3, 4}, true, 8);
  std::vector<Polygon> polys(room.begin(), room.end() - 64);  // +x wall open
  const Polygon opening = boxFaces({0, 0, 0}, {12, 3, 4}, true).back();
  const size_t light = polys.size();
  polys.push_back(boxFaces({10.5, 2.9, 1.5}, {11.5, 3.0, 2.5}, false)[0]);  // faces down
  VisibilityScene vis(visibilityTrianglesOf(polys));
  PatchHierarchy h = hierarchyOf(polys);
  const KeySolution s = solveTiled(h, polys, greyWithOneLight(polys.size(), light), vis, true);
  int floorNodes = 0, closedSeeing = 0;
  double seenMost = 0.0;
  for (const auto& [id, closed] : s.closedNodes) {
    const int i = h.find(PatchId::fromPacked(id));
    ASSERT_GE(i, 0);
    const Polygon& P = h.node(i).local;
    if (!(P.normal().y > 0.9 && P.centroid().y < 1e-9)) continue;
    ++floorNodes;
    const double f = pointToPolygonFormFactor(P.centroid(), P.normal(), opening);  // unoccluded
    if (closed && f >= 0.05) {
      ++closedSeeing;
      seenMost = std::max(seenMost, f);
    }
  }
  EXPECT_GT(floorNodes, 100);
  EXPECT_EQ(closedSeeing, 0) << "floor leaves counted closed that see the opening with F >= 5 %"
                             << " (at most " << seenMost << ")";
}
}  // namespace
}  // namespace rad
