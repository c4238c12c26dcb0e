// The key-time solver's exposure: which of a node's ray start points are covered, and the share
// that is not (a patch's covered part left out). See key_time_solver.h.
#include "libcommon/radiosity/key_time_solver.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "libcommon/radiosity/cosine_rays.h"
#include "libcommon/radiosity/visibility.h"

namespace rad {

// Exposure (the darkening at contacts): a box standing on the floor covers part of the floor's
// patches, whose links' shadow rays then start under the box and are blocked, so the area-averaged
// H and B of a patch straddling the box's footprint mix the lit part with the dark covered one; the
// camera sees only the lit part, and the ceiling and walls that gather from that patch see only its
// lit part too, so the mix darkens every surface of a room with boxes on its floor. A node's
// exposure e is the fraction of its ray start points (samplePoints, the same for all its links)
// that are not covered: a point is covered when it lies in a contact gap (inContact) or when a
// cosine-distributed ray from it first meets the back of a one-sided surface (the inside of a
// solid, the back of a wall) or a face of a closed solid from behind its outward normal, whatever
// its material's doubleSided says (closed_solid.h: Blender exports every material doubleSided). The
// gather divides a node's links' irradiance by e, so B and H are those of the exposed part, and a
// parent pulls its children's B weighted by exposed area. That holds when the covered points' ray
// pairs are the ones removed, so the links' visibility counts those pairs as blocked without
// casting them (evaluateLink, coveredPoints_): a shadow ray skips the first and last
// kSegmentEpsilon of its length, and from a board's face 20 micrometres from the next board's it
// passes that board, whose far side the exposure's shorter ray meets. The link then read V = 1 at e
// = 1/16, F V / e = 16 (issue 58: the solve diverged without the closed-room rows, and was far too
// bright at the link bound).
void KeyTimeSolver::computeExposures() {
  const size_t N = size_t(h_.size());
  exposure_.resize(N, -1.0);
  coveredPoints_.resize(N, 0);
  std::vector<int> todo;
  for (size_t i = 0; i < N; ++i)
    if (exposure_[i] < 0.0 && s_.inTree(int(i), h_)) todo.push_back(int(i));
  tbb::parallel_for(size_t(0), todo.size(), [&](size_t k) { expose(todo[k]); });
}

void KeyTimeSolver::exposeReceivers(size_t begin, size_t end) {
  const size_t N = size_t(h_.size());
  exposure_.resize(N, -1.0);
  coveredPoints_.resize(N, 0);
  std::vector<int> todo;
  for (size_t li = begin; li < end; ++li)
    if (exposure_[size_t(s_.links[li].receiver)] < 0.0) todo.push_back(s_.links[li].receiver);
  tbb::parallel_sort(todo.begin(), todo.end());
  todo.erase(std::unique(todo.begin(), todo.end()), todo.end());
  tbb::parallel_for(size_t(0), todo.size(), [&](size_t k) { expose(todo[k]); });
}

void KeyTimeSolver::expose(int i) {
  exposure_[size_t(i)] = 1.0;
  coveredPoints_[size_t(i)] = 0;
  if (!input_.visibility) return;
  const PatchNode& n = h_.node(i);
  const Polygon& P = s_.world[size_t(i)];
  const glm::dvec3 normal = P.normal();
  if (normal == glm::dvec3(0.0)) return;
  const CosineRays direction(normal);
  const std::vector<glm::dvec3> points =
      VisibilityScene::samplePoints(P, opt_.rays, receiverSeed(n.id));
  const uint64_t seed = splitMix64(receiverSeed(n.id));
  const double size = polygonSize(P);
  // Undecided rays (a front and a back at one distance: a partition flush with the ceiling,
  // a sheet of two back-to-back patches) go with the majority of the decided ones.
  enum : uint8_t { kExposed, kInside, kUndecided };
  std::vector<uint8_t> state(points.size(), kExposed);
  int exposed = 0, inside = 0, undecided = 0;
  for (size_t k = 0; k < points.size(); ++k) {
    if (inContact(points[k], normal, n.id.top)) {
      state[k] = kInside;
      ++inside;
      continue;
    }
    const glm::dvec3 d = direction(seed, k) * size;  // firstHit's tnear is relative to |d|
    const RayStart r = rayStart(*input_.visibility, points[k], d, n.id.top, [&](uint32_t hit) {
      return hit < uint32_t(h_.topCount()) &&
             surfaces_[hit].entersFromInside(s_.world[hit].normal(), d);
    });
    state[k] = r == RayStart::kOutside ? kExposed : r == RayStart::kInside ? kInside : kUndecided;
    (r == RayStart::kOutside ? exposed : r == RayStart::kInside ? inside : undecided) += 1;
  }
  const bool undecidedInside = inside > exposed;
  if (undecidedInside)
    inside += undecided;
  else
    exposed += undecided;
  uint64_t covered = 0;
  for (size_t k = 0; k < std::min(points.size(), size_t(VisibilityScene::kMaxRecordedPairs)); ++k)
    if (state[k] == kInside || (state[k] == kUndecided && undecidedInside))
      covered |= uint64_t(1) << k;
  coveredPoints_[size_t(i)] = covered;
  exposure_[size_t(i)] = points.empty() ? 1.0 : double(exposed) / double(points.size());
}

// A point lies in a contact gap when, along its normal and nearer than the shadow rays resolve
// (contactDistance_), it first meets the back of a one-sided surface (it is inside a solid) or the
// front of a surface parallel to it that faces it and whose plane it is strictly in front of: the
// face of a board 20 micrometres from its neighbour's, a box's bottom hovering over the floor.
// Light reaches such a gap only through its rim. A surface within rounding of the point's own plane
// is not a gap: two one-sided patches back to back on one plane are a sheet, each side seen from
// its own, and whether one lies on the other is left to the cosine ray (the next surface behind:
// the strip's top over a board, seen from the board, is the inside of the strip).
bool KeyTimeSolver::inContact(const glm::dvec3& x, const glm::dvec3& normal, uint32_t top) const {
  // Single precision holds a coordinate to 6e-8 of its magnitude, and Embree's hit distance to a
  // few of its units: 1e-6 of the coordinates is within rounding of x's plane.
  const double rounding =
      kContactRounding * std::max({std::abs(x.x), std::abs(x.y), std::abs(x.z), 1e-3});
  if (!(contactDistance_ > rounding)) return false;
  const VisibilityScene::Hit h =
      input_.visibility->nearestHit(x, normal, top, top, rounding, contactDistance_);
  if (h.surface == VisibilityScene::kNoSurface || h.surface >= uint32_t(h_.topCount()))
    return false;
  const Polygon& S = s_.world[h.surface];
  const SurfaceProperties& surface = surfaces_[h.surface];
  // Either of a closed solid's two copies of a face gives the same answer (closed_solid.h).
  const glm::dvec3 m = surface.outwardNormal(S.normal());
  if (glm::dot(m, normal) > 0.0) return surface.boundsSolid();  // a back: inside
  return glm::dot(m, normal) < -kContactParallel && glm::dot(m, x - S.v[0]) > rounding;
}

}  // namespace rad
