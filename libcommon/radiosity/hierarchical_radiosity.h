// Hierarchical radiosity at one time (Hanrahan, Salzman, Aupperle 1991, "A rapid hierarchical
// radiosity algorithm") and the pieces rad-global's space-time solve is made of (paper §3.1,
// §4.2; docs/design.md §6.1).
//
// One key-time solve, as named passes (solveKeyTime runs them in this order):
//  * link top level: with a cluster hierarchy (KeySolveInput::clusters), cluster links from the
//    root's self-link (cluster_links.h), refined each round like the patch links, whose pairs
//    of top-level patches become patch links; without one (--no-clustering), linkTopLevel:
//    links p <- q between every mutually facing pair of top-level patches (a pair where one
//    lies wholly on or behind the other's plane is never linked);
//  * evaluate: every new link gets the cheap estimate F~ (formFactorEstimate, both
//    directions) and its visibility V from k stratified shadow-ray pairs (VisibilityScene),
//    seeded from (receiver id, shooter id);
//  * refine, brightness-weighted (HSA'91 §4, "BF refinement"): a link p <- q is refined while
//    max_c B_q,c * F~_pq * V_pq * A_p > eps * Phi  (Phi = the largest power over the colour
//    channels, emitted or, once the last solve carries more, carried: sum of A B; so eps is
//    relative, the scene's units do not matter, and B >> E (rho -> 1) does not refine every
//    link down to the link bound) and the larger
//    of the two patches has area > minArea; the larger patch is subdivided and its four
//    children's links are evaluated and refined in turn. Refined links are kept (flag
//    refined) but not gathered;
//  * accurate pass: leaf links get the accurate unoccluded F (polygonToPolygonFormFactor);
//  * closure: each leaf's factor c that makes its row sum its own (exact in closed rooms);
//  * exposure: each node's fraction not covered by a solid standing on it; its links'
//    irradiance is divided by it, so B is the radiosity of the part that can be seen;
//  * gather + push-pull (HSA'91 §5), Gauss-Seidel over the top-level patches, until the
//    relative change of B is below tol * (1 - rho_max) (the stop rule of the furnace
//    reference: a change below tol alone leaves an error of tol / (1 - rho));
//  * refine again with the new B and re-solve, until a round refines nothing.
//
// Every key time works on one shared PatchHierarchy (the union over key times): a key's own
// tree is the set of nodes it split (KeySolution::split). Node indices are dense indices of
// that hierarchy; patch ids (PatchId) are what stays the same from key to key.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/radiosity/cluster_links.h"
#include "libcommon/radiosity/cluster_tree.h"
#include "libcommon/radiosity/form_factor.h"
#include "libcommon/radiosity/visibility.h"
#include "libcommon/scene/patch_hierarchy.h"
#include "libcommon/scene/scene.h"

