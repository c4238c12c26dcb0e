// The options of one key-time solve (RadiosityOptions, rad-global's quality and method knobs;
// docs/design.md §6.1) and the refinement oracle's names. Every field has its default written
// here; GlobalOptions (global_stage.h) holds one of these and its toJson() is the provenance.
// Why each default is what it is, and where it was measured, is said per field; the figures
// are in docs/results.md.
#pragma once

#include <cstddef>
#include <string>

#include "libcommon/radiosity/form_factor.h"

namespace rad {

// What the refinement oracle weighs (see the top of this file).
enum class RefinementOracle {
  kPower,  // HSA'91 "BF refinement": the power B_q F_pq V A_p the link carries
  kError,  // the power it may carry wrongly: B_q V max(A_p dF_p, A_q dF_q), dF = formFactorSpread
  kBoth,   // either one over eps
};
// "power", "error", "both"; anything else is a usage Error naming the value.
const char* refinementOracleName(RefinementOracle oracle);

// The largest RadiosityOptions::maxLinks (rad-global --max-links): a key solve indexes its
// links with 32 bits.
constexpr size_t kMaxLinkBound = size_t(1) << 31;

// The defaults are the ones measured best for their cost; the figures behind each are in
// docs/results.md, "Figures moved out of the radiosity code's comments (issue 55)", under the
// field's name.
struct RadiosityOptions {
  // both, not power: the error oracle catches the links whose form factor varies over their
  // patches, which the power oracle leaves coarse (lower bias and RMSE for a little more time).
  RefinementOracle oracle = RefinementOracle::kBoth;
  // Refinement threshold relative to the largest power (below; see the top of
  // hierarchical_radiosity.h). 2e-4: below it the error against converged references falls
  // little more while the time keeps growing ("Accuracy against converged references").
  double eps = 2e-4;
  // --shadow-eps-share: a partly visible link (0 < V < 1) is also refined while
  // B_q F~ min(V, 1 - V) A_p > shadowEpsShare x eps x Phi: its receiver's one radiosity blends
  // the lit and shadowed sides of a shadow boundary, and the movies' gather takes that blend
  // wherever a near surface sees the receiver (issue 56: the bundled scene's short box, bright
  // over the floor in its own shadow). 0: off (the power and error oracles alone).
  double shadowEpsShare = 0.25;
  double minArea = 0.0;        // m^2: a link whose larger patch is not larger than this stays
  bool refine = true;          // false: top-level links only (discrete system of the input patches)
  int rays = 16;               // shadow-ray pairs per link
  double tol = 1e-4;           // relative change, scaled by (1 - rho_max)
  int maxIterations = 200000;  // Gauss-Seidel sweeps per solve (a safety net)
  int maxRefineRounds = 8;     // refine / solve rounds
  bool shooterShape = true;    // gather B_q x SolverLink::shooterShape (false: B_q alone)
  int quadratureOrder = kAutoOrder;  // of polygonToPolygonFormFactor; kAutoOrder = per pair
  // Relative tolerance of the adaptive near-contact form factor: tighter moves no radiosity
  // visibly and costs time.
  double formFactorTolerance = 1e-5;
  // Memory bound: refinement stops once a key time's solve holds this many links (refined ones
  // included), and the solve goes on with the links it has; KeySolution::linkCapReached says
  // so. It bounds a key's memory where the oracle never stops refining (a furnace at
  // rho -> 1) instead of running out of it. At most kMaxLinkBound.
  size_t maxLinks = 4000000;
  // Scale each leaf's gathered irradiance so that its row sum is its own (see computeClosure in
  // key_time_closure.cpp): exact energy balance in closed rooms whatever the refinement. false:
  // the plain hierarchical gather (HSA'91), for comparison.
  bool closure = true;
  // Part of the closure: a leaf from which no ray escapes the scene (inside a closed room) has
  // its whole row sum made exactly 1, occluded links included (computeClosure). false: only the
  // unoccluded tops' share is corrected, as in open scenes.
  bool closedRooms = true;
  // Link from one self-link of a cluster hierarchy over the top-level patches (cluster_links.h)
  // instead of pairing every top-level patch with every other. false: the all-pairs linking
  // (linkTopLevel), the baseline. The space-time pass builds the tree (KeySolveInput::clusters).
  bool clustering = true;
  // A cluster link is kept only while the distance of its ends' centres is at least this many
  // times the sum of their bounding radii (the opening criterion of the point approximation,
  // whose 1/r^2 at the shooter's centre is a second-order error in radius / distance); closer
  // ones are refined. Larger is nearer all pairs and slower; 3.75 is where the error against
  // all pairs stopped falling for its cost once each receiver member takes its own V
  // (clusterMemberRays). ClusterLinks.ExposedFloorMatchesAllPairsAtTheDefaultSeparation checks
  // it.
  double clusterSeparation = 3.75;
  // A link from a light stays a cluster link while its power bound is under this share of
  // eps Phi (cluster_links.h); stronger ones end as patch links, whose shadows the second pass
  // takes per texel. 0: every light link ends as patch links (per-texel shadows from every
  // light, links growing as the top-level patches times the lights). 0.1 keeps nearly all of
  // 0's accuracy at a fraction of its links and time on scenes with many lights.
  double lightClusterShare = 0.1;
  // Shadow-ray pairs per member top of a cluster link's receiver cluster, for that member's own
  // V (cluster_links.h); 0: every member takes the V of its facing group over the link's pairs.
  // One V for all of a wall's tiles spreads the light its open tiles see over the ones hidden
  // behind something (a hall's lower wall behind its seats); more than 4 gains little.
  int clusterMemberRays = 4;
  // Cluster links' transfer: isotropic clusters (each cluster end emits and receives alike in
  // every direction, Smits, Arvo, Greenberg 1994 §3) instead of oriented facing groups
  // (cluster_links.h). Off: scenes of flat surfaces (a wall's tiles show all of their area to
  // what faces them, not a quarter) come out far too dark with isotropic ends.
  bool isotropicClusters = false;
  // Keep a near cluster link without a light whose bound with F = 1 cannot carry eps Phi,
  // instead of refining it (cluster_links.h, fateOf); the first round judges it by an estimate
  // of the shooters' B (ClusterLinks::estimateRadiosity). Off (--refine-weak-near-links): every
  // near link is refined down to its member pairs, and packed small objects (shelves of
  // binders, keyboards, a room's chairs) fill the link bound.
  bool keepWeakNearLinks = true;
  // --weak-near-ambient-share: the first round judges the near links' weakness by this share
  // of the ambient radiosity (ClusterLinks::estimateRadiosity; key_time_links.cpp). The mean
  // ambient B overestimates the B of packed, mostly shadowed parts (binders' sides), whose
  // links it refines at once; 0 judges by the lights' B alone, which keeps every near link
  // in the first round and leaves the refinement unsettled (docs/results.md, "Weak near links
  // kept by default", for the range that holds both).
  double weakNearAmbientShare = 0.1;
  // Rays of the blocked test of a near cluster link without a light whose ends have more facing
  // member pairs than are tested one by one (cluster_links.h, sampledBlocked): the link is
  // dropped when all of them are blocked; a link with a share p of its member pairs open is
  // dropped with probability (1 - p)^n. 0: such links are refined untested (furniture of
  // neighbouring rooms behind a wall then fills the link bound).
  int nearBlockRays = 64;
};

}  // namespace rad
