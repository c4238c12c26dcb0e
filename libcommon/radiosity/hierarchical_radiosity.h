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
//  * closure: each leaf's factor c that makes its row sum its own (exact in closed rooms, at
//    most 1 anywhere);
//  * exposure: each node's fraction not covered by a solid standing on it or by a surface in
//    contact with it; its links' irradiance is divided by it, so B is the radiosity of the part
//    that can be seen (computed for a link's receiver before its visibility, whose pairs from
//    covered points count as blocked);
//  * gather + push-pull (HSA'91 §5), Gauss-Seidel over the top-level patches, until the
//    relative change of B is below tol * (1 - rho_max) (the stop rule of the furnace
//    reference: a change below tol alone leaves an error of tol / (1 - rho));
//  * refine again with the new B and re-solve, until a round refines nothing.
//
// Every key time works on one shared PatchHierarchy (the union over key times): a key's own
// tree is the set of nodes it split (KeySolution::split). Node indices are dense indices of
// that hierarchy; patch ids (PatchId) are what stays the same from key to key.
//
// Its pieces, one idea a file: the options (radiosity_options.h), the link records and the
// values taken over between key times (link_records.h), a link's geometry (link_form_factor.h),
// and the solver whose passes this header lists (key_time_solver.h, private). What the
// space-time pass gives each solve from the animated scene is key_solve_inputs.h.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/radiosity/cluster_links.h"
#include "libcommon/radiosity/cluster_tree.h"
#include "libcommon/radiosity/lamp_irradiance.h"
#include "libcommon/radiosity/link_records.h"
#include "libcommon/radiosity/radiosity_options.h"
#include "libcommon/radiosity/visibility.h"
#include "libcommon/scene/patch_hierarchy.h"
#include "libcommon/scene/scene.h"

