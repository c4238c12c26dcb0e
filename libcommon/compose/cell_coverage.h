// How much of one sample's cell a projected polygon covers (docs/design.md §6.4 "edge cells"):
// rad-compose's grid places an edge between two samples to 1/s of a pixel, and a pixel beside a
// bright edge (a lamp's outline) is then off by a large share of the step. The cell of a sample
// is the square of side 1/s pixel around it; where an edge crosses it, the fraction of the cell
// on each side and that side's centroid let the filter weigh the two radiances by the area they
// really cover (footprint_filter.h, EdgeCell).
#pragma once

#include <glm/glm.hpp>

namespace rad {

struct CellCoverage {
  double fraction = 0.0;     // area of polygon ∩ cell over the cell's area, in [0, 1]
  glm::dvec2 centroid{0.0};  // that part's centroid minus the cell's centre, pixels
};

// The part of the axis-aligned square of half side `half` around `centre` covered by the
// polygon poly[0..count) (pixel coordinates; convex, either orientation, count <= 12). Exact to
// rounding: the square clipped by the half-plane of each edge that crosses it, then the
// shoelace area and centroid. A degenerate polygon covers nothing.
CellCoverage polygonCellCoverage(const glm::dvec2* poly, int count, glm::dvec2 centre, double half);

}  // namespace rad