namespace rad {

// What the refinement oracle weighs (see the top of this file).
enum class RefinementOracle {
  kPower,  // HSA'91 "BF refinement": the power B_q F_pq V A_p the link carries
  kError,  // the power it may carry wrongly: B_q V max(A_p dF_p, A_q dF_q), dF = formFactorSpread
  kBoth,   // either one over eps
};
// "power", "error", "both"; anything else is a usage Error naming the value.
RefinementOracle parseRefinementOracle(const std::string& name);
const char* refinementOracleName(RefinementOracle oracle);

// The largest RadiosityOptions::maxLinks (rad-global --max-links): 2^31 links, ~340 GB.
constexpr size_t kMaxLinkBound = size_t(1) << 31;

struct RadiosityOptions {
  // both, not power: on the bundled scene and the Cornell box of tests/data/external it halves
  // the bias (-1.7 % -> -0.9 %, -1.9 % -> -1.5 %) and lowers the RMSE by 1-2 points, at ~1.2x
  // rad-global's time (README, "Results").
  RefinementOracle oracle = RefinementOracle::kBoth;
  // Refinement threshold relative to the largest power (below). 2e-4, not 1e-3: against
  // converged references (352x240, RMSE / mean over non-emitters) the Cornell box went from
  // 4.55 to 3.19 %, the bundled scene 4.61 to 3.14 %, cubes-8 2.74 to 2.52 %, the cubic scene
  // 3.49 to 2.94 % (table-static-static 1.90 -> 1.88 %), at 1.48x the table's whole pipeline
  // time over 100 frames (farm-bench, one core); 1e-4 reached 3.10 % on the Cornell box at
  // about twice the time (README, "Accuracy").
  double eps = 2e-4;
  double minArea = 0.0;        // m^2: a link whose larger patch is not larger than this stays
  bool refine = true;          // false: top-level links only (discrete system of the input patches)
  int rays = 16;               // shadow-ray pairs per link
  double tol = 1e-4;           // relative change, scaled by (1 - rho_max)
  int maxIterations = 200000;  // Gauss-Seidel sweeps per solve (a safety net)
  int maxRefineRounds = 8;     // refine / solve rounds
  bool shooterShape = true;    // gather B_q x SolverLink::shooterShape (false: B_q alone)
  int quadratureOrder = kAutoOrder;  // of polygonToPolygonFormFactor; kAutoOrder = per pair
  // Relative tolerance of the adaptive near-contact form factor. 1e-5 instead of 1e-7 halves
  // rad-global's time on the table scene and moves no radiosity by more than 3e-7 relative.
  double formFactorTolerance = 1e-5;
  // Memory bound: refinement stops once a key time's solve holds this many links (refined ones
  // included), and the solve goes on with the links it has; KeySolution::linkCapReached says
  // so. About 160 bytes each through rad-global's peak (the closed furnace at rho = 0.99: 0.8 M
  // links, 128 MB), so the default bounds a key's links to ~0.6 GB instead of running out of
  // memory where the oracle never stops refining (the furnace at rho = 0.999). At most
  // kMaxLinkBound: a key solve indexes its links with 32 bits.
  size_t maxLinks = 4000000;
  // Scale each leaf's gathered irradiance so that its row sum is its own (see computeClosure in
  // the .cpp): exact energy balance in closed rooms whatever the refinement. false: the plain
  // hierarchical gather (HSA'91), for comparison.
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
  // ones are refined. One key, rad-global time on one core: the 10k-triangle hall (make_hall.py,
  // frame 48) against 4096-spp references (RMSE / mean, bias over non-emitters): 3: 3.16 %,
  // -1.43 %, 21.3 s, 365 MB; 4: 2.84 %, -1.00 %, 34.4 s, 480 MB; all pairs: 2.84 %, -1.09 %,
  // 81.4 s, 1.3 GB. Against all pairs (RMSE / mean): the 3k hall 0.90 % at 3 (7.0 s), 0.56 % at
  // 4 (8.6 s; all pairs 12.7 s); table-static-static 0.60 -> 0.06 %, cubes-8 0.11 -> 0.03 %
  // (same time). 2 and 1 gave 1.71 and 1.95 % on the 3k hall.
  // ClusterLinks.ExposedFloorMatchesAllPairsAtTheDefaultSeparation: 3 is 2.2 % dark there.
  // With each receiver member's own V (clusterMemberRays), 3.75: the 10k-triangle hall's 96
  // frames against all pairs 0.812 %, -0.125 % (4: 0.749 %, -0.100 %; 4 with one V per facing
  // group, the default before: 0.893 %, -0.133 %), and 9 % fewer links at its first key
  // (2,388,569 against 2,629,222; 1k-triangle hall 131,664 against 136,728).
  double clusterSeparation = 3.75;
  // A link from a light stays a cluster link while its power bound is under this share of
  // eps Phi (cluster_links.h); stronger ones end as patch links, whose shadows the second pass
  // takes per texel. 0: every light link ends as patch links (per-texel shadows from every
  // light, links growing as the top-level patches times the lights). The 10k-triangle hall
  // (make_hall.py, 35 lights; frame 48 against 4096-spp references, RMSE / mean, bias; bad
  // pairs; rad-movies on frames 40-56): 0: 3.34 %, -0.88 %, 95 k, 15.0 s; 0.1: 3.37 %,
  // -0.90 %, 42 k, 12.9 s; 1: 4.10 %, -1.14 %, 12 k, 11.1 s. The 100k hall (247 lights):
  // rad-global 533.5 -> 247.7 s, 4,183 -> 2,147 MiB, rad-movies ~36 min -> 104 s at 0.1.
  double lightClusterShare = 0.1;
  // Shadow-ray pairs per member top of a cluster link's receiver cluster, for that member's own
  // V (cluster_links.h); 0: every member takes the V of its facing group over the link's pairs.
  // One V for all of a wall's tiles had spread the light its open upper tiles see over its
  // lower ones, hidden behind the seats: on the 10k-triangle hall (make_hall.py, key 0) the
  // cluster links' F V at the tiles above 2 m was 3.5 % under its exact value (point-to-polygon
  // F over the shooter's tops, V from 4 ray pairs each) and 3.8 % over it below. The hall's 96
  // frames against all pairs (RMSE / mean, bias over non-emitters): 0: 0.893 %, -0.13 %; 4:
  // 0.742 %, -0.086 %; 8: 0.735 %, -0.089 %.
  int clusterMemberRays = 4;
  // Cluster links' transfer: isotropic clusters (each cluster end emits and receives alike in
  // every direction, Smits, Arvo, Greenberg 1994 §3) instead of oriented facing groups
  // (cluster_links.h). The 10k-triangle hall's 96 frames against all pairs (RMSE / mean, bias
  // over non-emitters): oriented 0.812 %, -0.125 %; isotropic 4.40 %, -2.38 % (a hall is flat
  // surfaces: a wall's tiles show all of their area to what faces them, not a quarter).
  bool isotropicClusters = false;
};

// Diffuse reflectance and emitted radiosity B_e = pi L_e (W/m^2) of one top-level patch.
struct SurfaceProperties {
  glm::dvec3 reflectance{0.0};
  glm::dvec3 emission{0.0};
  bool doubleSided = false;  // the material is doubleSided: its back is a surface too
  bool isEmitter() const { return emission.x > 0 || emission.y > 0 || emission.z > 0; }
};
// From the scene's materials (reflectance clamped to [0, 1]; the glTF default material is
// white).
std::vector<SurfaceProperties> surfacePropertiesOf(const Scene& scene,
                                                   const PatchHierarchy& hierarchy);

// One link of a key-time solve. 64 bytes: a key of the 10k-triangle hall holds 1.5 M of them
// (88 bytes each had been 137 MB of rad-global's peak). The oracle's F~ and spread, and the
// shooter's shape, are single precision: they steer refinement and weight the gather by
// factors whose own error is far above 6e-8; F and V stay double.
struct SolverLink {
  static constexpr uint32_t kNotKnown = ~uint32_t(0);
  int receiver = 0;  // dense node index (gathers)
  int shooter = 0;   // dense node index (shoots)
  // Its entry in KeySolveInput::reuse (the previous key's values: the accurate F when that key
  // computed one, and its ray pairs), else kNotKnown.
  uint32_t known = kNotKnown;
  // The shooter's radiosity as the receiver sees it over its mean (weightVisibility...): the
  // ray pairs' kernel-weighted mean of its leaves' B, divided by B_q; 1 for a leaf shooter.
  float shooterShape = 1.0f;
  double formFactor = 0;        // unoccluded F(receiver -> shooter); the estimate until `accurate`
  double visibility = 0;        // V in [0, 1] as gathered: rayVisibility weighted by the
                                // shooter's radiosity at the rays' ends (weightVisibility...)
  double rayVisibility = 0;     // V of the shadow rays, kernel-weighted (visibilityFrom)
  uint64_t openPairs = 0;       // which of those ray pairs were unoccluded (bit i: pair i < 64)
  float estimate = 0;           // F~ of the oracle
  float spreadArea = 0;         // max(A_p dF(p -> q), A_q dF(q -> p)) of the error oracle (m^2)
  bool refined = false;         // kept for the hierarchy, not gathered
  bool accurate = false;        // the accurate pass has seen it (an invisible link may keep F~)
  bool integrated = false;      // formFactor is the quadrature value
  bool reused = false;          // F and V taken from the previous key time (coherence)
  bool visibilityOnly = false;  // F taken over, V recomputed (the shaft met a moving object)
  double fv() const { return formFactor * visibility; }
};

// One ray pair of a link's radiosity-weighted visibility (weightVisibilityByShooterRadiosity):
// its kernel and the (u,v) of its end in the shooter. Geometry only: valid while both ends are
// static, like CachedLink's estimate. Single precision: 12 bytes instead of 24, and the 4.6 M
// pairs of a key of the 10k-triangle hall are held twice at rad-global's peak (the previous
// key's and this one's); a relative 6e-8 in a weight or in where a pair ends in the shooter
// moves no gathered value beyond the rays' own noise.
struct LinkRayPair {
  glm::vec2 uv{0.0f};
  float kernel = 0;
};
// A link's first ray pair is a 32-bit index: at most RadiosityOptions::maxLinks (4 M) times
// kMaxRecordedPairs (64) pairs.
constexpr uint32_t kNoRayPairs = ~uint32_t(0);

// Link values that a key-time solve may take over instead of recomputing (paper §4.2): keyed
// by (receiver, shooter) dense node index, which every key of the union hierarchy shares. Only
// values are taken over, never decisions: the solve refines and iterates exactly as without them,
// so a coherent key solve is bit-identical to an independent one whenever the cached values are
// what recomputing would give.
struct CachedLink {
  float estimate = 0, spreadArea = 0;  // geometry only: valid while both ends are static
  double formFactor = -1;              // accurate unoccluded F, or < 0 when never computed
  double visibility = 0;               // the shadow rays' V (SolverLink::rayVisibility)
  uint64_t openPairs = 0;              // and their unoccluded pairs
  uint32_t rayPairs = kNoRayPairs;     // its first LinkRayPair in the previous KeySolution
  bool visibilityValid = false;        // false: a moving object's swept bound met the link's shaft
};
using LinkCache = PairTable<CachedLink>;
// The closure's leaf-to-top form factors F(leaf -> top-level patch) a key-time solve may take
// over (both static): per dense node of the union hierarchy (whose numbering every key shares),
// its (top index, F) pairs. A previous key's KeySolution::leafTopFormFactor as it is: a hash
// map keyed by (node id, top) rebuilt at every key had been 6-7 % of rad-global's time on the
// table scene (perf), for values a dense index finds directly.
using LeafFormFactorCache = std::vector<std::vector<std::pair<uint32_t, double>>>;
// Whether a node of a static top-level patch is inside a closed room (its escape rays all meet
// the static geometry), keyed by node id: the same at every key time.
using ClosedNodeCache = std::unordered_map<uint64_t, bool>;

struct KeySolveInput {
  std::vector<glm::dmat4> topToWorld;           // per top-level patch: its node's world transform
  const VisibilityScene* visibility = nullptr;  // null: every link fully visible
  const LinkCache* reuse = nullptr;             // coherence: values to take over
  // The previous key's link and ray pair counts (0: none): this key's make about as many, so
  // its vectors are reserved once with a margin instead of doubling as they grow (the doubling
  // of 1.5 M links and 4.6 M ray pairs had held up to twice their size on the 10k-triangle hall).
  size_t expectedLinks = 0, expectedRayPairs = 0, expectedClusterLinks = 0;
  // coherence: the previous key's KeySolution::rayPairs (CachedLink::rayPairs indexes them)
  const std::vector<LinkRayPair>* reuseRayPairs = nullptr;
  // coherence: the closure's, moved into the solve at its first closure (a copy beside it had
  // held 22 MB through the 10k-triangle hall's key solves)
  LeafFormFactorCache* reuseLeafFormFactors = nullptr;
  const ClosedNodeCache* reuseClosed = nullptr;  // coherence: closed-room tests
  // Per top-level patch: it moves at some time of the animation. The closure corrects only
  // pairs of patches that never move (empty: none moves).
  std::vector<char> movingTops;
  // The cluster hierarchy to link from (cluster_links.h); null or empty: linkTopLevel.
  const ClusterTree* clusters = nullptr;
  const ClusterLinkCache* reuseClusterLinks = nullptr;  // coherence: cluster link values
  // Frees what reuseRayPairs points to. The solve calls it once its first round has copied the
  // pairs of its links, and from then on makes the pairs of links weighted in later rounds
  // afresh, which gives the same values (the link values of `reuse` stay taken over in every
  // round: a static scene recomputes no link after its first key). On the 10k-triangle hall
  // the previous key's pairs had held 57 MB through every round of a key.
  std::function<void()> releaseRayPairs;
  // Frees what reuseClusterLinks points to. The solve calls it once its first round has
  // evaluated its cluster links; the few that later rounds make (a few dozen on the
  // 10k-triangle hall) are computed afresh, which gives the values the cache held. The cache
  // had been 35 MB of that hall's peak, held through every round.
  std::function<void()> releaseClusterLinks;
};

struct KeySolution {
  std::vector<SolverLink> links;
  std::vector<char> split;             // per dense node: subdivided in this key's tree
  std::vector<glm::dvec3> radiosity;   // per dense node of this key's tree (area average)
  std::vector<glm::dvec3> irradiance;  // per dense node: H gathered at it and its ancestors
  // Per dense node: the closure factor of a leaf of this key's tree (1 elsewhere, and when
  // RadiosityOptions::closure is off), for all of its links and for its good ones (shooters
  // that do not emit). Empty without closure.
  std::vector<double> closure, goodClosure;
  // Per dense node of this key's tree: the fraction of its area that is exposed, not covered by
  // a solid standing on it (see computeExposures in the .cpp); 1 without a visibility scene.
  // Its radiosity and irradiance are those of the exposed part.
  std::vector<double> exposure;
  // Per dense node: the (top, F(node -> top)) the closure computed or took over at this key.
  std::vector<std::vector<std::pair<uint32_t, double>>> leafTopFormFactor;
  // The closed-room tests of static nodes cast or taken over at this key: (node id, closed).
  std::vector<std::pair<uint64_t, bool>> closedNodes;
  // Per top-level patch: the irradiance it gathers through cluster links at the final B, over
  // its exposure (uniform over the top; no closure factor). Empty without cluster links.
  std::vector<glm::dvec3> topClusterIrradiance;
  size_t clusterLinks = 0;        // cluster links gathered (not refined)
  size_t clusterLinksReused = 0;  // of them: values taken over (reuseClusterLinks)
  // The cluster links gathered, with their values, and the clusters' bounds at this key (for
  // the next key's coherence).
  std::vector<ClusterLink> clusterLinkValues;
  std::vector<uint8_t> clusterMemberVisibility;  // ClusterLink::memberVisibility indexes it
  std::vector<ClusterBounds> clusterBounds;
  std::vector<Polygon> world;  // per dense node: world polygon at this key
  std::vector<double> area;    // per dense node: world area
  // The ray pairs of the links the radiosity weighting saw, RadiosityOptions::rays of them per
  // link from rayPairStart[link] (kNoRayPairs: none), for the next key's coherence.
  std::vector<LinkRayPair> rayPairs;
  std::vector<uint32_t> rayPairStart;
  int iterations = 0;  // Gauss-Seidel sweeps, all rounds
  int refineRounds = 0;
  bool linkCapReached = false;     // refinement stopped at RadiosityOptions::maxLinks
  size_t linksComputed = 0;        // links whose F or V was computed here
  size_t linksReused = 0;          // links whose F and V came from `reuse`
  size_t linksVisibilityOnly = 0;  // of linksComputed: F from `reuse`, V computed
  double lastChange = 0;           // relative change of the last sweep
  double secondsLinks = 0, secondsSolve = 0;

