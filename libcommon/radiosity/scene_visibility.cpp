// The animated scene for shadow rays; see scene_visibility.h.
#include "libcommon/radiosity/scene_visibility.h"

#include <unordered_map>

namespace rad {

SceneVisibility::SceneVisibility(const Scene& scene, const PatchHierarchy& h, double t0, double t1,
                                 bool split)
    : scene_(scene) {
  auto addPolygon = [](std::vector<VisibilityTriangle>& out, const Polygon& p, uint32_t id) {
    out.push_back({{p.v[0], p.v[1], p.v[2]}, id});
    if (p.count == 4) out.push_back({{p.v[0], p.v[2], p.v[3]}, id});
  };
  std::vector<VisibilityTriangle> statics;
  std::vector<int> dynamicNodes;
  std::unordered_map<int, std::vector<VisibilityTriangle>> local;
  std::unordered_map<int, bool> dynamic;
  for (int i = 0; i < h.topCount(); ++i) {
    const InputPolygon& top = h.top(i);
    int node = top.node;
    auto d = dynamic.find(node);
    if (d == dynamic.end())
      d = dynamic.emplace(node, node >= 0 && scene.isDynamic(node, t0, t1)).first;
    if (d->second) {
      if (!local.count(node)) dynamicNodes.push_back(node);
      addPolygon(local[node], top.local, uint32_t(i));
    } else {
      glm::dmat4 m = node >= 0 ? scene.worldTransform(node, t0) : glm::dmat4(1.0);
      addPolygon(statics, top.local.transformed(m), uint32_t(i));
    }
  }
  vis_ = std::make_unique<VisibilityScene>(statics);
  if (split) moving_ = std::make_unique<VisibilityScene>(std::vector<VisibilityTriangle>());
  VisibilityScene& withInstances = moving_ ? *moving_ : *vis_;
  for (int node : dynamicNodes)
    instances_.emplace_back(node,
                            withInstances.addInstance(local[node], scene.worldTransform(node, t0)));
  vis_->commit();
  if (moving_) moving_->commit();
}

void SceneVisibility::setTime(double t) {
  VisibilityScene& withInstances = moving_ ? *moving_ : *vis_;
  for (auto& [node, id] : instances_)
    withInstances.setInstanceTransform(id, scene_.worldTransform(node, t));
  withInstances.commit();
}

}  // namespace rad
