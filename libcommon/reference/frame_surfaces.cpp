// docs/design.md §10.3–§10.5: the patches an item buffer saw, and which of them are one surface.
#include "libcommon/reference/frame_surfaces.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include "libcommon/core/error.h"
#include "libcommon/scene/scene.h"

namespace rad {

int topPatchOfItem(uint32_t id, int topCount) {
  if (id == kNoItem || topCount <= 0) return -1;
  uint64_t node = uint64_t(id) - 1;
  const uint64_t T = uint64_t(topCount);
  while (node >= T) node = (node - T) / 4;
  return int(node);
}

std::string surfaceName(const Scene& s, const InputPolygon& p) {
  const std::string node =
      p.node >= 0 && p.node < int(s.nodes.size()) && !s.nodes[size_t(p.node)].name.empty()
          ? s.nodes[size_t(p.node)].name
          : "node " + std::to_string(p.node);
  const std::string material =
      p.material < 0 ? "default"
      : p.material < int(s.materials.size()) && !s.materials[size_t(p.material)].name.empty()
          ? s.materials[size_t(p.material)].name
          : "material " + std::to_string(p.material);
  return node + " (" + material + ")";
}

namespace {

// The world-space plane of every top-level patch at one time.
struct PatchPlanes {
  const Scene* scene = nullptr;
  const std::vector<InputPolygon>* tops = nullptr;
  std::vector<glm::dvec3> normal, centroid;
  std::vector<double> diameter;
  double minCosine = std::cos(kCoplanarDegrees * M_PI / 180.0);

  PatchPlanes(const Scene& s, const std::vector<InputPolygon>& t, double time)
      : scene(&s), tops(&t) {
    std::map<int, glm::dmat4> toWorld;  // per mesh node
    for (const InputPolygon& p : t) {
      auto it = toWorld.find(p.node);
      if (it == toWorld.end()) it = toWorld.emplace(p.node, s.worldTransform(p.node, time)).first;
      const Polygon w = p.local.transformed(it->second);
      normal.push_back(w.normal());
      centroid.push_back(w.centroid());
      double d = 0.0;
      for (int i = 0; i < w.count; ++i)
        for (int j = i + 1; j < w.count; ++j) d = std::max(d, glm::length(w.v[i] - w.v[j]));
      diameter.push_back(d);
    }
  }

  bool sameSurface(int a, int b) const {
    if (a == b) return true;
    const InputPolygon &pa = (*tops)[size_t(a)], &pb = (*tops)[size_t(b)];
    if (pa.material != pb.material) return false;
    const glm::dvec3 &na = normal[size_t(a)], &nb = normal[size_t(b)];
    if (glm::dot(na, nb) < minCosine) return false;
    const glm::dvec3 offset = centroid[size_t(b)] - centroid[size_t(a)];
    const double tolerance = kPlaneOffset * std::max(diameter[size_t(a)], diameter[size_t(b)]);
    return std::abs(glm::dot(na, offset)) <= tolerance &&
           std::abs(glm::dot(nb, offset)) <= tolerance;
  }
};

}  // namespace

FrameSurfaces frameSurfaces(const ItemBuffer& items, const Scene& scene,
                            const std::vector<InputPolygon>& tops, double time, int width,
                            int height, const std::string& itemsWhere) {
  if (items.width != width || items.height != height)
    throw inputError(itemsWhere, "item buffer is " + std::to_string(items.width) + "x" +
                                     std::to_string(items.height) + ", the images " +
                                     std::to_string(width) + "x" + std::to_string(height));
  FrameSurfaces f;
  f.width = width;
  f.height = height;
  const int T = int(tops.size());
  f.patchOfPixel.resize(items.id.size());
  for (size_t p = 0; p < items.id.size(); ++p) f.patchOfPixel[p] = topPatchOfItem(items.id[p], T);
  auto planes = std::make_shared<const PatchPlanes>(scene, tops, time);
  f.sameSurface = [planes](int a, int b) { return planes->sameSurface(a, b); };
  f.emits = [planes](int patch) { return planes->scene->emits((*planes->tops)[size_t(patch)]); };
  f.nameOf = [planes](int patch) {
    return surfaceName(*planes->scene, (*planes->tops)[size_t(patch)]);
  };
  return f;
}

}  // namespace rad
