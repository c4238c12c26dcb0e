// The good layer of a texture movie as a per-texel gather over the global solution's good links
// (a "final gather", Lischinski, Tampieri, Greenberg 1992 §5; Smits, Arvo, Salesin 1994), in
// place of the paper's Gouraud interpolation of the vertex irradiance (§3.1).
//
// At texel centre x of a receiver whose union leaf chain (leaf and ancestors) is c(x), at key k,
//
//   G(x, k) = H_c(k) + \sum_{l = (p <- q) good, p \in c(x), active at k}  B_q(k) \, \bar V_l(k)
//   \, F(x \to q)
//
// with H_c(k) the irradiance the receiver's top gathers through rad-global's cluster links
// (GlobalSolution::topClusterIrradiance, linkhier 1.3; 0 in older files), averaged at the
// top's corners over the coplanar tops that share them and interpolated over the top
// (GoodLinksByReceiver::clusterCorners; the Gouraud layer's vertex values include it the same
// way, so both layers carry the same cluster light),
// F(x -> q) the exact point-to-polygon form factor at the texel, about its shading normal,
// and \bar V_l = V_l / e_p clamped to [0, 1]: the link's stored visibility (linkhier 1.2; older
// files: F·V / \bar F, the area-average form factor) over the receiver's exposure e_p (the share
// of it not covered by a touching solid, whose sample points count as occluded; rad-global
// divides its gather by it). The Gouraud layer spreads a receiver element's mean irradiance
// linearly over it; the point form factor follows what the element really sees: the darkening into
// a concave corner, the bright band next to a lit wall. For an unoccluded link the texel's sum is
// the exact form factor, so a closed room sums to 1 at every texel, not only per element.
//
// A link whose stored V is partial (0 < V < 1 at a key the movie needs), or 0 while the link is
// active (none of its ray pairs got through, yet it may be partly visible), takes its
// visibility per texel instead when its risk B_q F (1 - V) is at least --gather-partial-share s
// of what the texel gathers, or when it is among the smaller ones beyond the first that sum to
// 10 s (selectPartialLinks; a quarter of the rays then), V(x, q): --gather-rays shadow rays from
// x to points on the shooter part q (the same points for every texel), each weighted by the
// kernel and by the global solution's B at its end (pointVisibility), so that
//
//   term = B_q(k) F(x -> q) V(x, q)
//
// One V per receiver node stepped where two nodes whose links are occluded differently meet
// (4.3 % on the bundled scene's back wall); per texel the bundled scene went from 7.5 to 6.0 %
// RMSE / mean, and the B weights keep a double-sided lamp's gap from leaking (+0.1 %, against
// +8.7 % unweighted). Static blockers are cast once per movie, moving ones per key (§5).
//
// Cost: texels are planned in tiles of 8 x 8; a link whose shooter part is far from a tile
// (kTileFarRatio times its size) is evaluated at the tile's corners and interpolated
// bilinearly, so only near links cost a form factor per texel. A far partial link stays on the
// tile only while its V at the tile's middle texel is what the corners interpolate, within s of
// what the texel gathers (perTexelOnTiles).
//
// Near shooters (--near-shooter-levels L > 0, issue 15): a shooter part that is a leaf and still
// larger than shooterRatio times its distance to the receiver is split further into the cells
// of its virtual quadtree down to L levels, each carrying its own radiosity
//
//   B(y) = E + \rho (H_c + \sum_{l = (p <- s), p \in chain(q)} B_s F(y -> s) V(y, s))
//
// re-gathered at the cell centre y from every link of the leaf's chain (good and bad: the
// lights' links too), with V(y, s) from --gather-rays rays where the link is partly occluded
// (0 in a cell covered by a touching solid). A leaf's B is its chain's gather, and an
// ancestor's link carries the visibility averaged over the ancestor: the floor strip in front of
// the Cornell box's short box, in the box's shadow, took its ceiling light through 0/3.2 (V 0.17
// to 0.63 over a node 0.2 m across) and came out at B 0.023 where the movie's own gather (and
// the reference) has 0.015-0.017; the box front's foot, which sees that strip over half its
// hemisphere, was 31-60 % too bright. The estimate depends only on the leaf and the key, so it
// is made once per rad-movies run (GoodLinksByReceiver::nearShooterCells). Costly (the final
// setting only): at L = 2 the Cornell box's rad-movies 5.1 -> 16.0 s, the table's 12.8 -> 86.7 s.
//
// Between key times the gather is linear in t, as the Gouraud layer is. Coherence (§5): for a
// link whose two ends do not move during the movie, F(x -> q) is computed once per movie and
// kept (up to a memory budget); only B and \bar V change per key. A link with a moving end
// recomputes F at every movie key.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/intervals/movie_extent.h"
#include "libcommon/radiosity/global_solution.h"
#include "libcommon/radiosity/hierarchical_radiosity.h"
#include "libcommon/radiosity/scene_visibility.h"
#include "libcommon/scene/scene.h"

