// rad-diff: item buffers to pixel groups and frame surfaces.
#include "tools/rad-diff/item_surfaces.h"

#include <map>

#include "formats/gltf_scene.h"
#include "formats/item_buffer_exr.h"

namespace rad::diff {

ItemSurfaces::ItemSurfaces(const std::string& scenePath)
    : scene_(readGltfScene(scenePath)), tops_(scene_.inputPolygons()) {
  std::map<std::pair<int, int>, int> groupOf;  // (mesh node, material)
  for (const InputPolygon& p : tops_) {
    auto [it, fresh] = groupOf.emplace(std::pair(p.node, p.material), int(names_.size()));
    if (fresh) names_.push_back(surfaceName(scene_, p));
    groupOfTop_.push_back(it->second);
  }
}

ItemSurfaces::Frame ItemSurfaces::load(const std::string& itemsPath, const FloatImage& like) const {
  const ItemBuffer items = readItemBufferExr(itemsPath);
  const double time = readItemBufferTime(itemsPath);
  Frame f;
  f.surfaces = frameSurfaces(items, scene_, tops_, time, like.width, like.height, itemsPath);
  f.groups.count = int(names_.size());
  f.groups.ofPixel.assign(items.id.size(), -1);
  for (size_t p = 0; p < items.id.size(); ++p) {
    const int top = f.surfaces.patchOfPixel[p];
    if (top >= 0) f.groups.ofPixel[p] = groupOfTop_[size_t(top)];
  }
  return f;
}

}  // namespace rad::diff
