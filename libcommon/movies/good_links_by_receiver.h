// The global solution's links indexed by receiver node, for the per-texel gather
// (good_link_gather.h), with the cluster light at each top's corners and the stores the
// movies' gathers fill for one another. Built once per solution by a baker and shared by every
// movie it makes (one per worker thread: not thread-safe while a gather is planned). What the
// stores hold does not depend on the order in which movies are made.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/movies/cluster_light_rays.h"
#include "libcommon/movies/near_shooter_cells.h"
#include "libcommon/radiosity/global_solution.h"
#include "libcommon/radiosity/visibility.h"

namespace rad {

// F(receiver node -> shooter part), integrated, of the links that no ray pair got through
// (GoodLinkGather::planWeights: the risk of their hidden share), static links only, by link
// row, shooter node and cell: the same for every movie of the receiver's top, so it is
// integrated once per run.
struct HiddenLink {
  uint32_t row, shooter, cell;
  bool operator==(const HiddenLink& o) const {
    return row == o.row && shooter == o.shooter && cell == o.cell;
  }
};
struct HiddenLinkHash {
  size_t operator()(const HiddenLink& k) const {
    return size_t(splitMix64(((uint64_t(k.row) << 32) | k.shooter) ^ splitMix64(k.cell)));
  }
};

struct GoodLinksByReceiver {
  explicit GoodLinksByReceiver(const GlobalSolution& solution);
  // The good links that gather (not refined, not of a bad pair): per node, its links are
  // rows[start[i] .. start[i + 1]), indices into solution.links.
  std::vector<uint32_t> start;
  std::vector<uint32_t> rows;
  // Every link that gathers, good or bad, in the same form (near shooters only: empty until
  // indexAllLinks).
  std::vector<uint32_t> allStart, allRows;
  void indexAllLinks(const GlobalSolution& solution);
  // The cluster irradiance at each top's corners, [(top * K + k) * 4 + c] (empty without
  // cluster links): the mean of topClusterIrradiance, weighted by exposed area, over the tops of
  // the same mesh node that share the corner's position and face the same way (normals within 8
  // degrees; the plain mean where all of them are covered). The gather interpolates it over the
  // top, so that a wall of tiles whose clusters link differently shades smoothly instead of in
  // steps of one value per tile. A top whose own value lies beyond kClusterBand of its corners'
  // mean keeps it but for band^2 / distance, continuous at the band (keepOwnClusterLight).
  std::vector<glm::vec3> clusterCorners;
  // Per top, its planar surface (planar_surfaces.h): the seed of the shooter points of the
  // per-texel visibility, so that coplanar receivers take the same points.
  std::vector<uint32_t> surfaceOfTop;

  // The stores the movies' gathers fill for one another.
  NearShooterStore nearShooters;  // near_shooter_cells.h
  std::unordered_map<HiddenLink, double, HiddenLinkHash> hiddenFormFactor;
  ClusterLightStore clusterLight;  // cluster_light_rays.h

 private:
  void smoothClusterIrradiance(const GlobalSolution& solution);
  void keepOwnClusterLight(const GlobalSolution& solution);
  // How far (relative) a top's own cluster light may lie from its corners' mean and still be
  // smoothed over (keepOwnClusterLight): about the spread of the cluster links' visibility
  // estimates across a wall, so that walls stay continuous while a top linked differently from
  // its neighbours keeps its own light ("Scale, at `7cf6652`: where clusters and all pairs
  // part, and two fixes in rad-movies' gather" in docs/results.md).
  static constexpr double kClusterBand = 0.1;
};

}  // namespace rad
