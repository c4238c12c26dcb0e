// The lamps' light at rad-compose's fallback samples (contract in fallback_lamp_light.h).
#include "libcommon/compose/fallback_lamp_light.h"

#include "libcommon/movies/lamp_direct_term.h"
#include "libcommon/radiosity/lamp_irradiance.h"

namespace rad {

FallbackLampLight::FallbackLampLight(const Scene& scene, const GlobalSolution& solution)
    : solution_(solution), emitters_(scene, solution.hierarchy.tops()) {}

void FallbackLampLight::setTime(double t, const VisibilityScene& visibility) {
  placed_ = placeLamps(emitters_, t);
  visibility_ = &visibility;
  solution_.keyWeights(t, k0_, k1_, w_);
}

FallbackLampLight::Terms FallbackLampLight::at(int leaf, const Polygon& leafWorld,
                                               const glm::dvec3& x, const glm::dvec3& n,
                                               int top) const {
  Terms out;
  const glm::dvec3 leafNormal = leafWorld.normal();
  for (const PlacedPunctualLight* lamp : placed_.lamps) {
    out.leafAverage +=
        lampIrradiance(*lamp, leafWorld, leafNormal, visibility_, std::uint32_t(top)).mean;
    out.atPoint += lampDirectAt(*lamp, x, n, *visibility_, std::uint32_t(top));
  }
  // B between keys is (1 - w) B(k0) + w B(k1), each holding rho E / e of its key.
  const auto inverse = [&](int k) {
    const double e = solution_.exposureAtKey(leaf, k);
    return e > 0.0 ? 1.0 / e : 0.0;
  };
  out.leafAverage *= (1.0 - w_) * inverse(k0_) + w_ * inverse(k1_);
  return out;
}

}  // namespace rad