  bool inTree(int node, const PatchHierarchy& h) const {
    int parent = h.node(node).parent;
    return parent < 0 || (size_t(parent) < split.size() && split[size_t(parent)]);
  }
  // Power absorbed (sum over leaves of e A (1 - rho) H, e the exposure) and emitted (sum A B_e),
  // per channel.
  glm::dvec3 absorbedPower(const PatchHierarchy& h,
                           const std::vector<SurfaceProperties>& surfaces) const;
  glm::dvec3 emittedPower(const PatchHierarchy& h,
                          const std::vector<SurfaceProperties>& surfaces) const;
};

// One key-time solve (see the top of this file). Subdivides `hierarchy` as needed.
KeySolution solveKeyTime(PatchHierarchy& hierarchy, const std::vector<SurfaceProperties>& surfaces,
                         const KeySolveInput& input, const RadiosityOptions& options);

// The top-level links of a key-time solve (first pass above): receiver p <- shooter q for
// every ordered pair of distinct top-level patches p, q < topCount with positive area that are
// mutuallyFacing, in (p, q) order. `world` and `area` are per dense node (the top-level patches
// first). O(topCount^2): the baseline of clustering (RadiosityOptions::clustering).
std::vector<SolverLink> linkTopLevel(const std::vector<Polygon>& world,
                                     const std::vector<double>& area, int topCount);

// Unoccluded F(p -> q) of a leaf link. kAutoOrder: integrated over the smaller of the two
// with reciprocity (A_p F_pq = A_q F_qp), adaptively (to relative tolerance relTol) when the
// smaller one's centroid is nearer the other than the smaller one's size, else with a fixed
// Gauss rule whose order falls with that distance ratio; any other order:
// polygonToPolygonFormFactor(p, q, order) (one rule per receiver: exact row sums).
double linkFormFactor(const Polygon& p, const Polygon& q, int order, double relTol = 1e-5);
// kAutoOrder's two steps: the integral over the smaller patch, F(smaller -> other) (the same
// for p, q and q, p unless their areas are equal: a link and its reverse share it), and
// F(p -> q) from it by reciprocity.
double linkFormFactorIntegral(const Polygon& p, const Polygon& q, double relTol);
double linkFormFactorFrom(const Polygon& p, const Polygon& q, double fromSmaller);

// True when the top-level patches p and q can exchange energy at all: some vertex of each lies
// strictly in front of the other's plane. Each polygon's plane is made once (facingPlane), as
// one polygon meets many: the cluster refinement's patch pairs, 1.4 M a key on the 10k-triangle
// hall, tested one by one on the main thread, had recomputed both normals and centroids each.
struct FacingPlane {
  glm::dvec3 normal, centroid;
  double size = 0.0;  // polygonSize: the tolerance's scale
};
FacingPlane facingPlane(const Polygon& p);
bool mutuallyFacing(const Polygon& p, const FacingPlane& pPlane, const Polygon& q,
                    const FacingPlane& qPlane);

// Seed of the shadow rays of link (receiver <- shooter). It does not depend on the key time:
// a link whose ends and blockers did not move gets bit-identical visibility whether it is
// reused (coherent) or recomputed (--no-coherence), and its shadow does not shimmer in time.
uint64_t linkSeed(PatchId receiver, PatchId shooter);
// Seed of a receiver's shadow-ray start points (VisibilityScene::samplePoints): the same for
// all its links and its exposure, and at every key time.
uint64_t receiverSeed(PatchId receiver);

// The scene's triangles for visibility: mesh nodes static over [t0, t1] in the static BVH in
// world space, each dynamic mesh node an instance whose transform setTime() updates. Every
// triangle's surface id is its top-level patch index.
//
// Split (rad-movies' gather): the static triangles and the dynamic instances as two scenes,
// staticPart() and movingPart(), so that rays are cast against the static blockers once per
// movie and against the moving ones per key (paper §5); a ray is open when both leave it open,
// exactly the combined scene's answer. visibility() is then the static part.
class SceneVisibility {
 public:
  SceneVisibility(const Scene& scene, const PatchHierarchy& hierarchy, double t0, double t1,
                  bool split = false);
  void setTime(double t);  // sets the instance transforms and commits
  const VisibilityScene& visibility() const { return *vis_; }
  const VisibilityScene& staticPart() const { return *vis_; }
  const VisibilityScene& movingPart() const { return moving_ ? *moving_ : *vis_; }
  int dynamicNodeCount() const { return int(instances_.size()); }

