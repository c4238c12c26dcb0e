// What an item buffer says about a frame's pixels, for the error figures that need the geometry
// (docs/design.md §10.3 edge and interior pixels, §10.4 structured error, §10.5 seams): the
// top-level patch seen at each pixel, and which top-level patches form one smooth surface.
//
// Two top-level patches are one surface when they are coplanar and of the same material: their
// world-space planes (placed at the item buffer's time, so moving nodes count where they are)
// have normals within kCoplanarDegrees and each one's centroid lies within kPlaneOffset times
// the larger patch's diameter of the other's plane. Whether they share an edge of the mesh is
// not checked: the figures only ask it of patches seen in neighbouring pixels, which on one
// plane touch or overlap within a pixel's footprint (a T-junction shares no whole edge, yet its
// radiance must be continuous all the same).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "libcommon/gl/item_buffer.h"

namespace rad {

class Scene;
struct InputPolygon;

struct FrameSurfaces {
  int width = 0, height = 0;
  // Row-major, row 0 at the top: the top-level patch (index into Scene::inputPolygons()) seen
  // at each pixel; -1 where nothing is (background).
  std::vector<int> patchOfPixel;
  // Whether two top-level patches are one smooth surface (true for a == b). Symmetric.
  std::function<bool(int a, int b)> sameSurface;
  // Whether a top-level patch's material emits (its pixels are a light, never a wall).
  std::function<bool(int patch)> emits;
  // "node (material)" of a top-level patch (surfaceName), for reports.
  std::function<std::string(int patch)> nameOf;

  bool empty() const { return patchOfPixel.empty(); }
  int patchAt(int x, int y) const { return patchOfPixel[size_t(y) * size_t(width) + size_t(x)]; }
};

// Coplanarity tolerances of FrameSurfaces::sameSurface: generous against the float rounding of
// a file's vertices, far below the angle between two faces of any modelled object.
constexpr double kCoplanarDegrees = 1.0;
constexpr double kPlaneOffset = 1e-3;

// The top-level patch of an item id: ids are dense node indices + 1 of rad-intervals' regular
// subdivision (formats/texture_intervals.md "Item buffers"): the top-level patches 0..T-1, then
// four children per node in order, so node j >= T has parent (j - T) / 4. -1 for kNoItem.
int topPatchOfItem(uint32_t id, int topCount);

// "node (material)", by glTF name where there is one.
std::string surfaceName(const Scene& scene, const InputPolygon& patch);

// The surfaces of one frame from its item buffer. `tops` is scene.inputPolygons() (the patches
// the item ids count); `time` the item buffer's (rad.time, seconds). The result's functions
// refer to `scene` and `tops`, which must outlive it. Throws rad::inputError(itemsWhere) when
// the buffer is not width x height.
FrameSurfaces frameSurfaces(const ItemBuffer& items, const Scene& scene,
                            const std::vector<InputPolygon>& tops, double time, int width,
                            int height, const std::string& itemsWhere);

}  // namespace rad
