// The animated scene's triangles as rad-global's, rad-movies' and rad-compose's shadow rays see
// them (SceneVisibility): the static geometry once, each moving mesh node an instance moved to
// the time asked. Built on visibility.h's VisibilityScene.
#pragma once

#include <memory>
#include <utility>
#include <vector>

#include "libcommon/radiosity/visibility.h"
#include "libcommon/scene/patch_hierarchy.h"
#include "libcommon/scene/scene.h"

namespace rad {

// The scene's triangles for visibility: mesh nodes static over [t0, t1] in the static BVH in
// world space, each dynamic mesh node an instance whose transform setTime() updates. Every
// triangle's surface id is its top-level patch index.
//
// Split (rad-movies' gather): the static triangles and the dynamic instances as two scenes,
// staticPart() and movingPart(), so that rays are cast against the static blockers once per
// movie and against the moving ones per key (paper §5); a ray is open when both leave it open,
// exactly the combined scene's answer. visibility() is then the static part.
class SceneVisibility {
 public:
  SceneVisibility(const Scene& scene, const PatchHierarchy& hierarchy, double t0, double t1,
                  bool split = false);
  void setTime(double t);  // sets the instance transforms and commits
  const VisibilityScene& visibility() const { return *vis_; }
  const VisibilityScene& staticPart() const { return *vis_; }
  const VisibilityScene& movingPart() const { return moving_ ? *moving_ : *vis_; }
  int dynamicNodeCount() const { return int(instances_.size()); }

 private:
  const Scene& scene_;
  std::unique_ptr<VisibilityScene> vis_;
  std::unique_ptr<VisibilityScene> moving_;     // split: the instances alone
  std::vector<std::pair<int, int>> instances_;  // (mesh node, instance id)
};

}  // namespace rad
