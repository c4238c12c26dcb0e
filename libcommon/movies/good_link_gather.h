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
// way, so both layers carry the same cluster light), and scaled per texel by what the texel
// sees of the top's far surfaces (cluster_light_rays.h);
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
// kPartialSumShares s (selectPartialLinks; a quarter of the rays then), V(x, q): --gather-rays
// shadow rays from x to points on the shooter part q (the same points for every texel), each
// weighted by the kernel and by the global solution's B at its end (pointVisibility), so that
//
//   term = B_q(k) F(x -> q) V(x, q)
//
// Why: one V per receiver node steps where two nodes whose links are occluded differently meet;
// the B weights keep the light of a shooter bright where the texel cannot see it (a
// double-sided lamp's far side) from leaking through its visible part. Static blockers are cast
// once per movie, moving ones per key (§5). ("The per-texel good-link gather" and "Which
// gathered links take their visibility per texel" in docs/results.md.)
//
// Cost: texels are planned in tiles of kTile x kTile (gather_tiles.cpp); a link whose shooter
// part is far from a tile (kTileFarRatio times its size) is evaluated at the tile's corners and
// interpolated bilinearly, so only near links cost a form factor per texel. A far partial link
// stays on the tile only while its V at the tile's middle texel is what the corners
// interpolate, within s of what the texel gathers (perTexelOnTiles).
//
// Near shooters (--near-shooter-levels L > 0): a near leaf shooter is split into cells whose
// radiosity is re-gathered once per run (near_shooter_cells.h); each cell is then a shooter part
// of its own, weighted by its B over the leaf's (cellRatio).
//
// Between key times the gather is linear in t, as the Gouraud layer is. Coherence (§5): for a
// link whose two ends do not move during the movie, F(x -> q) is computed once per movie and
// kept (up to a memory budget); only B and \bar V change per key. A link with a moving end
// recomputes F at every movie key. The result does not depend on the order in which a baker's
// movies are made (what GoodLinksByReceiver stores is the same whichever movie made it).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/intervals/movie_extent.h"
#include "libcommon/movies/good_links_by_receiver.h"
#include "libcommon/movies/solid_contact.h"
#include "libcommon/radiosity/global_solution.h"
#include "libcommon/radiosity/hierarchical_radiosity.h"
#include "libcommon/radiosity/scene_visibility.h"
#include "libcommon/scene/scene.h"
#include "libcommon/scene/scene_emitters.h"

