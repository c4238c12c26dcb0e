// Which sample cells an edge crosses, and how (docs/design.md §6.4 "edge cells";
// footprint_filter.h, EdgeCell; cell_coverage.h): the geometry the composer knows, so that the
// pixel filter can place every edge exactly instead of to 1/s pixel.
//
// A cell is an edge cell when its sample shows another item than one of its 4 neighbours. Its
// other side is the neighbour of the largest luminance step (the one that matters most when a
// cell meets three items). The boundary in the cell is the outline of whichever polygon is in
// front there, projected: the sample's own surface a when the other side b is the background or
// its plane lies behind a's along the sample's ray (a's silhouette over b, or a crease), else
// b's (b's silhouette over a): then a has the cell less b's part. The other side's radiance is
// its neighbour sample's. Only shaded samples take part (needed()), so no sample is added and
// rad-intervals' coverage still holds. A polygon with a vertex behind the eye, or a cell whose
// other side is not shaded, keeps its sample's value. Deterministic: each cell is computed
// from the item buffer and the shaded samples alone.
#pragma once

#include <cstdint>
#include <vector>

#include "libcommon/compose/footprint_filter.h"
#include "libcommon/scene/camera_projection.h"
#include "libcommon/scene/geometry.h"
#include "libcommon/scene/sample_grid.h"

namespace rad {

struct EdgeCellInputs {
  const SampleGrid& grid;
  const std::vector<uint32_t>& ids;    // per grid sample: top-level index + 1, 0 background
  const std::vector<uint8_t>& shaded;  // per grid sample: 1 where sampleRgb holds its value
  const float* sampleRgb;              // 3 a grid sample
  const std::vector<Polygon>& world;   // per top at the frame's time; count 0: not seen
  const std::vector<glm::dvec3>& normals;
  const CameraView& view;
  const PrimaryRays& rays;
  // A cell whose luminance step is less than this share of its brighter side keeps its
  // sample's value: the 1/s px placement of a small step is a small error, and most of a
  // frame's edge cells are seams and creases of little contrast. 0: every edge cell.
  double minContrast = 0.0;
};

// The edge cells among the samples marked 1 in `candidates` (one byte a grid sample; a sample
// that is no edge cell is skipped), in increasing sample order.
std::vector<EdgeCell> findEdgeCells(const EdgeCellInputs& in,
                                    const std::vector<uint8_t>& candidates);

}  // namespace rad
