// Hierarchical radiosity at one time against tests/data/reference/furnace.json (see the README
// there): uniform furnaces up to rho = 0.999, the exact one-emitter discrete systems, the
// two-squares system, energy balance with refinement, and the shaft test.
#include "libcommon/hierarchical_radiosity.h"

#include <cmath>
#include <fstream>
#include <iostream>

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

std::vector<Polygon> geometry(const std::string& name) {
  std::vector<Polygon> out;
  for (const Json& p : furnace()["geometries"][name]["patches"]) out.push_back(polygonOf(p));
  return out;
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

// Closed box, small light, refinement on: absorbed = emitted power within 1% at rho = 0.5.
// Constant-basis hierarchical radiosity does not conserve energy exactly (a link between
// large patches uses the shooter's mean B, not its distribution); the brightness-weighted
// oracle bounds each link's energy, not the sum of their errors. At rho = 0.9 the measured
// excess is 13% (eps 1e-3), 11% (3e-4), 9% (1e-4): printed, not asserted.
TEST(HierarchicalRadiosity, EnergyBalanceWithRefinement) {
  for (double rho : {0.5, 0.9}) {
    // The unit cube with a small light 1 mm below the middle of the ceiling, facing down (a
    // closed enclosure: the light's back emits nothing and blocks nothing here).
    std::vector<Polygon> polys = geometry("unit_cube_6");
    Polygon light;
    light.count = 4;
    double z = 1 - 1e-3;
    light.v = {glm::dvec3(0.4, 0.4, z), glm::dvec3(0.4, 0.6, z), glm::dvec3(0.6, 0.6, z),
               glm::dvec3(0.6, 0.4, z)};
    polys.push_back(light);
    PatchHierarchy h = hierarchyOf(polys);
    std::vector<SurfaceProperties> surf(size_t(h.topCount()));
    for (auto& s : surf) s.reflectance = glm::dvec3(rho);
    surf[6].emission = glm::dvec3(1.0, 2.0, 3.0);
    RadiosityOptions o;
    o.eps = rho <= 0.5 ? 3e-4 : 1e-3;
    o.minArea = 1e-3;
    o.tol = 1e-6;
    KeySolution s = solveKeyTime(h, surf, identityInput(h), o);
    glm::dvec3 absorbed = s.absorbedPower(h, surf), emitted = s.emittedPower(h, surf);
    if (rho <= 0.5) {
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(absorbed[c] / emitted[c], 1.0, 0.01) << rho;
    }
    EXPECT_GT(h.size(), 6 * 5);
    std::cout << "box rho " << rho << ": " << h.size() << " nodes, " << s.links.size() << " links, "
              << s.iterations << " sweeps, " << s.refineRounds << " rounds, absorbed/emitted "
              << absorbed.x / emitted.x << "\n";
  }
}

// Visibility in a convex enclosure is 1 for every link; an inner blocker lowers it.
TEST(HierarchicalRadiosity, VisibilityInsideEnclosure) {
  std::vector<Polygon> polys = geometry("unit_cube_6");
  PatchHierarchy h = hierarchyOf(polys);
  std::vector<VisibilityTriangle> tris;
  for (int t = 0; t < h.topCount(); ++t) {
    const Polygon& p = polys[size_t(t)];
    tris.push_back({{p.v[0], p.v[1], p.v[2]}, uint32_t(t)});
    tris.push_back({{p.v[0], p.v[2], p.v[3]}, uint32_t(t)});
  }
  VisibilityScene vis(tris);
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
