// The cluster light per texel (rad-movies --cluster-visibility-rays): rad-global gathers the
// light of far surfaces through cluster links, one V per link shared by every member of the
// receiver, and stores one irradiance per top and key (GlobalSolution::topClusterIrradiance).
// Where a top is partly hidden from its far surfaces (a chair's seat under a desk, its back in
// the open) the camera sees its open parts, which the one value makes too dark. So a texel's
// cluster light is scaled by the open share of its rays to points on the top's far surfaces,
// over the mean of that share across the top's uncovered part: the top keeps rad-global's total
// and only its distribution over the texels changes ("Scale, at `6ee0935`/`9ea0a74`/`0c235b4`:
// the cluster light per texel" in docs/results.md).
//
// The far points of a top are the static tops that are neither shooters of its nodes' good
// links nor of its bad pairs (what it gathers itself), drawn by cos cos / d^4 from the top's
// centroid out of candidates drawn once per key from every static top by B A. The gather
// (GoodLinkGather::planClusterVisibility) casts the rays at the tiles' corner texels, once per
// movie against the static blockers at its first key, and interpolates in between. A moving
// receiver gets no per-texel cluster light (its rays would hold at one key only).
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/radiosity/global_solution.h"
#include "libcommon/scene/geometry.h"

namespace rad {

// What the cluster-light rays keep for a whole run (GoodLinksByReceiver::clusterLight), the
// same for every movie of a top; filled as the movies need it.
struct ClusterLightStore {
  // Per static top and global key (top * keyCount + key): the points on its far surfaces that
  // its texels' rays go to, and the mean open share of those rays over the top's uncovered part
  // (none: the top gets no per-texel cluster light).
  struct Rays {
    std::vector<glm::dvec3> points;
    double meanOpenShare = 0.0;
  };
  std::unordered_map<uint64_t, Rays> rays;
  // Per top: its world polygon (static tops only; empty until the first movie needs them) and
  // whether it moves anywhere in the solution's time range.
  std::vector<Polygon> staticTopWorld;
  std::vector<char> topMoves;
  // Per global key: kFarCandidates points on the static tops, the tops drawn by emitted and
  // reflected power B A (stratified) and each point area-uniform on its top, from which every
  // top's far points are drawn again by its own kernel. Drawing once for all tops, not from
  // every top for every top, keeps the cost linear in the number of tops.
  struct FarCandidate {
    glm::dvec3 point, normal;
    uint32_t top;
  };
  std::unordered_map<int, std::vector<FarCandidate>> farCandidates;
  static constexpr int kFarCandidates = 4096;
};

// The far candidates of global key `key` (ClusterLightStore::farCandidates), from the static
// tops of `store` (staticTopWorld and topMoves filled); empty when no static top has power.
// Deterministic: seeded by the key.
std::vector<ClusterLightStore::FarCandidate> drawFarCandidates(const GlobalSolution& solution,
                                                               const ClusterLightStore& store,
                                                               int key);

}  // namespace rad
