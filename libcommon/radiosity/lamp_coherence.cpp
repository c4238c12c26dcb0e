// rad-global's lamps over key times (contract in lamp_coherence.h).
#include "libcommon/radiosity/lamp_coherence.h"

#include <array>

#include "libcommon/core/error.h"
#include "libcommon/radiosity/key_solve_inputs.h"
#include "libcommon/radiosity/shaft.h"

namespace rad {

PlacedLamps placeLamps(const SceneEmitters& emitters, double t) {
  PlacedLamps out;
  if (emitters.lamps().size() > size_t(kMaxLamps))
    throw Error(ExitCode::kBadInput, "",
                std::to_string(emitters.lamps().size()) + " punctual lights; at most " +
                    std::to_string(kMaxLamps) + " are supported");
  static const PunctualLight kDark;  // a lamp degenerate at t: no intensity
  static const PlacedPunctualLight kNone(kDark, glm::dvec3(0.0), glm::dvec3(0.0, 0.0, -1.0),
                                         {glm::dvec3(0.0), glm::dvec3(0.0)});
  for (int index : emitters.lamps()) {
    std::unique_ptr<PlacedEmitter> placed = emitters[size_t(index)].at(t);
    const auto* lamp = dynamic_cast<const PlacedPunctualLight*>(placed.get());
    out.lamps.push_back(lamp ? lamp : &kNone);
    out.owned.push_back(std::move(placed));
  }
  return out;
}

namespace {

// The lamp's end of the shaft from receiver `r`: a small triangle at its position, or for a sun
// the receiver moved against its direction by its reach.
Polygon lampEnd(const PlacedPunctualLight& lamp, const Polygon& r) {
  Polygon p;
  if (lamp.directional()) {
    const glm::dvec3 far = lamp.shadowTarget(glm::dvec3(0.0));  // -direction x reach
    p = r;
    for (int k = 0; k < p.count; ++k) p.v[size_t(k)] += far;
    return p;
  }
  const double s = 1e-9 * (1.0 + glm::length(lamp.position()));
  p.count = 3;
  p.v[0] = lamp.position();
  p.v[1] = lamp.position() + glm::dvec3(s, 0.0, 0.0);
  p.v[2] = lamp.position() + glm::dvec3(0.0, s, 0.0);
  return p;
}

}  // namespace

LampValueCache reusableLampValues(const KeySolution& previous, const PlacedLamps& before,
                                  const SceneEmitters& emitters, const PatchHierarchy& hierarchy,
                                  const Scene& scene, double t0, double t1) {
  LampValueCache out;
  const std::vector<char> moving = movingTopsOf(scene, hierarchy, t0, t1);
  std::vector<std::array<glm::dvec3, 2>> swept;
  for (int node : scene.meshNodes())
    if (scene.isDynamic(node, t0, t1)) swept.push_back(scene.sweptBounds(node, t0, t1));
  std::vector<char> lampMoves;
  for (int index : emitters.lamps()) lampMoves.push_back(emitters[size_t(index)].moves(t0, t1));
  for (const auto& [key, value] : previous.lampValues) {
    const int node = int(key >> 8), lamp = int(key & 0xff);
    if (lampMoves[size_t(lamp)] || moving[hierarchy.node(node).id.top]) continue;
    const Polygon& r = previous.world[size_t(node)];
    const Polygon l = lampEnd(*before.lamps[size_t(lamp)], r);
    bool shadowed = false;
    for (const auto& box : swept)
      if (shaftMeetsBox(r, l, box[0], box[1])) {
        shadowed = true;
        break;
      }
    if (!shadowed) out.emplace(key, value);
  }
  return out;
}

}  // namespace rad
