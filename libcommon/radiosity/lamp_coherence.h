// The punctual lamps of rad-global's space-time pass (paper §4.2; docs/design.md §4 "Lights",
// §6.1): each key's lamps placed at its time, and which lamp values of the previous key stay
// valid (space-time coherence, as links' do: a static lamp's values on static receivers are kept
// while no moving object's swept bounds meet the shaft between them; a moving lamp's are
// computed again). Deterministic: pure functions of the scene, the times and the values.
#pragma once

#include <memory>
#include <vector>

#include "libcommon/radiosity/hierarchical_radiosity.h"
#include "libcommon/scene/patch_hierarchy.h"
#include "libcommon/scene/scene.h"
#include "libcommon/scene/scene_emitters.h"

namespace rad {

// The lamps of `emitters` (SceneEmitters::lamps, in order) placed at time t; a lamp that
// degenerates there (a zero scale) lights nothing at that key and stays in the list, so a
// lamp's index is the same at every key. Throws rad::Error (kBadInput) past kMaxLamps lamps.
struct PlacedLamps {
  std::vector<std::unique_ptr<PlacedEmitter>> owned;
  std::vector<const PlacedPunctualLight*> lamps;  // KeySolveInput::lamps
};
PlacedLamps placeLamps(const SceneEmitters& emitters, double t);

// The values of `previous` (solved at t0, lamps `before`) that stay valid at t1: the receiver's
// top static over [t0, t1], the lamp static over it, and no moving mesh node's swept bounds
// meeting the shaft from the receiver (prev.world) to the lamp (its position; a sun's: the
// receiver moved against its direction past the scene).
LampValueCache reusableLampValues(const KeySolution& previous, const PlacedLamps& before,
                                  const SceneEmitters& emitters, const PatchHierarchy& hierarchy,
                                  const Scene& scene, double t0, double t1);

}  // namespace rad
