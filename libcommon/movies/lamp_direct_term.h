// rad-movies' direct light from punctual lamps (docs/design.md §4 "Lights", §6.3): per texel,
// the lamp's irradiance $I \cos\theta / d^2$ (a sun's $E \cos\theta$) times an exact hard
// shadow, one Embree ray per texel and lamp to the lamp's shadowTarget. As the area lights' bad
// layer (paper §5): the static blockers are tested once per movie where lamp and receiver stay
// still, the moving ones at each key; a moving lamp or receiver tests both at every key. A ray
// is open when both parts leave it open, exactly the whole scene's answer, so the coherent
// result equals the from-scratch one. Rays start on the texel's surface point and ignore the
// receiver's own top-level patch; a point under a touching solid is dark (its rays leave
// through the solid) and the baker fills it from its exposed neighbours as for area lights.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/movies/movie_geometry.h"
#include "libcommon/radiosity/scene_visibility.h"
#include "libcommon/scene/punctual_light_emitter.h"
#include "libcommon/scene/scene_emitters.h"

namespace rad {

// Whether the lamps' shadows on a receiver (top-level patch node `receiverNode`, its polygon at
// t0 `receiver`) may move during [t0, t1]: the receiver or a lamp moves, or a moving mesh node's
// swept bounds meet the box around the receiver and a lamp's bounds (a sun's: the scene's). As
// the area lights' test in TextureMovieBaker::shadowsMove (--moving-shadow-key-step).
bool lampShadowsMove(const Scene& scene, const std::vector<InputPolygon>& tops,
                     const SceneEmitters& emitters, int receiverNode, const Polygon& receiver,
                     double t0, double t1);

// One point's direct irradiance from one placed lamp (W/m^2): the lamp's irradiance at p (unit
// normal n) when the segment from p to its shadowTarget is open in `visibility`, ignoring the
// surface `receiverTop` (the point's own top-level patch), else 0. The test LampDirectTerm::add
// makes per texel, against one whole scene instead of its static and moving parts; rad-compose's
// fallback samples take their lamps' light from it (fallback_lamp_light.h).
glm::dvec3 lampDirectAt(const PlacedEmitter& lamp, const glm::dvec3& p, const glm::dvec3& n,
                        const VisibilityScene& visibility, std::uint32_t receiverTop);

// One movie's lamp term. Used by one thread (the movie's baker), with `visibility` its own.
class LampDirectTerm {
 public:
  // `emitters`: the scene's (SceneEmitters::lamps are the lamps); `receiverTop` the movie's
  // top-level patch (its rays ignore it). Holds references: all must outlive the term.
  LampDirectTerm(const SceneEmitters& emitters, const MovieGeometry& geometry,
                 SceneVisibility& visibility, std::uint32_t receiverTop);

  // Adds the lamps' direct irradiance at key k (time t) to acc (per texel, W/m^2).
  void add(int k, double t, std::vector<glm::dvec3>& acc);

  // Rays cast so far (static and moving parts).
  long rays() const { return rays_; }

 private:
  const SceneEmitters& emitters_;
  const MovieGeometry& geo_;
  SceneVisibility& vis_;
  std::uint32_t receiverTop_;
  bool receiverMoves_ = false;
  // Per lamp: whether it moves during the movie, and (static lamp and receiver) each texel's
  // ray open against the static blockers, made at the first key (empty until then).
  std::vector<char> lampMoves_;
  std::vector<std::vector<char>> staticOpen_;
  long rays_ = 0;
};

}  // namespace rad
