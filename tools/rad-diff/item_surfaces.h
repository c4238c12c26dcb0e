// rad-diff's item buffers (--surfaces / --seams ITEMS --scene SCENE): per frame, the pixel
// groups of the per-surface figures (glTF node and material) and the surfaces of the figures
// that need the geometry (docs/design.md §10.3–§10.5).
#pragma once

#include <string>
#include <vector>

#include "libcommon/core/float_image.h"
#include "libcommon/reference/frame_surfaces.h"
#include "libcommon/reference/image_difference.h"
#include "libcommon/scene/scene.h"

namespace rad::diff {

class ItemSurfaces {
 public:
  explicit ItemSurfaces(const std::string& scenePath);

  struct Frame {
    PixelGroups groups;      // by glTF node and material: names()[group]
    FrameSurfaces surfaces;  // refers to this object's scene, which must outlive it
  };
  // One frame's item buffer, placed at its rad.time. Throws rad::inputError(itemsPath) when
  // it is not an item buffer or not of `like`'s size.
  Frame load(const std::string& itemsPath, const FloatImage& like) const;
  const std::vector<std::string>& names() const { return names_; }  // per group
  // "node (material)" of a top-level patch.
  std::string patchName(int patch) const { return surfaceName(scene_, tops_[size_t(patch)]); }

 private:
  Scene scene_;
  std::vector<InputPolygon> tops_;
  std::vector<int> groupOfTop_;  // per top-level patch
  std::vector<std::string> names_;
};

}  // namespace rad::diff
