// Edge and interior pixels of a frame (docs/design.md §10.3): where the image crosses a
// geometric edge, as the item buffer sees it. A pixel-centre renderer and its reference can
// disagree there by a whole surface's radiance, so the figure is reported apart at edges and
// inside surfaces, and the structured error (§10.4) keeps away from edges.
#pragma once

#include <cstdint>
#include <vector>

#include "libcommon/reference/frame_surfaces.h"
#include "libcommon/reference/image_difference.h"

namespace rad {

// The regions of ErrorFigures::regions, in this order.
enum PixelRegion : int { kEdgeRegion = 0, kInteriorRegion = 1, kBackgroundRegion = 2 };
constexpr int kPixelRegionCount = 3;
const char* pixelRegionName(int region);  // "edge", "interior", "background"

struct EdgePixels {
  int width = 0, height = 0;
  // Row-major, 1 where the pixel is an edge pixel: one of its 8 neighbours in the image shows
  // another surface (a top-level patch that is not FrameSurfaces::sameSurface with its own) or
  // the background while it shows a surface, or a surface while it shows the background. The
  // image's border is no edge. A seam between coplanar patches of one material is no edge.
  std::vector<uint8_t> edge;
  std::vector<uint8_t> background;  // 1 where the pixel shows nothing

  bool isEdge(int x, int y) const { return edge[size_t(y) * size_t(width) + size_t(x)] != 0; }
  // PixelGroups for measureError's regions: kEdgeRegion, kInteriorRegion (a surface, no edge),
  // kBackgroundRegion (background, no edge).
  PixelGroups regions() const;
  // 1 where no edge pixel is within Chebyshev distance clearance - 1 (the pixel's
  // (2 clearance - 1)^2 neighbourhood holds no edge pixel), i.e. at least `clearance` pixels
  // from every edge pixel.
  std::vector<uint8_t> clearOfEdges(int clearance) const;
};

EdgePixels findEdgePixels(const FrameSurfaces& surfaces);

}  // namespace rad
