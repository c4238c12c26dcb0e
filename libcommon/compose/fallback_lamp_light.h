// rad-compose's fallback samples under punctual lamps (docs/design.md §4 "Lights", §6.4). A
// covered sample that no movie textures reads the global solution's radiosity B, whose lamp term
// is rad-global's area average over the leaf (lamp_irradiance.h): the leaf's mean of
// $I \cos\theta / d^2$ and of its shadow rays, no hard shadow. The fallback takes that average
// out of B and puts in the point's own direct irradiance with rad-movies' per-texel test
// (lampDirectAt, lamp_direct_term.h), so a pixel that falls back shows the lamps' light and
// shadows as a movie's texel would (paper §5: the lights' direct term is the bad layer, exact
// per point):
//   $L = L_e + \frac{tex(x)}{\overline{tex}} \big(\max(0, B/\pi - \overline{L_e}
//        - \frac{\rho}{\pi} \overline{E}/e) + \frac{\rho}{\pi} E(x)\big)$.
// The leaf's average $\overline{E}$ is recomputed at the frame's time over the union leaf under
// the point, with rad-global's own function and rays, and divided by the leaf's exposure e
// interpolated as B is between key times. It equals what B holds when the union leaf is a leaf
// of the keys' trees and the lamps stand still between them (a static scene: every fallback
// sample); where a key's leaf was coarser, or a lamp moves between keys, the difference stays
// inside the leaf's share of the lamps' light. Deterministic: no random numbers, one answer per
// sample whatever the thread.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "libcommon/radiosity/global_solution.h"
#include "libcommon/radiosity/lamp_coherence.h"
#include "libcommon/radiosity/scene_visibility.h"
#include "libcommon/scene/scene.h"
#include "libcommon/scene/scene_emitters.h"

namespace rad {

class FallbackLampLight {
 public:
  // `scene` and `solution` must outlive this; solution.hierarchy's tops are the scene's.
  FallbackLampLight(const Scene& scene, const GlobalSolution& solution);

  // Whether the scene has lamps (without, the fallback is B / pi as before).
  bool empty() const { return emitters_.lamps().empty(); }

  // The lamps at time t, shadow rays against `visibility` (set to t by the caller; it must
  // outlive the calls of at()). Once a frame, before any sample.
  void setTime(double t, const VisibilityScene& visibility);

  struct Terms {
    glm::dvec3 leafAverage{0.0};  // the lamps' E in B at the leaf: $\overline{E}/e$, W/m^2
    glm::dvec3 atPoint{0.0};      // the lamps' E at the point, hard shadows, W/m^2
  };
  // The sample at world point x (unit normal n) on top-level patch `top`, in union leaf `leaf`
  // whose world polygon at t is `leafWorld`. Thread-safe between setTime() calls.
  Terms at(int leaf, const Polygon& leafWorld, const glm::dvec3& x, const glm::dvec3& n,
           int top) const;

 private:
  const GlobalSolution& solution_;
  SceneEmitters emitters_;
  PlacedLamps placed_;
  const VisibilityScene* visibility_ = nullptr;
  int k0_ = 0, k1_ = 0;  // the keys around the time, and the weight of k1 (keyWeights)
  double w_ = 0.0;
};

}  // namespace rad
