// The scene's list of lights (contract in scene_emitters.h).
#include "libcommon/scene/scene_emitters.h"

#include "libcommon/scene/emission_texture.h"
#include "libcommon/scene/emissive_polygon_emitter.h"

namespace rad {

SceneEmitters::SceneEmitters(const Scene& scene, const std::vector<InputPolygon>& tops)
    : ofTop_(tops.size(), -1) {
  for (std::size_t t = 0; t < tops.size(); ++t) {
    if (!scene.emits(tops[t])) continue;
    ofTop_[t] = int(emitters_.size());
    emitters_.push_back(std::make_unique<EmissivePolygonEmitter>(scene, tops[t], int(t),
                                                                 meanEmissionOver(scene, tops[t])));
  }
}

}  // namespace rad
