// Warnings about scenes that make rad-global's solve slow, said before it runs (issue 57).
//
// Blender's glTF exporter makes every material doubleSided unless "Backface Culling" is ticked,
// and a doubleSided polygon is two patches back to back (docs/design.md §4). A closed mesh then
// has an inside: a cavity whose patches see only each other and what lies inside. Light inside
// it (a bulb in a closed lamp shade) keeps a fraction ρ of itself at each bounce, ρ the area mean
// of the inside's reflectance, so the solve's change falls like ρ^n over n sweeps and the stop
// rule tol (1 - ρ_max) (hierarchical_radiosity.h) asks for about
// $n \approx \ln(\mathrm{tol}\,(1 - \rho_{max})) / \ln \rho$ sweeps: with the white of a base
// colour 1.0 (clamped to 0.999) hundreds or thousands, where a scene of ρ ≤ 0.8 takes a few tens.
#pragma once

#include <string>
#include <vector>

#include "libcommon/scene/scene.h"

namespace rad {

// A closed mesh whose inside reflects: its node, its mesh, the inside's reflectance (the area
// mean of the largest channel of ρ over its triangles, 0 for a one-sided material, whose back
// absorbs, and over the meshes inside it, by their world bounds over the animation), the material
// that reflects most on its walls, and whether something inside it emits.
struct ReflectingCavity {
  int node = -1;
  int mesh = -1;
  int material = -1;  // Scene::materials index
  double reflectance = 0.0;
  bool lit = false;
};

// Meshes of the displayed scene that are closed (every edge, by exact vertex positions, shared
// by exactly two triangles) and whose inside reflects at least `minReflectance`, in mesh-node
// order. Deterministic; linear in the triangles.
std::vector<ReflectingCavity> reflectingCavities(const Scene& scene, double minReflectance);

// Estimated Gauss-Seidel sweeps until the relative change is below tol (1 - ρ), for a cavity of
// reflectance ρ (the formula above with ρ_max = ρ); 1 for ρ = 0.
double estimatedSweeps(double reflectance, double tol);

// One line per lit cavity of reflectance ≥ 0.9 (ten bounces and more), naming node, mesh and
// material by glTF name and index, with the estimated sweeps against a scene of ρ 0.8 (Blender's
// default base colour) and what to change in Blender. `tol` is rad-global's --tol.
std::vector<std::string> slowSolveWarnings(const Scene& scene, double tol);

}  // namespace rad
