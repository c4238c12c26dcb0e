// The solver of one key time (hierarchical_radiosity.h's solveKeyTime), private to
// libcommon/radiosity: the state its named passes share, declared once, with each pass defined
// in its own file:
//  * hierarchical_radiosity.cpp: the driver (run: the rounds of the passes, in order), the
//    thresholds and the solution handed back (finish);
//  * key_time_links.cpp: link (cluster links' refinement), evaluate, refine, the accurate pass
//    and the radiosity-weighted visibility;
//  * key_time_closure.cpp: closure (each leaf's own row sum);
//  * key_time_exposure.cpp: exposure (which ray start points are covered);
//  * key_time_gather.cpp: gather + push-pull, the Gauss-Seidel sweeps.
// Nothing outside libcommon/radiosity includes this file; the contract is solveKeyTime's.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/radiosity/cluster_links.h"
#include "libcommon/radiosity/hierarchical_radiosity.h"
#include "libcommon/radiosity/link_form_factor.h"

namespace rad {

// One key-time solve as its named passes (see hierarchical_radiosity.h): link top level, then
// rounds of evaluate + refine, accurate pass, gather + push-pull, until a round refines
// nothing. The passes share the solution being built, the radiosity B of every node and the
// thresholds. One object solves one key time once (run moves its solution out).
class KeyTimeSolver {
 public:
  // A link's index in a key solve's links: 32 bits (RadiosityOptions::maxLinks is at most
  // kMaxLinkBound), half the size_t lists of links the refinement and the gather hold.
  using LinkIndex = uint32_t;

  KeyTimeSolver(PatchHierarchy& h, const std::vector<SurfaceProperties>& surfaces,
                const KeySolveInput& input, const RadiosityOptions& opt)
      : h_(h), surfaces_(surfaces), input_(input), opt_(opt) {
    addNewNodes();
    setThresholds();
  }

  // A vector's size from the previous key's, with a margin: this key makes about as many, so
  // its vectors are reserved once instead of doubling as they grow (KeySolveInput::expected*).
  static size_t withMargin(size_t n) { return n + n / 32 + 1024; }

  KeySolution run();

 private:
  static double maxComponent(const glm::dvec3& v) { return std::max(v.x, std::max(v.y, v.z)); }

  // The passes' driver and the state between rounds (hierarchical_radiosity.cpp).
  void releaseRayPairs();
  void addNewNodes();
  void setThresholds();
  void raiseThresholdToCarriedPower();
  KeySolution finish();
  void countLinks();

  // Link, evaluate, refine, the accurate pass and the radiosity-weighted visibility
  // (key_time_links.cpp).
  size_t refineClusterLinks();
  void measureShooterRanges();
  void evaluateNewLinks();
  void evaluateLink(SolverLink& l) const;
  void weightVisibilityByShooterRadiosity();
  bool weighted(const SolverLink& l) const;
  void setWeightedVisibility(SolverLink& l, double v, double seen) const;
  void weightLinkVisibility(SolverLink& l) const;
  bool oracleWantsRefinement(const SolverLink& l) const;
  int nodeToSplit(const SolverLink& l) const;
  void splitLink(LinkIndex li, int node, std::vector<LinkIndex>& next);

  size_t refine(std::vector<LinkIndex> work);
  std::vector<LinkIndex> unrefinedLinks() const;
  void computeAccurateFormFactors();

  // The lamps' direct irradiance and its refinement (key_time_lamps.cpp).
  double lampPower() const;
  size_t refineLamps();
  bool lampWantsSplit(int i) const;
  void splitForLamps(int i, std::vector<int>& next);

  // Closure and exposure (key_time_closure.cpp).
  void computeClosure();
  // Whether leaf r is inside a closed room: none of kEscapeRays cosine-distributed rays from
  // its points, nor from those of any of its ancestors, leaves the scene (testClosedRooms). A
  // room's opening of form factor f goes unseen with probability (1 - f)^(64 (depth + 1)) (f = 1
  // %, a leaf two levels down: 14 %), and then brightens that leaf by at most f.
  static constexpr int kEscapeRays = 64;
  void testClosedRooms(const std::vector<int>& leaves);
  bool closedAt(int r) const;
  bool castEscapeRays(int r) const;
  double leafToTop(int r, uint32_t q) const;

  // A pair with a moving end would need its F(leaf -> top) at every key time (with many moving
  // objects, most of rad-global's time); moving objects are small against the rooms they
  // move in, and the closed rooms the closure is exact for are static.
  bool moves(uint32_t top) const {
    return top < input_.movingTops.size() && input_.movingTops[top];
  }
  void closeLeaf(int r);

  std::pair<glm::dvec3, glm::dvec3> excessIrradiance(int r) const;
  // A leaf's row: at most 1, and exactly 1 inside a closed room (key_time_closure.cpp).
  void closeRow(int r);
  // How many times a closed room's row may be raised to reach 1 (closeRow).
  static constexpr double kMaxRowFill = 2.0;
  // Exposure (key_time_exposure.cpp): exposure_ and coveredPoints_ of every node of this key's
  // tree not yet exposed, of the receivers of links [begin, end), of node i.
  void computeExposures();
  void exposeReceivers(size_t begin, size_t end);
  void expose(int i);
  bool inContact(const glm::dvec3& x, const glm::dvec3& normal, uint32_t top) const;
  // Heights within this share of a point's coordinates are on its plane (rounding); normals whose
  // cosine is below minus this face each other (a milliradian, contact_cuts.h's parallel).
  static constexpr double kContactRounding = 1e-6;
  static constexpr double kContactParallel = 0.9999995;

