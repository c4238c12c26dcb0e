// The scene's list of lights (contract in scene_emitters.h).
#include "libcommon/scene/scene_emitters.h"

#include "libcommon/scene/emission_texture.h"
#include "libcommon/scene/emissive_polygon_emitter.h"
#include "libcommon/scene/punctual_light_emitter.h"

namespace rad {

SceneEmitters::SceneEmitters(const Scene& scene, const std::vector<InputPolygon>& tops)
    : ofTop_(tops.size(), -1) {
  for (std::size_t t = 0; t < tops.size(); ++t) {
    if (!scene.emits(tops[t])) continue;
    ofTop_[t] = int(emitters_.size());
    emitters_.push_back(std::make_unique<EmissivePolygonEmitter>(scene, tops[t], int(t),
                                                                 meanEmissionOver(scene, tops[t])));
  }
  const std::vector<int> lamps = scene.lightNodes();
  if (lamps.empty()) return;
  const std::array<glm::dvec3, 2> bounds = animationBounds(scene);
  for (int node : lamps) {
    lamps_.push_back(int(emitters_.size()));
    emitters_.push_back(std::make_unique<PunctualLightEmitter>(scene, node, bounds));
  }
}

}  // namespace rad
