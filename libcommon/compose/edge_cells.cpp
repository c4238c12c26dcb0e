// The edge cells of a frame's sample grid. Contract and reasons in edge_cells.h.
#include "libcommon/compose/edge_cells.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "libcommon/compose/cell_coverage.h"
#include "libcommon/core/error.h"
#include "libcommon/gl/item_buffer.h"

namespace rad {
namespace {

struct ProjectedTop {
  std::array<glm::dvec2, 5> v{};
  int count = 0;  // 0: not seen, or nothing of it beyond the near plane
};

// A top's polygon clipped to the near plane (a perspective camera; what the rasteriser can
// show), in pixel coordinates.
ProjectedTop projectTop(const Polygon& world, const CameraView& view, ImageSize image) {
  ProjectedTop pt;
  std::array<glm::dvec3, 5> front{};
  int m = 0;
  if (view.lens.perspective) {
    const glm::dvec3 forward = -glm::dvec3(view.worldFromCamera[2]);
    clipToFront(world.v.data(), size_t(world.count), forward, view.eye(), view.lens.znear,
                [&](const glm::dvec3& x) {
                  if (m < 5) front[size_t(m++)] = x;
                });
  } else {
    for (; m < world.count; ++m) front[size_t(m)] = world.v[size_t(m)];
  }
  if (m < 3) return pt;
  for (int k = 0; k < m; ++k) {
    const ProjectedPoint q = projectToPixel(view, image, front[size_t(k)]);
    if (!q.inFront) return pt;
    pt.v[size_t(k)] = q.pixel;
  }
  pt.count = m;
  return pt;
}

double luminanceOf(const float* rgb) {
  return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
}

// Distance along the sample's ray line (line(), not unit) to the plane of top `t`.
double planeDistance(const EdgeCellInputs& in, int t, const glm::dvec3& o, const glm::dvec3& d) {
  const double denom = glm::dot(in.normals[size_t(t)], d);
  if (std::abs(denom) < 1e-300) return HUGE_VAL;
  return glm::dot(in.normals[size_t(t)], in.world[size_t(t)].v[0] - o) / denom;
}

// The edge cell of shaded sample p, into e; false when p is no edge cell, or its other side is
// not shaded, or the outline's polygon could not be projected.
bool edgeCellAt(const EdgeCellInputs& in, const std::vector<ProjectedTop>& projected, size_t p,
                EdgeCell& e) {
  const ImageSize g = in.grid.size();
  const int i = int(p % size_t(g.width)), j = int(p / size_t(g.width));
  const uint32_t a = in.ids[p];
  const float* La = in.sampleRgb + 3 * p;
  // The other side: the shaded 4-neighbour of another item with the largest luminance step.
  size_t q = in.ids.size();
  double best = -1.0;
  for (const auto& [di, dj] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
    if (i + di < 0 || i + di >= g.width || j + dj < 0 || j + dj >= g.height) continue;
    const size_t r = size_t(j + dj) * g.width + size_t(i + di);
    if (in.ids[r] == a || !in.shaded[r]) continue;
    const double step = std::abs(luminanceOf(in.sampleRgb + 3 * r) - luminanceOf(La));
    if (step > best) best = step, q = r;
  }
  if (q == in.ids.size()) return false;
  const double Ya = luminanceOf(La), Yb = luminanceOf(in.sampleRgb + 3 * q);
  if (best < in.minContrast * std::max(Ya, Yb)) return false;
  const uint32_t b = in.ids[q];
  const glm::dvec2 centre = in.grid.position(i, j);
  // Whose outline the boundary is: a's unless b is in front of a's plane at the sample.
  bool byOther = a == kNoItem;
  if (a != kNoItem && b != kNoItem) {
    glm::dvec3 o, d;
    in.rays.line(centre, o, d);
    const double sa = planeDistance(in, int(a - 1), o, d), sb = planeDistance(in, int(b - 1), o, d);
    byOther = sb > 0.0 && sb < sa * (1.0 - 1e-7);
  }
  const ProjectedTop& outline = projected[(byOther ? b : a) - 1];
  if (outline.count == 0) return false;
  const CellCoverage cov =
      polygonCellCoverage(outline.v.data(), outline.count, centre, 0.5 / in.grid.perAxis);
  e.sample = p;
  if (byOther) {
    // a has the rest of the cell, whose centroid balances b's about the centre.
    const double rest = 1.0 - cov.fraction;
    e.coverage = float(rest);
    const glm::dvec2 d = rest > 1e-12 ? -cov.fraction * cov.centroid / rest : glm::dvec2(0.0);
    e.dx = float(d.x), e.dy = float(d.y);
  } else {
    e.coverage = float(cov.fraction);
    e.dx = float(cov.centroid.x), e.dy = float(cov.centroid.y);
  }
  const float* Lb = in.sampleRgb + 3 * q;
  for (int ch = 0; ch < 3; ++ch) e.step[ch] = La[ch] - Lb[ch];
  return true;
}

}  // namespace

std::vector<EdgeCell> findEdgeCells(const EdgeCellInputs& in,
                                    const std::vector<uint8_t>& candidates) {
  const ImageSize g = in.grid.size();
  const size_t n = size_t(g.pixelCount());
  if (candidates.size() != n)
    throw Error(ExitCode::kInternal, "compose", "edge candidates are not the sample grid's size");
  // The shaded candidates, in sample order.
  std::vector<size_t> cells;
  for (size_t p = 0; p < n; ++p) {
    const void* next = std::memchr(&candidates[p], 1, n - p);
    if (next == nullptr) break;
    p = size_t(static_cast<const uint8_t*>(next) - candidates.data());
    if (in.shaded[p]) cells.push_back(p);
  }
  // The tops seen (placed at the frame's time), projected once.
  std::vector<ProjectedTop> projected(in.world.size());
  for (size_t t = 0; t < projected.size(); ++t)
    if (in.world[t].count >= 3) projected[t] = projectTop(in.world[t], in.view, in.grid.image);
  std::vector<EdgeCell> found(cells.size());
  std::vector<uint8_t> isCell(cells.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, cells.size(), 512),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t c = r.begin(); c < r.end(); ++c)
                        isCell[c] = edgeCellAt(in, projected, cells[c], found[c]);
                    });
  std::vector<EdgeCell> out;
  for (size_t c = 0; c < cells.size(); ++c)
    if (isCell[c]) out.push_back(found[c]);
  return out;
}

}  // namespace rad