namespace rad {

// Where the ray from point p of top-level patch `top` (direction d) starts at time t: inside a
// touching solid (a box's foot on the floor: the first surface it meets is the back of a
// one-sided patch), outside, or undecided (a front and such a back at one distance; rayStart),
// as rad-global's exposure decides (exposureOf).
RayStart coveredBySolid(const VisibilityScene& blockers, const Scene& scene,
                        const PatchHierarchy& h, uint32_t top, const glm::dvec3& p,
                        const glm::dvec3& d, double t);

// Whether point p of top-level patch `top` (normal n) lies inside a touching solid at time t:
// the four rays 88 degrees from the normal, `size` long, all start inside or undecided
// (coveredBySolid), one at least inside. rad-movies' fill of covered texels and the near
// shooters' cells decide so.
bool insideSolid(const VisibilityScene& blockers, const Scene& scene, const PatchHierarchy& h,
                 uint32_t top, const glm::dvec3& p, const glm::dvec3& n, double size, double t);

// The good links that gather (not refined, not of a bad pair), grouped by receiver node: built
// once per solution, shared by every movie.
struct GoodLinksByReceiver {
  explicit GoodLinksByReceiver(const GlobalSolution& solution);
  std::vector<uint32_t> start;  // per node: its links are rows[start[i] .. start[i + 1])
  std::vector<uint32_t> rows;   // indices into solution.links
  // Near shooters: every link that gathers, good or bad, by receiver node (indexAllLinks), and
  // the re-gathered radiosity of each near leaf shooter's cells already made, keyed by
  // leaf * keyCount + key: per cell, its B's channel sum over the leaf's (0: covered).
  std::vector<uint32_t> allStart, allRows;
  std::unordered_map<uint64_t, std::vector<float>> nearShooterCells;
  // Per static near leaf: F(y_i -> s) V(y_i, s) of its chain's links that do not change (both
  // ends static, one F·V sample over the keys: no moving node crossed their shaft), per cell,
  // made at its first key and kept for the others, which then only sum B_s times them.
  struct FixedTerms {
    std::vector<uint32_t> rows;  // link rows, in the chain's order
    std::vector<float> factor;   // [row index * cells + cell]
  };
  std::unordered_map<uint32_t, FixedTerms> nearShooterFixed;
  // F(receiver node -> shooter part), integrated, of the links that no ray pair got through
  // (GoodLinkGather::planWeights: the risk of their hidden share), static links only, by link
  // row, shooter node and cell: the same for every movie of the receiver's top. The 10k-triangle
  // hall's movies had integrated 800,192 of them, 131,783 distinct, 6 % of rad-movies' time.
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
  std::unordered_map<HiddenLink, double, HiddenLinkHash> hiddenFormFactor;
  // Per static top and global key (top * keyCount + key): the points on its far surfaces that
  // its texels' cluster-light rays go to, and the mean open share of those rays over the top's
  // uncovered part (GoodLinkGather::planClusterVisibility); the same for every movie of the top
  // (none: the top gets no per-texel cluster light). And the static tops' world polygons
  // (empty until the first movie needs them; a moving top's is left empty).
  struct ClusterLightRays {
    std::vector<glm::dvec3> points;
    double meanOpenShare = 0.0;
  };
  std::unordered_map<uint64_t, ClusterLightRays> clusterLightRays;
  std::vector<Polygon> staticTopWorld;
  std::vector<char> topMoves;
  // Per global key: kFarCandidates points on the static tops, the tops drawn by emitted and
  // reflected power B A (stratified) and each point area-uniform on its top, from which every
  // top's far points are drawn again by its own kernel. Drawing from all tops for every top had
  // made the 100k-triangle hall's rad-movies 48 -> 140 s.
  struct FarCandidate {
    glm::dvec3 point, normal;
    uint32_t top;
  };
  std::unordered_map<int, std::vector<FarCandidate>> farCandidates;
  static constexpr int kFarCandidates = 4096;
  void indexAllLinks(const GlobalSolution& solution);
  // The cluster irradiance at each top's corners, [(top * K + k) * 4 + c] (empty without
  // cluster links): the mean of topClusterIrradiance, weighted by exposed area, over the tops of
  // the same mesh node that share the corner's position and face the same way (normals within 8
  // degrees; the plain mean where all of them are covered). The gather
  // interpolates it over the top, so that a wall of tiles whose clusters link differently shades
  // smoothly instead of in steps of one value per tile (the 10k hall's back wall). A top whose
  // own value lies beyond kClusterBand of its corners' mean keeps it but for the band
  // (keepOwnClusterLight).
  std::vector<glm::vec3> clusterCorners;