namespace rad {

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
  // sub-tree larger than shooterRatio times their distance to the receiver's nearest point, so
  // that the parts depend on where a receiver is, not on its shape or the level at which it is
  // linked; 0: no split), their
  // visibility at the global keys it needs and, within `cacheBytes`, the per-texel form factors
  // of the links whose ends do not move.
  // `emitters` are the lights among the solution's tops (SceneEmitters of hierarchy.tops()).
  GoodLinkGather(const Scene& scene, const GlobalSolution& solution, const SceneEmitters& emitters,
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
    // One of the small partial links that take a quarter of the rays (selectPartialLinks; the
    // stats): not told by its ray count since a node's parts and a leaf's cells share rays too.
    bool fewRays = false;
    uint64_t seed = 0;                // of its shooter points (the same for every texel)
    std::vector<glm::dvec3> points;   // ends static: the shooter points (world)
    std::vector<int> pointLeaf;       // the union leaf under each shooter point
    std::vector<double> pointWeight;  // per global key k: [k * rays + i] B there (channel sum)
    std::vector<glm::dvec3> weight;   // per global key: B_q(k) \bar V(k); 0 when inactive
  };
  const Scene& scene_;
  const GlobalSolution& solution_;
  const SceneEmitters& emitters_;
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
  // (selectPartialLinks): each misplaces little, but a receiver with many of them (a floor
  // seeing the ceiling past many table edges) misplaces their sum, and two receiver nodes side by
  // side that keep different links step by it along their border: a seam between coplanar
  // patches (issue 56; docs/results.md, "Seams from the small partial links").
  static constexpr double kPartialSumShares = 2.5;
  // Per partial link, what its receiver chain carries (selectPartialLinks' total): the scale of
  // the tiles' visibility test.
  std::vector<double> linkGather_;
  static constexpr double kTileFarRatio = 2.0;
  // The same for the links of the nodes below a tile's common node (Tile::groups), which hold
  // only some of its texels: larger than kTileFarRatio, the smallest ratio that costs no
  // accuracy against per-texel form factors.
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
  // texelKernelAt_[e] in texelKernel_ (kNoKernels: made at each key), so that pointVisibility
  // does not make them again at every movie key.
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
                                   const NearShooterStore::FixedTerms* fixed,
                                   NearShooterStore::FixedTerms* fresh) const;
  double cellRatio(const Link& l, int key) const;  // the cell's B over its leaf's (1: no cell)
  // Per near leaf shooter, the areas of its 4^nearShooterLevels_ cells (cellRatio's weights).
  std::unordered_map<uint32_t, std::vector<double>> cellAreas_;
  void planLinks(const GoodLinksByReceiver& byReceiver, const MovieExtent& request,
                 const std::vector<char>& neededKeys);
  void shooterParts(const std::vector<Polygon>& receiverAt, const std::vector<double>& times,
                    const std::vector<char>& neededKeys, uint32_t shooter,
                    std::vector<std::pair<uint32_t, int>>& out) const;
  // The parts come with the levels they lie below the last node larger than kRaysRatio times
  // the ratio: such a node's rays are shared among its parts (a quarter a level, as a near
  // leaf's cells share them), for they split where B varies, not V, and a texel's V of the node
  // is then taken from as many rays as before its parts were made finer for their B.
  static constexpr double kRaysRatio = 2.0;
  // A shooter part is split only where its children's radiosities differ from its own by more
  // than this share (childrenDiffer): the step two receivers linked at different levels can
  // make is then at most this share of the part's term.
  static constexpr double kPartSpread = 0.02;
  bool childrenDiffer(uint32_t q, const std::vector<char>& neededKeys) const;
  void planWeights(const std::vector<char>& neededKeys);
  void selectPartialLinks(const std::vector<double>& risk, const std::vector<double>& carried);
  void planTexels(double cacheBytes);
  // The cluster light's visibility per texel (clusterVisibility_; cluster_light_rays.h): per
  // top and global key, clusterVisibilityRays_ far points and their mean open share at
  // kClusterVisibilityPoints uncovered points of the top (clusterLightRays); a texel's cluster
  // light is scaled by the open share of its rays to them over that mean. At the tiles' corner
  // texels, bilinear in between, once per movie against the static blockers at its first key.
  void planClusterVisibility();
  // The top's far points and mean open share at global key k (cached in byReceiver_).
  const ClusterLightStore::Rays& clusterLightRays(int k);
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
  // planTexels' steps (gather_tiles.cpp).
  using LinkRanges = std::map<int, std::pair<uint32_t, uint32_t>>;  // receiver node -> links_
  LinkRanges linkRanges() const;
  struct ShooterBounds {  // per link, its shooter part at the movie's first key
    std::vector<Polygon> polygon;
    std::vector<glm::dvec3> centre;
    std::vector<double> radius;  // of the sphere about centre holding the polygon
  };
  ShooterBounds shooterBounds(double t) const;
  void makeTiles();
  void sortTileLinks(size_t tile, const LinkRanges& linksOf, const std::vector<int>& leaf,
                     const TexelFrame& frame, const ShooterBounds& shooters, bool covered,
                     std::vector<uint32_t>& nearOfTile,
                     std::vector<std::pair<uint64_t, uint32_t>>& nearBelow);
  void planCorners(const TexelFrame& frame, const std::vector<Polygon>& shooter);
  void listTexelLinks(const std::vector<std::vector<uint32_t>>& nearOfTile,
                      const std::vector<std::vector<std::pair<uint64_t, uint32_t>>>& nearBelow);
  void cacheTexelTerms(const TexelFrame& frame, const std::vector<Polygon>& shooter,
                       double cacheBytes);
  void cacheTexelKernels(const TexelFrame& frame, const std::vector<Polygon>& shooter, double left);
  // gather's steps: what every texel shares at one time, then the tiles.
  struct KeyTerms {
    std::vector<glm::dvec3> weight;               // per link: B_q \bar V at t; 0 when inactive
    std::vector<Polygon> shooter;                 // per link: its part at t (when needed)
    std::vector<glm::dvec3> shooterNormal;        // partial links
    std::vector<std::vector<glm::dvec3>> points;  // moving partial links: points at t
    std::vector<double> pointWeight;              // [link * visibilityRays_ + i]
    std::vector<char> movingNow;                  // a moving node meets the shaft at t
  };
  KeyTerms keyTerms(double t) const;
  const std::vector<glm::dvec3>& pointsOf(const KeyTerms& key, uint32_t link) const;
  std::array<glm::dvec3, 4> clusterCornersAt(double t) const;
  glm::dvec3 clusterAt(const std::array<glm::dvec3, 4>& corners, size_t texel) const;
  std::vector<double> farLinksAtCorners(const KeyTerms& key, const TexelFrame& frame) const;
  void gatherTile(const Tile& tile, const KeyTerms& key, const std::array<glm::dvec3, 4>& cluster,
                  const TexelFrame& frame, const std::vector<double>& cornerValue,
                  std::vector<glm::dvec3>& acc) const;
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
