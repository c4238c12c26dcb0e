// Near shooters (rad-movies --near-shooter-levels L > 0): a shooter part of the gather
// (good_link_gather.h) that is a leaf and still larger than the gather's shooter ratio times
// its distance to the receiver is split further into the cells of its virtual quadtree, down
// to L levels, each carrying its own radiosity
//
//   B(y) = E + \rho (H_c + \sum_{l = (p <- s), p \in chain(q)} B_s F(y -> s) V(y, s))
//
// re-gathered at the cell centre y from every link of the leaf's chain (good and bad: the
// lights' links too), with V(y, s) from the gather's rays where the link is partly occluded,
// and 0 in a cell covered by a touching solid (solid_contact.h).
//
// Why: a leaf's B is its chain's gather, and an ancestor's link carries the visibility
// averaged over the ancestor, so a leaf half in a blocker's shadow passes on the mean of its
// lit and shadowed parts; a receiver that sees the leaf at close range (the foot of a box
// beside a shadowed floor strip) gathered that mean and came out too bright ("The final
// setting re-gathers its near shooters" in docs/results.md). A cell's value depends only on the
// leaf and the key, so it is made once per rad-movies run and kept in a NearShooterStore.
// Costly: the final setting's only.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "libcommon/scene/geometry.h"

namespace rad {

// A cell of a near leaf shooter is its path in the leaf's virtual quadtree: a leading 1 bit,
// then two bits per level (as PatchId::path); 1 is the whole leaf. Its level: 0 for the leaf.
inline int cellLevel(uint32_t cell) {
  return (31 - __builtin_clz(cell)) / 2;
}

// The 4^levels cells of polygon p in path order (subdividePolygon's children at each level).
std::vector<Polygon> cellsOf(const Polygon& p, int levels);

// The polygon of `cell` (cellLevel's encoding) within the leaf's polygon.
Polygon cellPolygon(const Polygon& leaf, uint32_t cell);

// What the near-shooter re-gather keeps for a whole run (GoodLinksByReceiver::nearShooters),
// shared by the movies one baker makes. The values stored do not depend on which movie made
// them first: movies in any order and any shard split come out bit-identical.
struct NearShooterStore {
  // The re-gathered radiosity of each near leaf shooter's cells, keyed by leaf * keyCount +
  // key: per finest cell (path order), its B's channel sum over the leaf's (0: covered).
  std::unordered_map<uint64_t, std::vector<float>> cells;
  // Per static near leaf: F(y_i -> s) V(y_i, s) of its chain's links that do not change (both
  // ends static, one F·V sample over the keys: no moving node crossed their shaft), per cell,
  // made at its first key and kept for the others, which then only sum B_s times them.
  struct FixedTerms {
    std::vector<uint32_t> rows;  // link rows, in the chain's order
    std::vector<float> factor;   // [row index * cells + cell]
  };
  std::unordered_map<uint32_t, FixedTerms> fixed;
};

}  // namespace rad