 private:
  void smoothClusterIrradiance(const GlobalSolution& solution);
  void keepOwnClusterLight(const GlobalSolution& solution);
  // How far (relative) a top's own cluster light may lie from its corners' mean and still be
  // smoothed over (keepOwnClusterLight). 10k hall, frame 48 against the all-pairs frames:
  // ceiling RMSE / mean 2.0 % smoothed, 1.0 % unsmoothed (0), 1.3 % at 0.1; walls 1.2, 1.4,
  // 1.3 %.
  static constexpr double kClusterBand = 0.1;
};

// The texels of one movie: their (u,v) in the receiver's top-level patch and their points in
// its local frame (MovieGeometry's, shared).
struct MovieTexels {
  const std::vector<glm::dvec2>& topUv;
  const std::vector<glm::dvec3>& localPoint;
  const std::vector<glm::dvec3>& localNormal;  // shading normals (shadingNormalAt)
  int width = 0, height = 0;
};

struct GoodLinkGatherStats {
  long links = 0;                       // link rows gathered, summed over movies
  long entries = 0;                     // (texel, near link) terms per key, summed over movies
  long cachedEntries = 0;               // of which F was computed once per movie
  long tileEntries = 0;                 // (tile, far link) terms, each 4 corner form factors
  long partialLinks = 0;                // links with V per texel (partly occluded)
  long partialLinksMovingBlockers = 0;  // of which rays also meet moving blockers per key
  long partialLinksFewRays = 0;         // of which small ones, a quarter of the rays each
  long partialTileLinksPerTexel = 0;    // (tile, far partial link) pairs taken per texel
  long nearShooterLeaves = 0;           // (leaf, key) re-gathered (--near-shooter-levels)
  double nearShooterSeconds = 0.0;      // their time, part of the good layer's
};

class GoodLinkGather {
 public:
  // Plans the gather of one movie: its links (each shooter split into the parts of its union
  // sub-tree larger than shooterRatio times their distance to the receiver; 0: no split), their
  // visibility at the global keys it needs and, within `cacheBytes`, the per-texel form factors
  // of the links whose ends do not move.
  GoodLinkGather(const Scene& scene, const GlobalSolution& solution,
                 GoodLinksByReceiver& byReceiver, const MovieExtent& request,
                 const MovieTexels& texels, const std::vector<double>& movieKeyTimes,
                 double shooterRatio, double cacheBytes, GoodLinkGatherStats& stats,
                 SceneVisibility* visibility, int visibilityRays, int nearShooterLevels,
                 double partialShare, int clusterVisibilityRays = 0);

