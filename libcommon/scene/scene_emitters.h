// The scene's lights, made in one place (the light seam, emitter.h): every stage that asks which
// things emit asks this list.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "libcommon/scene/emitter.h"
#include "libcommon/scene/scene.h"

namespace rad {

class SceneEmitters {
 public:
  // One EmissivePolygonEmitter per polygon of `tops` whose material emits (Scene::emits), in the
  // order of `tops`; Emitter::top() indexes `tops` (Scene::inputPolygons(), or a patch
  // hierarchy's tops). Then one PunctualLightEmitter per Scene::lightNodes(), in node order
  // (top() -1). `scene` must outlive the list; `tops` is copied where needed.
  SceneEmitters(const Scene& scene, const std::vector<InputPolygon>& tops);

  std::size_t size() const { return emitters_.size(); }
  bool empty() const { return emitters_.empty(); }
  const Emitter& operator[](std::size_t i) const { return *emitters_[i]; }
  // The index into this list of the emitter that top-level patch `top` is, or -1 (not a light,
  // or out of range).
  int indexOfTop(int top) const {
    return top >= 0 && std::size_t(top) < ofTop_.size() ? ofTop_[std::size_t(top)] : -1;
  }
  // Whether top-level patch `top` is a light.
  bool topEmits(int top) const { return indexOfTop(top) >= 0; }
  // The indices into this list of the punctual lights (no patch, area 0), ascending.
  const std::vector<int>& lamps() const { return lamps_; }

 private:
  std::vector<std::unique_ptr<Emitter>> emitters_;
  std::vector<int> ofTop_;  // per top: index into emitters_, or -1
  std::vector<int> lamps_;  // indices of the punctual lights
};

}  // namespace rad