 private:
  const Scene& scene_;
  std::unique_ptr<VisibilityScene> vis_;
  std::unique_ptr<VisibilityScene> moving_;     // split: the instances alone
  std::vector<std::pair<int, int>> instances_;  // (mesh node, instance id)
};

// Per top-level patch: its node moves somewhere in [t0, t1] (KeySolveInput::movingTops).
std::vector<char> movingTopsOf(const Scene& scene, const PatchHierarchy& hierarchy, double t0,
                               double t1);

// Values of `previous`'s cluster links (solved at t0) that stay valid until t1: both ends static
// over [t0, t1] and no moving node's swept bounds meeting the box around both ends (the convex
// hull of the two lies in it).
ClusterLinkCache reusableClusterLinks(const KeySolution& previous, const ClusterTree& tree,
                                      const PatchHierarchy& hierarchy, const Scene& scene,
                                      double t0, double t1);

// The cluster hierarchy of the animation [t0, t1] (KeySolveInput::clusters): static patches
// placed at t0, each moving node's in its own frame.
ClusterTree clusterTreeOf(const Scene& scene, const PatchHierarchy& hierarchy, double t0,
                          double t1);

// World transform of every top-level patch's node at time t.
std::vector<glm::dmat4> topTransforms(const Scene& scene, const PatchHierarchy& hierarchy,
                                      double t);

// Shaft culling (Haines & Wallace 1994, "Shaft culling for efficient ray-cast radiosity"):
// true when the axis-aligned box [lo, hi] may meet the convex hull of the two polygons. The
// shaft used is the hull's bounding box intersected with the prisms over the hull's three
// axis-aligned projections (a 2D convex hull each), which contains the hull: a `false` is
// exact, a `true` may be conservative.
bool shaftMeetsBox(const Polygon& a, const Polygon& b, const glm::dvec3& lo, const glm::dvec3& hi);

// The same shaft built once, for testing many boxes against one pair of polygons (rad-movies'
// blockers of one receiver and one light).
class Shaft {
 public:
  Shaft(const Polygon& a, const Polygon& b);
  bool meets(const glm::dvec3& lo, const glm::dvec3& hi) const;

 private:
  struct Edge {
    int axis;            // the projection drops this axis
    glm::dvec2 p0, out;  // a hull edge's start and outward unit normal
  };
  glm::dvec3 lo_{0.0}, hi_{0.0};
  double scale_ = 0;
  std::vector<Edge> edges_;
};

}  // namespace rad