  // Gather + push-pull, the Gauss-Seidel sweeps (key_time_gather.cpp).
  void buildGatherLists();
  void gatherClusterLight();

  // What a node gives its parent's pull: its exposed area e A and e A B.
  struct Pulled {
    glm::dvec3 power{0.0};
    double area = 0;
  };

  // Gather + push-pull at node i (HSA'91 §5): $H_i = H_{down} + \sum_j F_{ij} V_{ij} B_j / e_i$
  // over its links (e_i its exposure, computeExposures), pushed down to the children; a leaf
  // sets $B_i = E_i + \rho_i c_i H_i$ (c_i its closure factor), a parent pulls up the average of
  // its children weighted by exposed area.
  // The irradiance pushed down, from emitting shooters and from the others: a closed leaf
  // scales them by different closure factors (closeLeaf).
  struct Gathered {
    glm::dvec3 light{0.0}, good{0.0};
    glm::dvec3 cluster{0.0};  // through cluster links, at the top (no closure factor)
  };

  Pulled gatherPushPull(int i, const Gathered& down);

  // The sweeps' links in gather order, each its shooter (kSweepEmits set when it emits) and
  // F V times its shooter shape: 12 bytes read in order instead of a 64-byte SolverLink and a
  // flag reached through adj_ (the sweeps are serial, and memory-bound). The same products, so the
  // same B bit for bit. The shooters overwrite adj_ (the next buildGatherLists makes it again):
  // rad-global's peak is in the solve.
  static constexpr uint32_t kSweepEmits = 0x80000000u;
  void buildSweepLists();
  void solve();

  PatchHierarchy& h_;
  const std::vector<SurfaceProperties>& surfaces_;
  const KeySolveInput& input_;
  // input_.reuseRayPairs until the first round has copied them (releaseRayPairs).
  const std::vector<LinkRayPair>* reuseRayPairs_ = input_.reuseRayPairs;
  const RadiosityOptions& opt_;
  KeySolution s_;
  std::vector<glm::dvec3> B_;  // per dense node: radiosity (W/m^2), area average of a parent
  size_t evaluated_ = 0;       // links [0, evaluated_) have their estimate and visibility
  double emittedPower_ = 0;    // Phi: the lights' power (largest channel) and the lamps'
  double epsAbs_ = 0;          // eps * Phi, raised to eps times the power carried
  bool refineOn_ = false;
  double stopChange_ = 0;  // tol * (1 - rho_max)
  std::vector<size_t> adjStart_;
  std::vector<LinkIndex> adj_;
  std::vector<glm::dvec3> irr_;   // per dense node: H gathered at it and its ancestors
  std::vector<double> exposure_;  // per dense node: its exposure once exposed, else < 0
  // Per dense node, once exposed: bit k set when its sample point k (< 64) is covered; the pairs
  // of its links from those points count as blocked (key_time_exposure.cpp).
  std::vector<uint64_t> coveredPoints_;
  // How near a surface in front of a point puts the point in a contact gap (inContact): the part
  // of a shadow ray the visibility skips at each end, kSegmentEpsilon of its length, for the
  // longest link (the diagonal of the tops' bounds at this key).
  double contactDistance_ = 0;
  // Per dense node: the closure factor of a leaf's links to shooters that do not emit (its
  // closure factor, or the closed-room one).
  std::vector<double> goodFactor_;
  // Per leaf: its chain's links whose top's share the closure replaces (link index, the top's
  // G_q / sum F V - 1 over the exposure of the node that gathers it).
  std::vector<std::vector<std::pair<size_t, double>>> topExcess_;
  std::vector<int8_t> closed_;          // per dense node: closedAt once tested (0 or 1), else -1
  std::vector<uint8_t> shooterEmits_;   // per link: its shooter's top-level patch emits
  std::vector<uint32_t> sweepShooter_;  // per adj_ entry (buildSweepLists)
  std::vector<double> sweepCoefficient_;
  std::vector<double> shooterRange_;  // per dense node: measureShooterRanges
  // Per dense node: F(node -> top-level patch) computed for the closure in this key's solve.
  std::vector<std::vector<std::pair<uint32_t, double>>> leafTopFormFactor_;
  // weightVisibilityByShooterRadiosity's ray pairs, opt_.rays per link from pairStart_[link]
  // (kNoRayPairs: not weighted yet in this key solve).
  std::vector<uint32_t> pairStart_;
  std::vector<LinkRayPair> pairs_;
  double maxDelta_ = 0, maxB_ = 0;  // of the current sweep
  bool nonFinite_ = false;          // a sweep produced NaN or Inf
  double radiosityBound_ = 0;       // 1e6 E_max / (1 - rho_max): above it the solve diverges
  std::unique_ptr<ClusterLinks> clusters_;  // null: all-pairs linking
  std::vector<double> topEmission_;         // per top: largest emitted channel (clusters_)
  std::vector<glm::dvec3> clusterH_;        // per top: irradiance through cluster links
  std::vector<double> clusterRow_;          // per top: its cluster links' form factor sum
  std::vector<FacingPlane> topPlanes_;      // per top at this key (refineClusterLinks)
  // Per dense node: the lamps' E summed (lampE_), its largest spread over the lamps (a lamp's
  // own: the oracle's), and whether they are known at this key (refineLamps).
  std::vector<glm::dvec3> lampE_;
  std::vector<double> lampSpread_;
  std::vector<char> lampKnown_;
};
}  // namespace rad
