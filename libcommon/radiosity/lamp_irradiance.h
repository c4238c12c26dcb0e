// A punctual lamp's direct irradiance on a radiosity element (docs/design.md §4 "Lights",
// §6.1): the first-pass term E of $B = B_e + \rho (E + H)$, an area average over the element
// with the lamp's own shadow rays, and how much it varies across the element (what the
// refinement oracle reads: a lamp's receivers are subdivided where E varies, at its shadow
// boundaries and under it).
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/radiosity/visibility.h"
#include "libcommon/scene/geometry.h"
#include "libcommon/scene/punctual_light_emitter.h"

namespace rad {

// The solid angle (sr) that polygon `p` subtends at point `x` when x is on its front side
// (the side its normal points to), else 0: the sum over its fan triangles of Van Oosterom and
// Strackee's $\tan(\Omega/2) = |a \cdot (b \times c)| / (abc + (a \cdot b)c + (a \cdot c)b +
// (b \cdot c)a)$ (1983, "The solid angle of a plane triangle").
double frontSolidAngle(const Polygon& p, const glm::dvec3& x);

// A lamp's irradiance on one element.
struct LampValue {
  glm::dvec3 mean{0.0};  // area average over the element, W/m^2, shadows included
  double spread = 0.0;   // largest channel's (max - min) of E over the element's sample points
};

// Samples per side of an element's stratified grid (cell centres; no randomness, so a value is
// the same whenever its geometry is, which is what coherence relies on).
constexpr int kLampSamplesPerSide = 4;

// The lamp's E over element `world` (unit front normal `normal`), shadow rays to the lamp's
// shadowTarget against `visibility` (null: unoccluded) ignoring the element's own surface id.
// Unoccluded and isotropic it is exact: for a point or spot lamp $I \Omega / A$ (the integral of
// $\cos\theta / d^2$ over the element is the solid angle it subtends at the lamp), weighted by
// the kernel-weighted mean of the spot profile, the range window and the visibility over the
// samples, $\sum_k K_k f_k v_k / \sum_k K_k$, $K_k = \cos\theta_k / d_k^2$; for a sun
// $E \cos\theta$ times the fraction of samples that see it.
LampValue lampIrradiance(const PlacedPunctualLight& lamp, const Polygon& world,
                         const glm::dvec3& normal, const VisibilityScene* visibility,
                         std::uint32_t surface);

// The lamps' values of a key solve kept for the next (coherence): (dense node << 8 | lamp) ->
// value. Only values whose geometry and shadows stay the same are handed on
// (reusableLampValues, key_solve_inputs.h).
using LampValueCache = std::unordered_map<std::uint64_t, LampValue>;
inline std::uint64_t lampValueKey(int node, int lamp) {
  return (std::uint64_t(node) << 8) | std::uint64_t(lamp);
}
// At most this many lamps a scene (the key's low byte).
constexpr int kMaxLamps = 256;

}  // namespace rad