namespace rad {

// Diffuse reflectance and emitted radiosity B_e = pi L_e (W/m^2) of one top-level patch.
struct SurfaceProperties {
  glm::dvec3 reflectance{0.0};
  glm::dvec3 emission{0.0};
  bool doubleSided = false;  // the material is doubleSided: its back is a surface too
  // Its mesh is a closed solid with faces out (closed_solid.h): the winding gives the outside
  // even when the material is doubleSided.
  bool closedSolid = false;
  bool backFace = false;  // the reversed copy of a doubleSided polygon (InputPolygon::backFace)
  bool isEmitter() const { return emission.x > 0 || emission.y > 0 || emission.z > 0; }
  // The normal of the solid's outside at this patch, from its geometric normal n: -n for the
  // reversed copy of a closed solid's face, else n (a one-sided patch's back is its inside).
  glm::dvec3 outwardNormal(const glm::dvec3& n) const {
    return doubleSided && closedSolid && backFace ? -n : n;
  }
  // Whether this patch bounds a solid (one-sided, or a face of a closed solid), so that a ray
  // meeting it from behind outwardNormal starts inside (rad-global's exposure).
  bool boundsSolid() const { return !doubleSided || closedSolid; }
  // Whether a ray along d that first meets this patch (geometric normal n) starts inside a solid.
  bool entersFromInside(const glm::dvec3& n, const glm::dvec3& d) const {
    return boundsSolid() && glm::dot(outwardNormal(n), d) > 0.0;
  }
};
// From the scene's materials (reflectance clamped to [0, 1]; the glTF default material is
// white) and the tops' InputPolygon::closedSolid.
std::vector<SurfaceProperties> surfacePropertiesOf(const Scene& scene,
                                                   const PatchHierarchy& hierarchy);

struct KeySolveInput {
  std::vector<glm::dmat4> topToWorld;           // per top-level patch: its node's world transform
  const VisibilityScene* visibility = nullptr;  // null: every link fully visible
  const LinkCache* reuse = nullptr;             // coherence: values to take over
  // The previous key's link and ray pair counts (0: none): this key's make about as many, so
  // its vectors are reserved once with a margin instead of doubling as they grow (doubling holds
  // up to twice their size at the peak).
  size_t expectedLinks = 0, expectedRayPairs = 0, expectedClusterLinks = 0;
  // coherence: the previous key's KeySolution::rayPairs (CachedLink::rayPairs indexes them)
  const std::vector<LinkRayPair>* reuseRayPairs = nullptr;
  // coherence: the closure's, moved into the solve at its first closure (not copied: a copy
  // would be held beside it through the key's solve)
  LeafFormFactorCache* reuseLeafFormFactors = nullptr;
  const ClosedNodeCache* reuseClosed = nullptr;  // coherence: closed-room tests
  // coherence: the previous key's KeySolution::coveredPoints. A link taken over keeps its V only
  // where its receiver's covered points are the same at this key (a moving object can change
  // which ray start points are covered), else its rays are cast again.
  const std::vector<uint64_t>* reuseCoveredPoints = nullptr;
  // Per top-level patch: it moves at some time of the animation. The closure corrects only
  // pairs of patches that never move (empty: none moves).
  std::vector<char> movingTops;
  // The cluster hierarchy to link from (cluster_links.h); null or empty: linkTopLevel.
  const ClusterTree* clusters = nullptr;
  const ClusterLinkCache* reuseClusterLinks = nullptr;  // coherence: cluster link values
  // Frees what reuseRayPairs points to. The solve calls it once its first round has copied the
  // pairs of its links, and from then on makes the pairs of links weighted in later rounds
  // afresh, which gives the same values (the link values of `reuse` stay taken over in every
  // round: a static scene recomputes no link after its first key). Freed early because the
  // previous key's pairs would otherwise be held through every round of the key.
  std::function<void()> releaseRayPairs;
  // Frees what reuseClusterLinks points to. The solve calls it once its first round has
  // evaluated its cluster links; the few that later rounds make are computed afresh, which
  // gives the values the cache held, and the cache is not held through every round.
  std::function<void()> releaseClusterLinks;
  // The scene's punctual lamps placed at this key (docs/design.md §4 "Lights"; at most
  // kMaxLamps), owned by the caller: no patch and no link, a direct irradiance E per receiver
  // leaf (lamp_irradiance.h) in $B = B_e + \rho (E + H)$, whose variation the oracle refines.
  std::vector<const PlacedPunctualLight*> lamps;
  const LampValueCache* reuseLamps = nullptr;  // coherence: lamp values to take over
};

struct KeySolution {
  std::vector<SolverLink> links;
  std::vector<char> split;             // per dense node: subdivided in this key's tree
  std::vector<glm::dvec3> radiosity;   // per dense node of this key's tree (area average)
  std::vector<glm::dvec3> irradiance;  // per dense node: H gathered at it and its ancestors
  // Per dense node: the lamps' direct E at a leaf of this key's tree, over its exposure (0
  // elsewhere, and without lamps). Not in `irradiance`: the second pass computes it per texel.
  std::vector<glm::dvec3> lampIrradiance;
  // The lamps' values computed or taken over at this key, for the next key's coherence.
  LampValueCache lampValues;
  size_t lampValuesReused = 0;  // of them: taken over (KeySolveInput::reuseLamps)
  // Per dense node: the closure factor of a leaf of this key's tree (1 elsewhere, and when
  // RadiosityOptions::closure is off), for all of its links and for its good ones (shooters
  // that do not emit). Empty without closure.
  std::vector<double> closure, goodClosure;
  // Per dense node of this key's tree: the fraction of its area that is exposed, not covered by
  // a solid standing on it (see computeExposures in the .cpp); 1 without a visibility scene.
  // Its radiosity and irradiance are those of the exposed part.
  std::vector<double> exposure;
  // Per dense node exposed at this key: bit k set when its ray start point k (< 64) is covered
  // (key_time_exposure.cpp); 0 elsewhere.
  std::vector<uint64_t> coveredPoints;
  // Per dense node: the (top, F(node -> top)) the closure computed or took over at this key.
  std::vector<std::vector<std::pair<uint32_t, double>>> leafTopFormFactor;
  // The closed-room tests of static nodes cast or taken over at this key: (node id, closed).
  std::vector<std::pair<uint64_t, bool>> closedNodes;
  // Per top-level patch: the irradiance it gathers through cluster links at the final B, over
  // its exposure (uniform over the top; no closure factor). Empty without cluster links.
  std::vector<glm::dvec3> topClusterIrradiance;
  LinkCensus linkCensus;          // the key's links by kind at the end of its refinement
  size_t clusterLinks = 0;        // cluster links gathered (not refined)
  size_t clusterLinksReused = 0;  // of them: values taken over (reuseClusterLinks)
  // The cluster links gathered, with their values, and the clusters' bounds at this key (for
  // the next key's coherence).
  std::vector<ClusterLink> clusterLinkValues;
  std::vector<uint8_t> clusterMemberVisibility;  // ClusterLink::memberVisibility indexes it
  // The near cluster links tested for being blocked, with the answer (cluster_links.h), for
  // the next key's coherence.
  std::vector<NearLinkTest> clusterNearTests;
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

}  // namespace rad
