// The good layer of a texture movie as a per-texel gather over the global solution's good links
// (a "final gather", Lischinski, Tampieri, Greenberg 1992 §5; Smits, Arvo, Salesin 1994), in
// place of the paper's Gouraud interpolation of the vertex irradiance (§3.1).
//
// At texel centre x of a receiver whose union leaf chain (leaf and ancestors) is c(x), at key k,
//
//   G(x, k) = \sum_{l = (p <- q) good, p \in c(x), active at k}  B_q(k) \, \bar V_l(k) \, F(x \to
//   q)
//
// with F(x -> q) the exact point-to-polygon form factor at the texel and \bar V_l the link's
// visibility, recovered from the stored F·V as  \bar V = F V_l / (\bar F(p -> q) e_p),  clamped
// to [0, 1], where \bar F is the area-average form factor (areaAverageFormFactor) and e_p the
// receiver's exposure (the share of it that is not covered; rad-global divides its gather by
// it). The Gouraud layer spreads a receiver element's mean irradiance linearly over it; the
// point form factor follows what the element really sees: the darkening into a concave corner,
// the bright band next to a lit wall. For an unoccluded link the texel's sum is the exact
// form factor, so a closed room sums to 1 at every texel, not only per element.
//
// Cost: a link whose shooter part is far from the receiver node (kFarRatio) is evaluated at the
// node's corners and interpolated bilinearly, so only near links cost a form factor per texel.
//
// Between key times the gather is linear in t, as the Gouraud layer is. Coherence (§5): for a
// link whose two ends do not move during the movie, F(x -> q) is computed once per movie and
// kept (up to a memory budget); only B and \bar V change per key. A link with a moving end
// recomputes F at every movie key.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/intervals/movie_extent.h"
#include "libcommon/radiosity/global_solution.h"
#include "libcommon/scene/scene.h"

namespace rad {

// The good links that gather (not refined, not of a bad pair), grouped by receiver node: built
// once per solution, shared by every movie.
struct GoodLinksByReceiver {
  explicit GoodLinksByReceiver(const GlobalSolution& solution);
  std::vector<uint32_t> start;  // per node: its links are rows[start[i] .. start[i + 1])
  std::vector<uint32_t> rows;   // indices into solution.links
};

// The texels of one movie: their (u,v) in the receiver's top-level patch and their points in
// its local frame (MovieGeometry's, shared).
struct MovieTexels {
  const std::vector<glm::dvec2>& topUv;
  const std::vector<glm::dvec3>& localPoint;
  int width = 0, height = 0;
};

struct GoodLinkGatherStats {
  long links = 0;                // link rows gathered, summed over movies
  long entries = 0;              // (texel, near link) terms per key, summed over movies
  long cachedEntries = 0;        // of which F was computed once per movie
  long interpolatedEntries = 0;  // (texel, receiver node) interpolations of far links' corners
};

class GoodLinkGather {
 public:
  // Plans the gather of one movie: its links (each shooter split into the parts of its union
  // sub-tree larger than shooterRatio times their distance to the receiver; 0: no split; links
  // under weakShare of their chain's irradiance interpolated from the node corners), their
  // visibility at the global keys it needs and, within `cacheBytes`, the per-texel form factors
  // of the links whose ends do not move.
  GoodLinkGather(const Scene& scene, const GlobalSolution& solution,
                 const GoodLinksByReceiver& byReceiver, const MovieExtent& request,
                 const MovieTexels& texels, const std::vector<double>& movieKeyTimes,
                 double shooterRatio, double weakShare, double cacheBytes,
                 GoodLinkGatherStats& stats);

  // acc[x] = G(x, t).
  void gather(double t, std::vector<glm::dvec3>& acc) const;

 private:
  struct Link {  // one link row's share from one part of its shooter
    uint32_t row = 0;
    uint32_t shooter = 0;  // dense node: the link's shooter or a node of its sub-tree
    bool moves = false;    // an end moves during the movie: F per key
    bool far = false;      // far or weak: gathered at the receiver node's corners, interpolated
    std::vector<glm::dvec3> weight;  // per global key: B_q(k) \bar V(k); 0 when inactive
  };
  const Scene& scene_;
  const GlobalSolution& solution_;
  const double shooterRatio_;
  const double weakShare_;
  const MovieTexels texels_;
  const std::vector<double>& keyTimes_;
  int receiverTop_ = 0;
  std::vector<Link> links_;
  // A link is far when its shooter part is farther from the receiver node than kFarRatio times
  // the node's size.
  static constexpr double kFarRatio = 4.0;
  struct ReceiverNode {  // a node of the texels' chains
    int node = 0, corners = 4;
    std::array<glm::dvec3, 4> cornerLocal{};    // in the top's local frame
    std::vector<uint32_t> nearLinks, farLinks;  // links_ indices
    std::vector<double> cornerFormFactor;       // per far link, 4 corners (at the movie's start)
  };
  std::vector<ReceiverNode> nodes_;
  // Per texel its near terms: links_ indices texelLinks_[texelStart_[x] .. texelStart_[x + 1])
  // and, when cached_, the form factors of the links that do not move in the same places; and
  // the chain nodes with far links, texelNodes_[texelNodeStart_[x] ..), with the texel's (u,v)
  // in each.
  std::vector<uint32_t> texelStart_, texelLinks_, texelNodeStart_, texelNodes_;
  std::vector<glm::dvec2> texelNodeUv_;
  std::vector<float> texelFormFactor_;
  bool cached_ = false;

  void planLinks(const GoodLinksByReceiver& byReceiver, const MovieExtent& request);
  void shooterParts(const Polygon& receiver, uint32_t shooter, double t,
                    std::vector<uint32_t>& out) const;
  void planWeights(const std::vector<char>& neededKeys);
  void planTexels(double cacheBytes);
  void classifyLinks(const std::map<int, uint32_t>& nodeOf, double t0);
  Polygon nodeWorld(uint32_t node, double t) const;
  struct TexelFrame {  // the receiver's local-to-world map and world normal at one time
    glm::dmat4 m;
    glm::dvec3 n;
  };
  TexelFrame texelFrame(double t) const;
  void cornerFormFactors(const ReceiverNode& n, const TexelFrame& frame,
                         const Polygon& receiverWorld, const Polygon& shooter, double* out) const;
};

}  // namespace rad