  // acc[x] = G(x, t), the cluster irradiance of the receiver's top included (every texel).
  void gather(double t, std::vector<glm::dvec3>& acc) const;

 private:
  struct Link {  // one link row's share from one part of its shooter
    uint32_t row = 0;
    uint32_t shooter = 0;  // dense node: the link's shooter or a node of its sub-tree
    // A cell of a near leaf shooter: its path in the leaf's virtual quadtree (a leading 1 bit,
    // two bits per level, as PatchId::path); 1: the whole node.
    uint32_t cell = 1;
    // Its shooter points for V per texel: visibilityRays_ over a whole node, that share of them
    // over a cell (one per finest cell), so that a leaf split into cells casts as many rays.
    int rays = 0;
    bool moves = false;  // an end moves during the movie: F per key
    // Partly occluded at a needed key (0 < V < 1, or V = 0 while active) and risky enough: V per
    // texel from rays to its shooter part instead of the link's one V (pointVisibility); its
    // weight is then B_q alone at every key where the link is active.
    bool partial = false;
    // Coherence (§5), as the bad layer's static and dynamic blockers: the rays of a partial link
    // whose ends do not move are cast against the static blockers once per movie; against the
    // moving ones at every key, only when a moving node's swept bounds meet its shaft.
    bool movingBlockers = false;
    uint64_t seed = 0;                // of its shooter points (the same for every texel)
    std::vector<glm::dvec3> points;   // ends static: the shooter points (world)
    std::vector<int> pointLeaf;       // the union leaf under each shooter point
    std::vector<double> pointWeight;  // per global key k: [k * rays + i] B there (channel sum)
    std::vector<glm::dvec3> weight;   // per global key: B_q(k) \bar V(k); 0 when inactive
  };
  const Scene& scene_;
  const GlobalSolution& solution_;
  const std::vector<glm::vec3>& clusterCorners_;  // GoodLinksByReceiver::clusterCorners
  const double shooterRatio_;
  const MovieTexels texels_;
  const std::vector<double>& keyTimes_;
  int receiverTop_ = 0;
  SceneVisibility* visibility_ = nullptr;
  int visibilityRays_ = 16;
  GoodLinksByReceiver& byReceiver_;
  int nearShooterLevels_ = 0;
  std::vector<Link> links_;
  // Texels are planned in tiles of kTile x kTile; a link whose shooter part is farther than
  // kTileFarRatio times a tile's size is evaluated at the tile's corners and interpolated.
  static constexpr int kTile = 8;
  // --gather-partial-share: a partly occluded link gets V per texel when its risk B F (1 - V)
  // is at least this share of what its receiver chain carries (TextureMovieBakerOptions).
  double partialShare_;
  // The small partial links left on the link's one V sum to at most this many shares
  // (selectPartialLinks). On the 10k hall (frames 40-56 baked, frame 48 against its
  // references): 10 took the floor strip's bias from 9.4 to 4.5 %.
  static constexpr double kPartialSumShares = 10.0;
  // Per partial link, what its receiver chain carries (selectPartialLinks' total): the scale of
  // the tiles' visibility test.
  std::vector<double> linkGather_;
  static constexpr double kTileFarRatio = 2.0;
  // The same for the links of the nodes below a tile's common node (Tile::groups), which hold
  // only some of its texels. At 2 the bundled scene's frame 20 went from 2.46 to 2.50 % RMSE /
  // mean against its references; at 4 it stays at 2.46 % with 29 % fewer per-texel form factors
  // than none at all (8: 2.46 %, 10 % fewer).
  static constexpr double kTileFarRatioBelow = 4.0;
  struct Tile {
    int i0 = 0, j0 = 0, i1 = 0, j1 = 0;  // first texel and the corner texels (last column, row)
    // The corner texels (i0,j0), (i1,j0), (i1,j1), (i0,j1) of a texture `width` wide.
    std::array<size_t, 4> cornerTexels(int width) const {
      return {size_t(j0) * width + i0, size_t(j0) * width + i1, size_t(j1) * width + i1,
              size_t(j1) * width + i0};
    }
    // Values at the corner texels (in cornerTexels' order) interpolated bilinearly to texel
    // (i, j): the far links' irradiance (gather) and the cluster light's ratio
    // (planClusterVisibility).
    template <class V>
    V bilinear(int i, int j, const V (&c)[4]) const {
      const double u = i1 > i0 ? double(i - i0) / (i1 - i0) : 0.0;
      const double v = j1 > j0 ? double(j - j0) / (j1 - j0) : 0.0;
      return (1 - u) * (1 - v) * c[0] + u * (1 - v) * c[1] + u * v * c[2] + (1 - u) * v * c[3];
    }
    int common = -1;              // deepest node holding every texel of the tile
    std::vector<uint32_t> links;  // links_ indices interpolated over the tile
    // The links in groups by the texels they reach: links [groups[g - 1].second,
    // groups[g].second) reach the texels of mask groups[g].first (bit (j - j0) kTile + i - i0).
    // The common node's chain reaches all; a node below it only its own texels, where a
    // texture side that is not a power of two cuts the nodes between texels.
    std::vector<std::pair<uint64_t, uint32_t>> groups;
    std::vector<uint32_t> cornerEntry;  // per tile link, its 4 corners' cornerLink_ entries
    static uint64_t bit(int i, int j, const Tile& t) {
      return uint64_t(1) << ((j - t.j0) * kTile + (i - t.i0));
    }
  };
  // The corner texels of the tiles, each with its far links (sorted links_ indices)
  // cornerLink_[corners_[i].first .. corners_[i + 1].first) (a last entry ends the list), and
  // per entry the form factor (links that do not move) and the rays open past the static
  // blockers (partial links that do not move).
  struct Corner {
    size_t texel = 0;
    uint32_t first = 0;
  };
  std::vector<Corner> corners_;
  std::vector<uint32_t> cornerLink_;
  std::vector<double> cornerFormFactor_;
  std::vector<uint64_t> cornerOpen_;
  int tilesX_ = 0;
  std::vector<Tile> tiles_;
  int clusterVisibilityRays_ = 0;
  std::vector<float> clusterVisibility_;  // per texel; empty: 1
  size_t tileLinkCount_ = 0;              // over all tiles (the stats)
  size_t partialTileLinksPerTexel_ = 0;   // (tile, partial link) pairs moved per texel (the stats)
  // Per texel its own terms: links_ indices texelLinks_[texelStart_[x] .. texelStart_[x + 1])
  // and, when cached_, the form factors of the links that do not move in the same places.
  std::vector<uint32_t> texelStart_, texelLinks_;
  std::vector<float> texelFormFactor_;
  std::vector<uint64_t> texelOpen_;  // with texelFormFactor_: rays open past static blockers
  // The kernels of a texel's partial-link rays (pointKernels), the same at every key, from
  // texelKernelAt_[e] in texelKernel_ (kNoKernels: made at each key): pointVisibility had made
  // them again at every movie key, 8 % of the 10k hall's rad-movies samples.
  static constexpr uint32_t kNoKernels = ~0u;
  std::vector<uint32_t> texelKernelAt_;
  std::vector<double> texelKernel_;
  bool cached_ = false;
  int movieNode_ = 0;
  std::vector<std::array<glm::dvec3, 2>> swept_;  // of the nodes that move during the movie
  std::vector<int> movingNodes_;                  // those nodes

