// Warnings about slow solves (solve_cost_warnings.h).
#include "libcommon/radiosity/solve_cost_warnings.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include "libcommon/core/error.h"
#include "libcommon/scene/gltf_item_label.h"

namespace rad {
namespace {

// The reflectance from which a cavity is reported: ten bounces and more.
constexpr double kSlowCavityReflectance = 0.9;
// Blender's default base colour, the comparison the warning gives.
constexpr double kBlenderDefaultReflectance = 0.8;

using Point = std::array<double, 3>;
using Edge = std::pair<Point, Point>;

Point pointOf(const glm::dvec3& p) {
  return {p.x, p.y, p.z};
}

// Whether every edge of the triangles is shared by exactly two of them.
bool isClosed(const std::vector<MeshTriangle>& triangles) {
  if (triangles.size() < 4) return false;
  std::map<Edge, int> uses;
  for (const MeshTriangle& t : triangles)
    for (int k = 0; k < 3; ++k) {
      Point a = pointOf(t.p[size_t(k)]), b = pointOf(t.p[size_t((k + 1) % 3)]);
      if (b < a) std::swap(a, b);
      ++uses[{a, b}];
    }
  return std::all_of(uses.begin(), uses.end(), [](const auto& e) { return e.second == 2; });
}

double maxComponent(const glm::dvec3& v) {
  return std::max({v.x, v.y, v.z});
}

}  // namespace

std::vector<ReflectingCavity> reflectingCavities(const Scene& scene, double minReflectance) {
  std::vector<ReflectingCavity> out;
  const std::vector<int> meshNodes = scene.meshNodes();
  const double t0 = scene.startTime(), t1 = scene.endTime();
  for (int node : meshNodes) {
    const int mesh = scene.nodes[size_t(node)].mesh;
    const std::vector<MeshTriangle>& triangles = scene.meshes[size_t(mesh)].triangles;
    if (!isClosed(triangles)) continue;
    ReflectingCavity c{node, mesh, -1, 0.0, false};
    double area = 0.0, reflected = 0.0, best = -1.0;
    const auto add = [&](int n, bool inside) {
      const glm::dmat4 world = scene.worldTransform(n, t0);
      for (const MeshTriangle& t : scene.meshes[size_t(scene.nodes[size_t(n)].mesh)].triangles) {
        const glm::dvec3 p0(world * glm::dvec4(t.p[0], 1.0)), p1(world * glm::dvec4(t.p[1], 1.0)),
            p2(world * glm::dvec4(t.p[2], 1.0));
        const double a = 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
        area += a;
        const bool known = t.material >= 0 && size_t(t.material) < scene.materials.size();
        const Material m = known ? scene.materials[size_t(t.material)] : Material{};
        if (inside && m.isEmitter()) c.lit = true;
        // A one-sided wall's back absorbs (docs/design.md §4); what lies inside shows its front.
        if (!inside && !m.doubleSided) continue;
        const double rho = std::min(maxComponent(m.reflectance), kMaxReflectance);
        reflected += a * rho;
        if (!inside && rho > best) best = rho, c.material = t.material;
      }
    };
    add(node, false);
    const auto bounds = scene.sweptBounds(node, t0, t1);
    for (int other : meshNodes) {
      if (other == node) continue;
      const auto b = scene.sweptBounds(other, t0, t1);
      if (glm::all(glm::greaterThanEqual(b[0], bounds[0])) &&
          glm::all(glm::lessThanEqual(b[1], bounds[1])))
        add(other, true);
    }
    c.reflectance = area > 0.0 ? reflected / area : 0.0;
    if (c.reflectance >= minReflectance) out.push_back(c);
  }
  return out;
}

double estimatedSweeps(double reflectance, double tol) {
  if (!(reflectance > 0.0)) return 1.0;
  const double rho = std::min(reflectance, kMaxReflectance);
  return std::max(1.0, std::log(tol * (1.0 - rho)) / std::log(rho));
}

std::vector<std::string> slowSolveWarnings(const Scene& scene, double tol) {
  std::vector<std::string> out;
  for (const ReflectingCavity& c : reflectingCavities(scene, kSlowCavityReflectance)) {
    if (!c.lit) continue;  // no light inside: the cavity stays dark and costs nothing
    const double sweeps = estimatedSweeps(c.reflectance, tol);
    const double usual = estimatedSweeps(kBlenderDefaultReflectance, tol);
    out.push_back(meshLabel(scene, c.mesh) + " of " + nodeLabel(scene, c.node) +
                  " is closed around a light and its inside reflects " + numberText(c.reflectance) +
                  " (" + materialLabel(scene, c.material) +
                  " is double-sided): light inside it bounces about 1/(1 - rho) = " +
                  numberText(std::round(1.0 / (1.0 - c.reflectance))) +
                  " times, and the solve needs about " + numberText(std::round(sweeps)) +
                  " sweeps where reflectance 0.8 needs " + numberText(std::round(usual)) +
                  "; tick \"Backface Culling\" in the material's settings in Blender (a one-sided "
                  "material), or lower its base colour");
  }
  return out;
}

}  // namespace rad
