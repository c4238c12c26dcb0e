// Hierarchical radiosity at one key time (Hanrahan, Salzman, Aupperle 1991); see the header.
// The driver of the key-time solver's passes (key_time_solver.h): the rounds in order, the
// thresholds, and the solution handed back; the passes are in key_time_*.cpp.
// The figures behind the reasons given here: docs/results.md, "Figures moved out of the radiosity
// code's comments (issue 55)".
#include "libcommon/radiosity/hierarchical_radiosity.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <tuple>

#include "libcommon/core/error.h"
#include "libcommon/core/stopwatch.h"
#include "libcommon/radiosity/key_time_solver.h"
#include "libcommon/scene/emission_texture.h"

namespace rad {

std::vector<SurfaceProperties> surfacePropertiesOf(const Scene& scene,
                                                   const PatchHierarchy& hierarchy) {
  std::vector<SurfaceProperties> out(size_t(hierarchy.topCount()));
  for (int t = 0; t < hierarchy.topCount(); ++t) {
    const InputPolygon& top = hierarchy.top(t);
    out[size_t(t)].closedSolid = top.closedSolid;  // set once per mesh by Scene::inputPolygons
    out[size_t(t)].backFace = top.backFace;
    int m = top.material;
    if (m >= 0 && m < int(scene.materials.size())) {
      const Material& mat = scene.materials[size_t(m)];
      out[size_t(t)].reflectance = glm::clamp(mat.reflectance, glm::dvec3(0.0), glm::dvec3(1.0));
      // B_e = pi L_e, L_e the mean over the patch of an emissive texture (emission_texture.h).
      out[size_t(t)].emission =
          glm::max(meanEmissionOver(scene, hierarchy.top(t)), glm::dvec3(0.0)) * M_PI;
      out[size_t(t)].doubleSided = mat.doubleSided;
    } else {
      // glTF default material: white (rho 1, kept below 1 as a file's are: the solve needs
      // rho < 1), no emission.
      out[size_t(t)].reflectance = glm::dvec3(kMaxReflectance);
    }
  }
  return out;
}

glm::dvec3 KeySolution::absorbedPower(const PatchHierarchy& h,
                                      const std::vector<SurfaceProperties>& surfaces) const {
  glm::dvec3 sum(0.0);
  for (size_t i = 0; i < split.size(); ++i) {
    if (split[i] || !inTree(int(i), h)) continue;
    const SurfaceProperties& s = surfaces[h.node(int(i)).id.top];
    const double e = i < exposure.size() ? exposure[i] : 1.0;
    const glm::dvec3 lamp = i < lampIrradiance.size() ? lampIrradiance[i] : glm::dvec3(0.0);
    sum += e * area[i] * (glm::dvec3(1.0) - s.reflectance) * (irradiance[i] + lamp);
  }
  return sum;
}

glm::dvec3 KeySolution::emittedPower(const PatchHierarchy& h,
                                     const std::vector<SurfaceProperties>& surfaces) const {
  glm::dvec3 sum(0.0);
  for (int t = 0; t < h.topCount(); ++t) sum += area[size_t(t)] * surfaces[size_t(t)].emission;
  return sum;
}

std::vector<SolverLink> linkTopLevel(const std::vector<Polygon>& world,
                                     const std::vector<double>& area, int topCount) {
  std::vector<SolverLink> links;
  std::vector<FacingPlane> plane(static_cast<size_t>(topCount));
  for (int t = 0; t < topCount; ++t) plane[size_t(t)] = facingPlane(world[size_t(t)]);
  for (int p = 0; p < topCount; ++p)
    for (int q = 0; q < topCount; ++q)
      if (p != q && area[size_t(p)] > 0 && area[size_t(q)] > 0 &&
          mutuallyFacing(world[size_t(p)], plane[size_t(p)], world[size_t(q)], plane[size_t(q)])) {
        SolverLink l;
        l.receiver = p;
        l.shooter = q;
        links.push_back(l);
      }
  return links;
}

KeySolution KeyTimeSolver::run() {
  if (input_.expectedLinks > 0) s_.links.reserve(withMargin(input_.expectedLinks));
  if (input_.clusters && !input_.clusters->empty()) {
    topEmission_.resize(size_t(h_.topCount()));
    for (int t = 0; t < h_.topCount(); ++t)
      topEmission_[size_t(t)] = maxComponent(surfaces_[size_t(t)].emission);
    clusters_ = std::make_unique<ClusterLinks>(*input_.clusters, s_.world, s_.area, topEmission_,
                                               input_.visibility, opt_.rays, opt_.clusterSeparation,
                                               opt_.lightClusterShare, opt_.clusterMemberRays,
                                               opt_.isotropicClusters, input_.reuseClusterLinks);
    clusters_->keepWeakNearLinks(opt_.keepWeakNearLinks);
    clusters_->nearBlockRays(opt_.nearBlockRays);
    if (input_.expectedClusterLinks > 0)
      clusters_->expectLinks(withMargin(input_.expectedClusterLinks));
  } else {
    s_.links = linkTopLevel(s_.world, s_.area, h_.topCount());
  }
  for (int round = 0;; ++round) {
    auto tl = std::chrono::steady_clock::now();
    size_t refined = clusters_ ? refineClusterLinks() : 0;
    if (refineOn_)
      refined += refine(unrefinedLinks());
    else
      evaluateNewLinks();
    refined += refineLamps();
    if (round > 0 && refined == 0) {
      s_.secondsLinks += secondsSince(tl);
      break;
    }
    computeAccurateFormFactors();
    weightVisibilityByShooterRadiosity();
    if (round == 0) releaseRayPairs();
    computeExposures();  // the closure of a closed leaf divides by them too
    if (clusters_) clusterRow_ = clusters_->rowSums(exposure_);
    if (opt_.closure) computeClosure();
    s_.secondsLinks += secondsSince(tl);
    auto ts = std::chrono::steady_clock::now();
    solve();
    raiseThresholdToCarriedPower();
    measureShooterRanges();
    s_.secondsSolve += secondsSince(ts);
    s_.refineRounds = round + 1;
    if (!refineOn_ || round + 1 >= opt_.maxRefineRounds) break;
  }
  return finish();
}

// After the first round: the previous key's ray pairs are no longer copied, and their owner
// frees them (KeySolveInput::releaseRayPairs).
void KeyTimeSolver::releaseRayPairs() {
  if (!reuseRayPairs_) return;
  reuseRayPairs_ = nullptr;
  if (input_.releaseRayPairs) input_.releaseRayPairs();
}

// World geometry and starting radiosity of the nodes of the union hierarchy this solve has
// not seen yet (the ones made before it, then the ones each subdivision appends). A node
// starts with its parent's B, a top-level patch with its emission.
void KeyTimeSolver::addNewNodes() {
  for (int i = int(s_.world.size()); i < h_.size(); ++i) {
    const PatchNode& n = h_.node(i);
    s_.world.push_back(n.local.transformed(input_.topToWorld[n.id.top]));
    s_.area.push_back(s_.world.back().area());
    s_.split.push_back(0);
    B_.push_back(n.parent >= 0 ? B_[size_t(n.parent)] : surfaces_[n.id.top].emission);
    lampE_.push_back(glm::dvec3(0.0));
    lampSpread_.push_back(0.0);
    lampKnown_.push_back(0);
  }
}

// The absolute refinement threshold eps * Phi (Phi = largest emitted power over the colour
// channels) and the stop rule tol * (1 - rho_max) of the Gauss-Seidel sweeps.
void KeyTimeSolver::setThresholds() {
  glm::dvec3 emitted(0.0);
  double rhoMax = 0.0, emissionMax = 0.0;
  for (int t = 0; t < h_.topCount(); ++t) {
    emitted += s_.area[size_t(t)] * surfaces_[size_t(t)].emission;
    rhoMax = std::max(rhoMax, maxComponent(surfaces_[size_t(t)].reflectance));
    emissionMax = std::max(emissionMax, maxComponent(surfaces_[size_t(t)].emission));
  }
  // No patch gathers more than the whole hemisphere (form factors sum to <= 1), so a solve is
  // bounded by $B \le E_{max} / (1 - \rho_{max})$ (the furnace's B everywhere). Sweeps may
  // overshoot that while refinement is under way (the furnace at high rho does, on the way to a
  // finite answer), so only a solve a million times above it is called diverging: at rho x rowsum =
  // 1.002 (the furnace at rho = 0.999) that takes ~7000 sweeps, long before B overflows to Inf and
  // NaN, which the stop rule's std::max would not see.
  // A lamp's E has no such bound (I / d^2 near it): with lamps only non-finite B is caught.
  radiosityBound_ = rhoMax < 1.0 && input_.lamps.empty() ? 1e6 * emissionMax / (1.0 - rhoMax)
                                                         : std::numeric_limits<double>::infinity();
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
  for (int t = 0; t < h_.topCount(); ++t)
    for (int k = 0; k < s_.world[size_t(t)].count; ++k) {
      lo = glm::min(lo, s_.world[size_t(t)].v[size_t(k)]);
      hi = glm::max(hi, s_.world[size_t(t)].v[size_t(k)]);
    }
  contactDistance_ =
      h_.topCount() > 0 ? VisibilityScene::kSegmentEpsilon * glm::length(hi - lo) : 0.0;
  emittedPower_ = maxComponent(emitted) + lampPower();
  epsAbs_ = opt_.eps * emittedPower_;
  refineOn_ = opt_.refine && epsAbs_ > 0.0;
  stopChange_ = opt_.tol * std::max(1.0 - rhoMax, 1e-6);
}

// The oracle where B >> E (rho -> 1): eps is relative to the power the surfaces carry,
// $\Phi = \max_c \sum_t A_t B_t$ of the last solve, once that exceeds the emitted power. The
// emitted power alone made the threshold 1 / (1 - rho) times too strict in a furnace, which
// at rho = 0.999 refined every link down to the link bound; relative to the power carried, a
// furnace refines the same whatever rho, and the closure keeps its row sums exact.
void KeyTimeSolver::raiseThresholdToCarriedPower() {
  glm::dvec3 carried(0.0);
  for (int t = 0; t < h_.topCount(); ++t) carried += s_.area[size_t(t)] * B_[size_t(t)];
  epsAbs_ = std::max(epsAbs_, opt_.eps * maxComponent(carried));
}

KeySolution KeyTimeSolver::finish() {
  for (const SolverLink& l : s_.links) {
    (l.reused ? s_.linksReused : s_.linksComputed)++;
    s_.linksVisibilityOnly += l.visibilityOnly ? 1 : 0;
  }
  countLinks();
  if (clusters_) {               // at the final B, as the merge gathers the patch links
    if (clusters_->reusing()) {  // held to the end (refineClusterLinks)
      clusters_->forgetReuse();
      if (input_.releaseClusterLinks) input_.releaseClusterLinks();
    }
    gatherClusterLight();
    s_.topClusterIrradiance = clusterH_;
    s_.clusterLinks = clusters_->size();
    s_.clusterLinksReused = clusters_->reusedCount();
    s_.clusterBounds = clusters_->clusterBounds();
    s_.clusterNearTests = clusters_->nearTests();
    // Moved out, and the rest of the cluster links (their gather lists) freed here, not when the
    // solver goes: a copy held beside them until then would raise rad-global's peak at the end of
    // each key's solve.
    s_.clusterLinkValues = std::move(*clusters_).takeLinks();
    s_.clusterMemberVisibility = std::move(*clusters_).takeMemberVisibility();
    clusters_.reset();
  }
  s_.radiosity = std::move(B_);
  pairStart_.resize(s_.links.size(), kNoRayPairs);
  s_.rayPairStart = std::move(pairStart_);
  s_.rayPairs = std::move(pairs_);
  s_.leafTopFormFactor = std::move(leafTopFormFactor_);
  for (size_t i = 0; i < closed_.size(); ++i)
    if (closed_[i] >= 0 && !moves(h_.node(int(i)).id.top))
      s_.closedNodes.push_back({h_.node(int(i)).id.packed(), closed_[i] != 0});
  s_.coveredPoints = std::move(coveredPoints_);
  s_.exposure = std::move(exposure_);
  s_.exposure.resize(size_t(h_.size()), 1.0);
  for (double& e : s_.exposure)
    if (e < 0.0) e = 1.0;  // not in this key's tree
  s_.irradiance = std::move(irr_);
  s_.irradiance.resize(size_t(h_.size()), glm::dvec3(0.0));
  if (!input_.lamps.empty()) {
    s_.lampIrradiance.assign(size_t(h_.size()), glm::dvec3(0.0));
    for (size_t i = 0; i < s_.split.size(); ++i)
      if (!s_.split[i] && s_.inTree(int(i), h_) && s_.exposure[i] > 0.0)
        s_.lampIrradiance[i] = lampE_[i] / s_.exposure[i];
  }
  return std::move(s_);
}

// The key's links by kind (link_census.h), before the cluster links are handed on.
void KeyTimeSolver::countLinks() {
  LinkCensus& c = s_.linkCensus;
  for (const SolverLink& l : s_.links) {
    if (l.refined) {
      ++c.patchRefined;
      continue;
    }
    ++c.patchLeaves;
    const uint32_t r = h_.node(l.receiver).id.top, q = h_.node(l.shooter).id.top;
    c.patchLight += maxComponent(surfaces_[q].emission) > 0.0 ? 1 : 0;
    c.patchBlocked += l.rayVisibility == 0.0 ? 1 : 0;
    c.patchNearTops += clusters_ && clusters_->near(ClusterRef(r), ClusterRef(q)) ? 1 : 0;
  }
  if (clusters_) clusters_->countInto(c);
}

KeySolution solveKeyTime(PatchHierarchy& h, const std::vector<SurfaceProperties>& surfaces,
                         const KeySolveInput& input, const RadiosityOptions& opt) {
  const int T = h.topCount();
  if (int(surfaces.size()) != T || int(input.topToWorld.size()) != T)
    throw Error(ExitCode::kInternal, "", "solveKeyTime: per-top arrays have the wrong size");
  return KeyTimeSolver(h, surfaces, input, opt).run();
}

}  // namespace rad