  Polygon nodeWorld(uint32_t node, double t) const;
  Polygon linkWorld(const Link& l, double t) const;  // its shooter part (or cell) at t
  // receiverAt[k]: the receiver at times[k] (one time when neither the receiver nor the shooter
  // moves during the movie, the movie's keys otherwise).
  void nearCells(const std::vector<Polygon>& receiverAt, const std::vector<double>& times,
                 uint32_t leaf, std::vector<uint32_t>& out) const;
  void planNearShooters(const std::vector<char>& neededKeys, GoodLinkGatherStats& stats);
  // fixed: the leaf's kept terms, or null; fresh: where to keep them when null (static leaf).
  std::vector<float> regatherCells(uint32_t leaf, int key, double t,
                                   const GoodLinksByReceiver::FixedTerms* fixed,
                                   GoodLinksByReceiver::FixedTerms* fresh) const;
  double cellRatio(const Link& l, int key) const;  // the cell's B over its leaf's (1: no cell)
  // Per near leaf shooter, the areas of its 4^nearShooterLevels_ cells (cellRatio's weights).
  std::unordered_map<uint32_t, std::vector<double>> cellAreas_;
  void planLinks(const GoodLinksByReceiver& byReceiver, const MovieExtent& request);
  void shooterParts(const std::vector<Polygon>& receiverAt, const std::vector<double>& times,
                    uint32_t shooter, std::vector<uint32_t>& out) const;
  void planWeights(const std::vector<char>& neededKeys);
  void selectPartialLinks(const std::vector<double>& risk, const std::vector<double>& carried);
  void planTexels(double cacheBytes);
  // The cluster light's visibility per texel (clusterVisibility_): rad-global gathers the
  // light of far surfaces through cluster links, one V per link shared by every member of the
  // receiver, and stores one irradiance per top and key; where a top is partly hidden from its
  // far surfaces (a chair's seat under a desk, its back in the open) the camera sees its open
  // parts, and the all-pairs frames, whose far links take V per texel, were brighter there
  // (10k hall, frame 48: chairs -2.2 to -2.9 % against the references, -4.4 to -5.1 % with
  // the far links' per-texel V turned off, -4.6 to -5.9 % with clusters). Per top and global key: k
  // points on its far surfaces (the static tops that are neither shooters of its nodes' good links
  // nor of its bad pairs; drawn from the key's farCandidates by cos cos / d^4 from the top's
  // centroid), seeded by the top, and their mean open share at 64 uncovered points of the top
  // (clusterLightRays); a texel's cluster light is scaled by the open share of its rays to them
  // over that mean (so the top keeps rad-global's total). At the tiles' corner texels, bilinear in
  // between, once per movie against the static blockers at its first key. (10k hall: chairs -2.0 to
  // -4.1 %, the frame's bias -1.10 -> -0.98 %.)
  void planClusterVisibility();
  // The top's far points and mean open share at global key k (cached in byReceiver_).
  const GoodLinksByReceiver::ClusterLightRays& clusterLightRays(int k);
  static constexpr int kClusterVisibilityPoints = 64;
  struct TexelFrame {  // the receiver's local-to-world map and its normal map at one time
    glm::dmat4 m;
    glm::dmat3 normalMap;
    glm::dvec3 point(const glm::dvec3& local) const {
      return glm::dvec3(m * glm::dvec4(local, 1.0));
    }
    glm::dvec3 normal(const glm::dvec3& local) const { return glm::normalize(normalMap * local); }
  };
  TexelFrame texelFrame(double t) const;
  std::vector<char> coveredTiles() const;
  void perTexelOnTiles(const std::vector<Polygon>& shooter,
                       std::vector<std::vector<uint32_t>>& nearOfTile,
                       std::vector<std::vector<std::pair<uint64_t, uint32_t>>>& nearBelow);
  void planVisibility(Link& l, const std::vector<char>& neededKeys) const;
  std::vector<glm::dvec3> pointsInFront(const Polygon& shooter, double t, int k,
                                        uint64_t seed) const;
  uint64_t openRays(const VisibilityScene& blockers, const glm::dvec3& x, const Link& l,
                    const std::vector<glm::dvec3>& points,
                    uint64_t candidates = ~uint64_t(0)) const;
  // V of link part l at texel point x (normal n): its rays open past the static blockers
  // (`open`, or cast now when null) and, for a link with moving blockers, past those at the
  // current time, weighted by the kernel and the shooter's B at their ends (`weight`).
  double visibilityAt(const glm::dvec3& x, const glm::dvec3& n, const Link& l,
                      const std::vector<glm::dvec3>& points, const glm::dvec3& shooterNormal,
                      const uint64_t* open, const double* weight, bool movingNow,
                      const double* kernels = nullptr) const;
};

}  // namespace rad
