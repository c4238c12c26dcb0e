// Hierarchical radiosity at one key time (Hanrahan, Salzman, Aupperle 1991); see the header.
#include "libcommon/radiosity/hierarchical_radiosity.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "libcommon/core/error.h"
#include "libcommon/core/stopwatch.h"
#include "libcommon/radiosity/cluster_links.h"
#include "libcommon/radiosity/global_solution.h"

namespace rad {

namespace {

double maxComponent(const glm::dvec3& v) {
  return std::max(v.x, std::max(v.y, v.z));
}

// Some vertex of `p` lies strictly in front of the plane of `q`.
bool someVertexInFront(const Polygon& p, const FacingPlane& pPlane, const FacingPlane& qPlane) {
  if (qPlane.normal == glm::dvec3(0.0)) return false;
  const double tol = 1e-12 * std::max(pPlane.size, qPlane.size);
  for (int i = 0; i < p.count; ++i)
    if (glm::dot(qPlane.normal, p.v[i] - qPlane.centroid) > tol) return true;
  return false;
}

// 2D convex hull (Andrew's monotone chain), counter-clockwise, collinear points dropped.
std::vector<glm::dvec2> convexHull2d(std::vector<glm::dvec2> p) {
  std::sort(p.begin(), p.end(), [](const glm::dvec2& a, const glm::dvec2& b) {
    return a.x < b.x || (a.x == b.x && a.y < b.y);
  });
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return p;
  auto cross = [](const glm::dvec2& o, const glm::dvec2& a, const glm::dvec2& b) {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
  };
  std::vector<glm::dvec2> h(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (size_t i = p.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(h[k - 2], h[k - 1], p[i - 1]) <= 0) --k;
    h[k++] = p[i - 1];
  }
  h.resize(k - 1);
  return h;
}

}  // namespace

RefinementOracle parseRefinementOracle(const std::string& name) {
  if (name == "power") return RefinementOracle::kPower;
  if (name == "error") return RefinementOracle::kError;
  if (name == "both") return RefinementOracle::kBoth;
  throw Error(ExitCode::kUsage, "",
              "refinement oracle '" + name + "'; expected power, error or both");
}

const char* refinementOracleName(RefinementOracle oracle) {
  switch (oracle) {
    case RefinementOracle::kPower:
      return "power";
    case RefinementOracle::kError:
      return "error";
    case RefinementOracle::kBoth:
      return "both";
  }
  return "?";
}

double linkFormFactor(const Polygon& p, const Polygon& q, int order, double relTol) {
  if (order != kAutoOrder) return polygonToPolygonFormFactor(p, q, order);
  return linkFormFactorFrom(p, q, linkFormFactorIntegral(p, q, relTol));
}

double linkFormFactorIntegral(const Polygon& p, const Polygon& q, double relTol) {
  // Integrate over the smaller patch and use reciprocity: a Gauss rule on the larger one misses
  // the log-singular strip along a shared edge (README of the reference: perp_common_edge_*).
  const bool swap = p.area() > q.area();
  const Polygon& from = swap ? q : p;
  const Polygon& to = swap ? p : q;
  // How near is measured against the patch integrated over (areaAverageFormFactor's rule, with
  // the adaptive rule up to a ratio of 1 so that shared edges stay adaptive): F(x -> to) varies
  // over `from` on the scale of x's distance to `to`, whatever `to`'s size. The larger patch's
  // size had made every pair with a giant patch adaptive (issue 18: a mutated vertex 1e10 m
  // away cost 5x as much per link).
  return areaAverageFormFactor(from, to, relTol, 1.0);
}

double linkFormFactorFrom(const Polygon& p, const Polygon& q, double fromSmaller) {
  const double ap = p.area(), aq = q.area();
  return ap > aq ? std::min(1.0, fromSmaller * aq / ap) : fromSmaller;
}

std::vector<SurfaceProperties> surfacePropertiesOf(const Scene& scene,
                                                   const PatchHierarchy& hierarchy) {
  std::vector<SurfaceProperties> out(size_t(hierarchy.topCount()));
  for (int t = 0; t < hierarchy.topCount(); ++t) {
    int m = hierarchy.top(t).material;
    if (m >= 0 && m < int(scene.materials.size())) {
      const Material& mat = scene.materials[size_t(m)];
      out[size_t(t)].reflectance = glm::clamp(mat.reflectance, glm::dvec3(0.0), glm::dvec3(1.0));
      out[size_t(t)].emission = glm::max(mat.emission, glm::dvec3(0.0)) * M_PI;  // B_e = pi L_e
      out[size_t(t)].doubleSided = mat.doubleSided;
    } else {
      // glTF default material: white (rho 1, kept below 1 as a file's are: the solve needs
      // rho < 1), no emission.
      out[size_t(t)].reflectance = glm::dvec3(kMaxReflectance);
    }
  }
  return out;
}

FacingPlane facingPlane(const Polygon& p) {
  return {p.normal(), p.centroid(), polygonSize(p)};
}

bool mutuallyFacing(const Polygon& p, const FacingPlane& pPlane, const Polygon& q,
                    const FacingPlane& qPlane) {
  return someVertexInFront(p, pPlane, qPlane) && someVertexInFront(q, qPlane, pPlane);
}

uint64_t linkSeed(PatchId receiver, PatchId shooter) {
  return splitMix64(splitMix64(splitMix64(receiver.packed()) ^ shooter.packed()) +
                    0x9E3779B97F4A7C15ull);
}

uint64_t receiverSeed(PatchId receiver) {
  return splitMix64(splitMix64(receiver.packed()) ^ 0xA0761D6478BD642Full);
}

glm::dvec3 KeySolution::absorbedPower(const PatchHierarchy& h,
                                      const std::vector<SurfaceProperties>& surfaces) const {
  glm::dvec3 sum(0.0);
  for (size_t i = 0; i < split.size(); ++i) {
    if (split[i] || !inTree(int(i), h)) continue;
    const SurfaceProperties& s = surfaces[h.node(int(i)).id.top];
    const double e = i < exposure.size() ? exposure[i] : 1.0;
    sum += e * area[i] * (glm::dvec3(1.0) - s.reflectance) * irradiance[i];
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

namespace {

// A link's index in a key solve's links: 32 bits (RadiosityOptions::maxLinks is at most
// kMaxLinkBound), half the size_t lists of links the refinement and the gather hold.
using LinkIndex = uint32_t;

// One key-time solve as its named passes (see the header): link top level, then rounds of
// evaluate + refine, accurate pass, gather + push-pull, until a round refines nothing. The
// passes share the solution being built, the radiosity B of every node and the thresholds.
class KeyTimeSolver {
 public:
  KeyTimeSolver(PatchHierarchy& h, const std::vector<SurfaceProperties>& surfaces,
                const KeySolveInput& input, const RadiosityOptions& opt)
      : h_(h), surfaces_(surfaces), input_(input), opt_(opt) {
    addNewNodes();
    setThresholds();
  }

  // A vector's size from the previous key's, with a margin: this key makes about as many, so
  // its vectors are reserved once instead of doubling as they grow (KeySolveInput::expected*).
  static size_t withMargin(size_t n) { return n + n / 32 + 1024; }

  KeySolution run() {
    if (input_.expectedLinks > 0) s_.links.reserve(withMargin(input_.expectedLinks));
    if (input_.clusters && !input_.clusters->empty()) {
      topEmission_.resize(size_t(h_.topCount()));
      for (int t = 0; t < h_.topCount(); ++t)
        topEmission_[size_t(t)] = maxComponent(surfaces_[size_t(t)].emission);
      clusters_ = std::make_unique<ClusterLinks>(
          *input_.clusters, s_.world, s_.area, topEmission_, input_.visibility, opt_.rays,
          opt_.clusterSeparation, opt_.lightClusterShare, opt_.clusterMemberRays,
          opt_.isotropicClusters, input_.reuseClusterLinks);
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

 private:
  // After the first round: the previous key's ray pairs are no longer copied, and their owner
  // frees them (KeySolveInput::releaseRayPairs).
  void releaseRayPairs() {
    if (!reuseRayPairs_) return;
    reuseRayPairs_ = nullptr;
    if (input_.releaseRayPairs) input_.releaseRayPairs();
  }

  // World geometry and starting radiosity of the nodes of the union hierarchy this solve has
  // not seen yet (the ones made before it, then the ones each subdivision appends). A node
  // starts with its parent's B, a top-level patch with its emission.
  void addNewNodes() {
    for (int i = int(s_.world.size()); i < h_.size(); ++i) {
      const PatchNode& n = h_.node(i);
      s_.world.push_back(n.local.transformed(input_.topToWorld[n.id.top]));
      s_.area.push_back(s_.world.back().area());
      s_.split.push_back(0);
      B_.push_back(n.parent >= 0 ? B_[size_t(n.parent)] : surfaces_[n.id.top].emission);
    }
  }

  // The absolute refinement threshold eps * Phi (Phi = largest emitted power over the colour
  // channels) and the stop rule tol * (1 - rho_max) of the Gauss-Seidel sweeps.
  void setThresholds() {
    glm::dvec3 emitted(0.0);
    double rhoMax = 0.0, emissionMax = 0.0;
    for (int t = 0; t < h_.topCount(); ++t) {
      emitted += s_.area[size_t(t)] * surfaces_[size_t(t)].emission;
      rhoMax = std::max(rhoMax, maxComponent(surfaces_[size_t(t)].reflectance));
      emissionMax = std::max(emissionMax, maxComponent(surfaces_[size_t(t)].emission));
    }
    // No patch gathers more than the whole hemisphere (form factors sum to <= 1), so a solve
    // is bounded by $B \le E_{max} / (1 - \rho_{max})$ (the furnace's B everywhere). Sweeps may
    // overshoot that while refinement is under way (the furnace at rho = 0.99 passes 2x on the
    // way to a finite answer), so only a solve a million times above it is called diverging:
    // at rho x rowsum = 1.002 (the furnace at rho = 0.999) that takes ~7000 sweeps, long before
    // B overflows to Inf and NaN, which the stop rule's std::max would not see.
    radiosityBound_ =
        rhoMax < 1.0 ? 1e6 * emissionMax / (1.0 - rhoMax) : std::numeric_limits<double>::infinity();
    epsAbs_ = opt_.eps * maxComponent(emitted);
    refineOn_ = opt_.refine && epsAbs_ > 0.0;
    stopChange_ = opt_.tol * std::max(1.0 - rhoMax, 1e-6);
  }

  // The oracle where B >> E (rho -> 1): eps is relative to the power the surfaces carry,
  // $\Phi = \max_c \sum_t A_t B_t$ of the last solve, once that exceeds the emitted power. The
  // emitted power alone made the threshold 1 / (1 - rho) times too strict in a furnace, which
  // at rho = 0.999 refined every link down to the link bound; relative to the power carried, a
  // furnace refines the same whatever rho, and the closure keeps its row sums exact.
  void raiseThresholdToCarriedPower() {
    glm::dvec3 carried(0.0);
    for (int t = 0; t < h_.topCount(); ++t) carried += s_.area[size_t(t)] * B_[size_t(t)];
    epsAbs_ = std::max(epsAbs_, opt_.eps * maxComponent(carried));
  }

  // Cluster links (cluster_links.h): one round of their refinement with this round's B and
  // threshold (all the way down to patch pairs when refinement is off: the all-pairs linking);
  // the pairs of top-level patches reached become patch links, appended in the order reached.
  size_t refineClusterLinks() {
    std::vector<std::pair<int, int>> pairs;
    const size_t held = s_.links.size() + clusters_->size();
    const size_t budget = opt_.maxLinks > held ? opt_.maxLinks - held : 0;
    bool overBudget = false;
    const size_t refined = clusters_->refine(epsAbs_, !refineOn_, budget, pairs, overBudget);
    if (overBudget || s_.links.size() + clusters_->size() + pairs.size() > opt_.maxLinks)
      s_.linkCapReached = true;
    if (topPlanes_.empty()) {  // the tops' planes at this key, once
      topPlanes_.resize(size_t(h_.topCount()));
      tbb::parallel_for(size_t(0), topPlanes_.size(),
                        [&](size_t t) { topPlanes_[t] = facingPlane(s_.world[t]); });
    }
    std::vector<char> facing(pairs.size());
    tbb::parallel_for(size_t(0), pairs.size(), [&](size_t i) {
      const size_t r = size_t(pairs[i].first), q = size_t(pairs[i].second);
      facing[i] = s_.area[r] > 0 && s_.area[q] > 0 &&
                  mutuallyFacing(s_.world[r], topPlanes_[r], s_.world[q], topPlanes_[q]);
    });
    for (size_t i = 0; i < pairs.size(); ++i)
      if (facing[i]) {
        SolverLink l;
        l.receiver = pairs[i].first;
        l.shooter = pairs[i].second;
        s_.links.push_back(l);
      }
    clusters_->evaluate();
    if (input_.releaseClusterLinks && clusters_->reusing()) {
      clusters_->forgetReuse();
      input_.releaseClusterLinks();
    }
    return refined;
  }

  // Per node of this key's tree: the range (max - min over the colour channel of largest
  // range) of B over the leaves below it, from the last solve; 0 for a leaf.
  void measureShooterRanges() {
    const size_t N = size_t(h_.size());
    std::vector<glm::dvec3> lo(N), hi(N);
    shooterRange_.assign(N, 0.0);
    for (size_t i = N; i-- > 0;) {  // children (higher indices) before their parent
      if (!s_.inTree(int(i), h_)) continue;
      if (!s_.split[i]) {
        lo[i] = hi[i] = B_[i];
        continue;
      }
      const int first = h_.node(int(i)).firstChild;
      lo[i] = lo[size_t(first)], hi[i] = hi[size_t(first)];
      for (int c = 1; c < 4; ++c) {
        lo[i] = glm::min(lo[i], lo[size_t(first + c)]);
        hi[i] = glm::max(hi[i], hi[size_t(first + c)]);
      }
      shooterRange_[i] = maxComponent(hi[i] - lo[i]);
    }
  }

  // Evaluate: the oracle's estimate F~ (and spread) and the visibility V of every link made
  // since the last call, in parallel (each link writes only itself).
  void evaluateNewLinks() {
    size_t begin = evaluated_, end = s_.links.size();
    tbb::parallel_for(begin, end, [&](size_t li) { evaluateLink(s_.links[li]); });
    evaluated_ = end;
  }

  void evaluateLink(SolverLink& l) const {
    const PatchNode& r = h_.node(l.receiver);
    const PatchNode& q = h_.node(l.shooter);
    const Polygon& P = s_.world[size_t(l.receiver)];
    const Polygon& Q = s_.world[size_t(l.shooter)];
    auto shadowRays = [&] {
      l.openPairs = ~uint64_t(0);
      return input_.visibility
                 ? input_.visibility->visibilityFrom(
                       VisibilityScene::samplePoints(P, opt_.rays, receiverSeed(r.id)), P.normal(),
                       Q, linkSeed(r.id, q.id), r.id.top, q.id.top, &l.openPairs)
                 : 1.0;
    };
    if (input_.reuse) {
      const uint32_t known = input_.reuse->indexOf(uint32_t(l.receiver), uint32_t(l.shooter));
      if (known != LinkCache::kNotFound) {
        // The values, never a decision: F starts as the estimate as in a fresh evaluation,
        // and the accurate pass takes the known accurate F instead of integrating again.
        const CachedLink& c = input_.reuse->value(known);
        l.known = known;
        l.estimate = c.estimate;
        l.spreadArea = c.spreadArea;
        l.formFactor = l.estimate;
        if (c.visibilityValid) {
          l.rayVisibility = c.visibility;
          l.openPairs = c.openPairs;
          l.reused = true;
        } else {
          l.rayVisibility = shadowRays();
          l.visibilityOnly = true;
        }
        l.visibility = l.rayVisibility;
        return;
      }
    }
    double ap = s_.area[size_t(l.receiver)], aq = s_.area[size_t(l.shooter)];
    // Both directions: the centroid estimate alone can miss a near-contact pair.
    const double fpq = formFactorEstimate(P, Q), fqp = formFactorEstimate(Q, P);
    l.estimate = float(std::min(1.0, std::max(fpq, fqp * aq / ap)));
    l.formFactor = l.estimate;
    if (opt_.oracle != RefinementOracle::kPower)
      l.spreadArea =
          float(std::max(ap * formFactorSpread(P, Q, fpq), aq * formFactorSpread(Q, P, fqp)));
    l.rayVisibility = shadowRays();
    l.visibility = l.rayVisibility;
  }

  // Radiosity-weighted visibility (before each solve): a link's shooter bright where the
  // receiver cannot see it and dim where it can (the ceiling above a double-sided lamp 2 cm
  // under it: the bright spot is hidden by the lamp) carries $\int B V$, not $\bar B \bar V$.
  // The mean-B-times-mean-V product let the spot's light out into the room (+11 % over the
  // whole frame, contact.py lamp-two-sided). A link whose shooter is split in this key's tree
  // and whose rays are partly blocked weights each ray pair by the radiosity of the shooter's
  // leaf at its end, from the last solve (the same pairs: no new rays). Fully visible or fully
  // hidden links are unchanged, and so are links to a leaf shooter (constant B).
  //
  // The same pairs give the shooter's B as the receiver sees it, open or not: their
  // kernel-weighted mean of the leaves' B over B_q (shooterShape), which the gather multiplies
  // in. A coarse link (ceiling <- wall) gathered the wall's mean B, but the ceiling sees mostly
  // the wall's upper part, which the lamp lights best: the bundled scene's coarse ceiling was
  // 3.4 % below its converged B (eps 1e-5), 0.6 % with the shape; frames against path-traced
  // references: Cornell box 5.15 -> 4.62 % RMSE / mean, cubes-8 4.75 -> 4.52 %, bundled 5.64 ->
  // 5.23 %, table 2.04 -> 2.02 %, cubic 3.36 -> 3.53 % (--no-shooter-shape for the former).
  void weightVisibilityByShooterRadiosity() {
    if (!input_.visibility) return;
    const int k = std::max(opt_.rays, 1);
    if (k > VisibilityScene::kMaxRecordedPairs) {  // open pairs not recorded: rays again
      tbb::parallel_for(size_t(0), s_.links.size(),
                        [&](size_t li) { weightLinkVisibility(s_.links[li]); });
      return;
    }
    // The links weighted for the first time in this key solve get their pairs (kernel, the
    // shooter's (u,v) at each pair's end): the previous key's for a link coherence took over
    // (both ends static, so the same values), else made here; every round after takes them
    // over, as this key's geometry and rays do not change between rounds. Regenerating the
    // points, kernels and (u,v) of every link at every round had been 38 % of rad-global's
    // time on the table scene (perf: samplePoints, pairedPoints, polygonUvAt, descendToChild).
    const size_t L = s_.links.size();
    pairStart_.resize(L, kNoRayPairs);
    // The links without pairs yet, in link order (found in parallel parts).
    RowOrder withPairs = sortByRow(L, 2u, [&](size_t li) {
      return pairStart_[li] == kNoRayPairs && weighted(s_.links[li]) ? 0u : 1u;
    });
    std::vector<uint32_t> fresh = std::move(withPairs.order);
    fresh.resize(withPairs.rowStart[1]);
    // Pair starts are 32-bit (kNoRayPairs): 4 M links (the default --max-links) of 64 pairs
    // stay far below; a link bound raised past a billion pairs is refused, not wrapped.
    if (pairs_.size() + fresh.size() * size_t(k) >= size_t(kNoRayPairs))
      throw Error(ExitCode::kEnvironment, "",
                  "more than 4 G shadow-ray pairs in one key time; lower --max-links or --rays");
    // Reserved at their first use, not when the solve starts: the cluster refinement before it
    // holds a level of links and its children at once, and the two together had made
    // rad-global's peak on the 10k-triangle hall.
    if (pairs_.capacity() == 0 && input_.expectedRayPairs > 0)
      pairs_.reserve(withMargin(input_.expectedRayPairs));
    const size_t firstFresh = pairs_.size();
    pairs_.resize(pairs_.size() + fresh.size() * size_t(k));
    tbb::parallel_for(size_t(0), fresh.size(), [&](size_t f) {
      pairStart_[fresh[f]] = uint32_t(firstFresh + f * size_t(k));
      const SolverLink& l = s_.links[fresh[f]];
      LinkRayPair* pair = &pairs_[pairStart_[fresh[f]]];
      const uint32_t knownPairs =
          l.known != SolverLink::kNotKnown ? input_.reuse->value(l.known).rayPairs : kNoRayPairs;
      if (knownPairs != kNoRayPairs && reuseRayPairs_) {
        std::copy_n(reuseRayPairs_->begin() + std::ptrdiff_t(knownPairs), k, pair);
      } else {
        const PatchNode& r = h_.node(l.receiver);
        const PatchNode& q = h_.node(l.shooter);
        const Polygon& P = s_.world[size_t(l.receiver)];
        const Polygon& Q = s_.world[size_t(l.shooter)];
        const bool triangle = Q.count == 3;
        std::vector<glm::dvec3> bPoints;
        std::vector<double> kernel;
        VisibilityScene::pairsFrom(VisibilityScene::samplePoints(P, opt_.rays, receiverSeed(r.id)),
                                   P.normal(), Q, linkSeed(r.id, q.id), bPoints, kernel);
        for (int i = 0; i < k; ++i)
          pair[i] = {
              glm::vec2(clampToParameterDomain(polygonUvAt(Q, bPoints[size_t(i)]), triangle)),
              float(kernel[size_t(i)])};
      }
    });
    // The previous key's pairs are copied: they go before the pairs' leaves are made (held
    // together, the two had made rad-global's peak on the 10k-triangle hall).
    releaseRayPairs();
    tbb::parallel_for(size_t(0), L, [&](size_t li) {
      SolverLink& l = s_.links[li];
      l.visibility = l.rayVisibility;
      l.shooterShape = 1.0;
      if (!weighted(l)) return;
      const bool triangle = s_.world[size_t(l.shooter)].count == 3;
      const LinkRayPair* pair = &pairs_[pairStart_[li]];
      double kernel[VisibilityScene::kMaxRecordedPairs], weight[VisibilityScene::kMaxRecordedPairs];
      for (int i = 0; i < k; ++i) {
        // The leaf under the pair's end, found again at every round from the shooter (a few
        // levels). Keeping it per pair between rounds had held 4 bytes a pair (18 MB of the
        // 10k-triangle hall's peak, once the sweeps' lists were made), its (u,v) too before
        // that 24 (110 MB).
        int node = l.shooter;
        glm::dvec2 uv(pair[i].uv);
        while (s_.split[size_t(node)])
          node = h_.node(node).firstChild + descendToChild(uv, triangle);
        const glm::dvec3 b = B_[size_t(node)];
        kernel[i] = pair[i].kernel;
        weight[i] = b.x + b.y + b.z;
      }
      double seen = -1.0;
      const double v = VisibilityScene::weightedVisibilityOfPairs(k, kernel, l.openPairs, weight,
                                                                  nullptr, &seen);
      setWeightedVisibility(l, v, seen);
    });
  }

  // A link whose shooter is split in this key's tree and whose rays are not all blocked.
  bool weighted(const SolverLink& l) const {
    return !l.refined && l.rayVisibility > 0.0 && s_.split[size_t(l.shooter)];
  }

  // The radiosity-weighted V, and the shooter's B as the receiver sees it (`seen`) over its
  // mean, into l.
  void setWeightedVisibility(SolverLink& l, double v, double seen) const {
    if (l.rayVisibility < 1.0) l.visibility = v;
    const glm::dvec3 mean = B_[size_t(l.shooter)];
    if (opt_.shooterShape && seen >= 0.0 && mean.x + mean.y + mean.z > 0.0)
      l.shooterShape = float(seen / (mean.x + mean.y + mean.z));
  }

  // weightVisibilityByShooterRadiosity for one link, its pairs made again (more rays than
  // the open pairs record: cast again).
  void weightLinkVisibility(SolverLink& l) const {
    l.visibility = l.rayVisibility;
    l.shooterShape = 1.0;
    if (!weighted(l)) return;
    const PatchNode& r = h_.node(l.receiver);
    const PatchNode& q = h_.node(l.shooter);
    const Polygon& P = s_.world[size_t(l.receiver)];
    const Polygon& Q = s_.world[size_t(l.shooter)];
    const bool triangle = Q.count == 3;
    auto radiosityAt = [&](const glm::dvec3& y) {
      int n = l.shooter;
      glm::dvec2 uv = clampToParameterDomain(polygonUvAt(Q, y), triangle);
      while (s_.split[size_t(n)]) n = h_.node(n).firstChild + descendToChild(uv, triangle);
      const glm::dvec3 b = B_[size_t(n)];
      return b.x + b.y + b.z;
    };
    double seen = -1.0;
    const double v = input_.visibility->weightedVisibilityFrom(
        VisibilityScene::samplePoints(P, opt_.rays, receiverSeed(r.id)), P.normal(), Q,
        linkSeed(r.id, q.id), r.id.top, q.id.top, &l.openPairs, radiosityAt, nullptr, &seen);
    setWeightedVisibility(l, v, seen);
  }

  // The refinement oracle (header): power max_c B_q F~ V A_p, error max_c B_q V spreadArea,
  // either one, against eps * Phi.
  bool oracleWantsRefinement(const SolverLink& l) const {
    double bv = maxComponent(B_[size_t(l.shooter)]) * l.visibility;
    // The shooter's B varies inside it (a shadow across the floor patch a box face gathers
    // from): the link's error is up to that range times F V A_p. Counted in the power oracle,
    // which otherwise sees only the shooter's mean.
    double range = size_t(l.shooter) < shooterRange_.size() ? shooterRange_[size_t(l.shooter)] : 0;
    bool power =
        std::max(bv, range * l.visibility) * l.estimate * s_.area[size_t(l.receiver)] > epsAbs_;
    bool error = bv * l.spreadArea > epsAbs_;
    return opt_.oracle == RefinementOracle::kPower   ? power
           : opt_.oracle == RefinementOracle::kError ? error
                                                     : power || error;
  }

  // Which node a link would split, or -1 (HSA'91: the larger one, if above minArea).
  int nodeToSplit(const SolverLink& l) const {
    int a = l.receiver, b = l.shooter;
    if (s_.area[size_t(b)] > s_.area[size_t(a)]) std::swap(a, b);
    for (int n : {a, b})
      if (s_.area[size_t(n)] > opt_.minArea && h_.node(n).id.level() < PatchId::kMaxLevel) return n;
    return -1;
  }

  // Subdivides `node` (one end of link li) and replaces the link by its four children's links,
  // whose indices go to `next`.
  void splitLink(LinkIndex li, int node, std::vector<LinkIndex>& next) {
    const SolverLink l = s_.links[li];  // a copy: push_back below may move the links
    bool fresh = !s_.split[size_t(node)];
    int first = h_.subdivide(node);
    addNewNodes();
    s_.split[size_t(node)] = 1;
    if (fresh)  // children enter this key's tree with their parent's radiosity
      for (int c = 0; c < 4; ++c) B_[size_t(first + c)] = B_[size_t(node)];
    s_.links[li].refined = true;
    for (int c = 0; c < 4; ++c) {
      SolverLink child;
      child.receiver = node == l.receiver ? first + c : l.receiver;
      child.shooter = node == l.receiver ? l.shooter : first + c;
      next.push_back(LinkIndex(s_.links.size()));
      s_.links.push_back(child);
    }
  }

  // Refine: the links of `work`, and the links that makes, until the oracle is satisfied
  // (each generation evaluated first). Returns the number of links refined.
  size_t refine(std::vector<LinkIndex> work) {
    size_t count = 0;
    while (!work.empty()) {
      evaluateNewLinks();
      // Per link, the node it splits (-1: none), in parallel first: the oracle and the choice
      // are pure functions of the link, of B and of the nodes' areas, which splitting other
      // links of this generation does not change (a new node's B is its parent's, and an
      // existing node keeps its own), so the decisions below are the same. Asked one link after
      // the other they had been 2 % of the 10k-triangle hall's rad-global.
      std::vector<int> splits(work.size());
      tbb::parallel_for(size_t(0), work.size(), [&](size_t j) {
        const SolverLink& l = s_.links[work[j]];
        splits[j] = !l.refined && oracleWantsRefinement(l) ? nodeToSplit(l) : -1;
      });
      std::vector<LinkIndex> next;
      for (size_t j = 0; j < work.size(); ++j) {
        const int node = splits[j];
        if (node < 0) continue;
        const LinkIndex li = work[j];
        if (s_.links.size() + 4 > opt_.maxLinks) {  // the memory bound: stop refining
          s_.linkCapReached = true;
          evaluateNewLinks();  // this generation's links, made before the bound, get F~ and V
          return count;
        }
        splitLink(li, node, next);
        ++count;
      }
      work.swap(next);
    }
    return count;
  }

  std::vector<LinkIndex> unrefinedLinks() const {
    // A row order with the refined links last (one scan of the links in parallel parts).
    RowOrder order =
        sortByRow(s_.links.size(), 2u, [&](size_t i) { return s_.links[i].refined ? 1u : 0u; });
    order.order.resize(order.rowStart[1]);
    return std::move(order.order);
  }

  // Accurate pass: the quadrature F (linkFormFactor) of every visible leaf link not yet
  // computed, or the accurate F the previous key time already computed (coherence).
  void computeAccurateFormFactors() {
    std::vector<LinkIndex> fresh;  // the links whose F is integrated here
    for (size_t li = 0; li < s_.links.size(); ++li) {
      SolverLink& l = s_.links[li];
      if (l.refined || l.accurate) continue;
      l.accurate = true;
      if (!(l.rayVisibility > 0.0)) continue;
      l.integrated = true;
      const double knownFormFactor =
          l.known != SolverLink::kNotKnown ? input_.reuse->value(l.known).formFactor : -1.0;
      if (knownFormFactor >= 0.0) {
        l.formFactor = knownFormFactor;
        continue;
      }
      l.reused = false;  // computed here after all
      l.visibilityOnly = false;
      fresh.push_back(LinkIndex(li));
    }
    // Reciprocity: linkFormFactor integrates over the smaller patch of a pair, so a link and its
    // reverse (p <- q, q <- p: 93 % of the 1.2 M links of the 10k-triangle hall's first key)
    // take one integral, bit for bit what each would have computed. Pairs of equal area (the
    // rule's tie keeps the receiver as the patch integrated over) are computed per link.
    std::vector<std::pair<uint64_t, LinkIndex>> byPair(fresh.size());
    tbb::parallel_for(size_t(0), fresh.size(), [&](size_t i) {
      const SolverLink& l = s_.links[fresh[i]];
      const uint64_t a = uint32_t(std::min(l.receiver, l.shooter)),
                     b = uint32_t(std::max(l.receiver, l.shooter));
      byPair[i] = {(a << 32) | b, fresh[i]};
    });
    std::vector<LinkIndex>().swap(fresh);
    tbb::parallel_sort(byPair.begin(), byPair.end());  // distinct: deterministic
    std::vector<size_t> groupStart;
    for (size_t i = 0; i < byPair.size(); ++i)
      if (i == 0 || byPair[i].first != byPair[i - 1].first) groupStart.push_back(i);
    groupStart.push_back(byPair.size());
    const bool autoOrder = opt_.quadratureOrder == kAutoOrder;
    tbb::parallel_for(size_t(0), groupStart.size() - 1, [&](size_t g) {
      const size_t first = groupStart[g], count = groupStart[g + 1] - first;
      SolverLink& l = s_.links[byPair[first].second];
      const Polygon& p = s_.world[size_t(l.receiver)];
      const Polygon& q = s_.world[size_t(l.shooter)];
      SolverLink& next = s_.links[byPair[first + (count > 1 ? 1 : 0)].second];
      if (count == 2 && autoOrder && next.receiver == l.shooter && p.area() != q.area()) {
        const double f = linkFormFactorIntegral(p, q, opt_.formFactorTolerance);
        l.formFactor = linkFormFactorFrom(p, q, f);
        next.formFactor = linkFormFactorFrom(q, p, f);
        return;
      }
      for (size_t i = first; i < first + count; ++i) {
        SolverLink& li = s_.links[byPair[i].second];
        li.formFactor = linkFormFactor(s_.world[size_t(li.receiver)], s_.world[size_t(li.shooter)],
                                       opt_.quadratureOrder, opt_.formFactorTolerance);
      }
    });
  }

  // Closure (energy conservation whatever the refinement): a leaf r gathers through a link
  // (a <- b) at an ancestor a the area average F(a -> b), not its own F(r -> b), so its row sum
  // $\sum_k F(a_k \to b_k) V_k$ over the links of r and its ancestors is not its own: 0.82 ..
  // 1.37 in the refined unit-cube furnace (1 in the area average), whose B that error,
  // amplified by 1 / (1 - rho), made 7 % too bright at rho = 0.9 and 52 % at 0.99. The shooters
  // b_k of a leaf's links tile the top-level patches it is linked with, so for a top-level
  // patch q that every one of those links sees unoccluded (V = 1), the links to q carry exactly
  // $F(r \to q)$ at the leaf's own resolution; the leaf's links to such a q are scaled by
  //   $c_{rq} = G_q / \sum_{k \in q} F(a_k \to b_k) V_k$,  $G_q = F(r \to q)$
  // (topExcess_ holds c_rq - 1 per link), the links to a q any of whose links is occluded are
  // kept: row sums exact in a closed empty room at any refinement, and the averaging error of
  // unoccluded pairs (a wall meeting the floor) removed in any scene, while the occluded pairs
  // keep hierarchical radiosity's estimate (scaling them by an unoccluded ratio would brighten
  // what an occluder darkens). Per top, not one ratio for the row: a floor leaf beside a dim
  // wall had its light scaled by the wall's ratio (1.85 in the bundled scene). The good-link
  // share (shooters that do not emit: the default bad-link rule's good links) also gets one
  // factor, goodClosure, which rad-global's merge applies to the good-link irradiance the
  // Gouraud layer interpolates.
  void computeClosure() {
    buildGatherLists();
    const size_t N = size_t(h_.size());
    s_.closure.assign(N, 1.0);
    s_.goodClosure.assign(N, 1.0);
    goodFactor_.assign(N, 1.0);
    closed_.resize(N, -1);  // kept from the rounds before: a node's rays do not change
    // The previous key's values (coherence) start each node's list: closeLeaf finds them as
    // its own, and they are kept for the next key (all of them static pairs, valid at every key).
    if (leafTopFormFactor_.empty() && input_.reuseLeafFormFactors)
      leafTopFormFactor_ = std::move(*input_.reuseLeafFormFactors);
    leafTopFormFactor_.resize(N);
    topExcess_.assign(N, {});
    std::vector<int> leaves;
    for (size_t i = 0; i < N; ++i)
      if (s_.inTree(int(i), h_) && !s_.split[i]) leaves.push_back(int(i));
    tbb::parallel_for(size_t(0), leaves.size(), [&](size_t li) { closeLeaf(leaves[li]); });
  }

  // Cosine-distributed directions about a node's normal (Malley's method), the k-th from two
  // counter-based numbers of `seed`: the exposure's rays and the closed-room test's.
  struct CosineRays {
    glm::dvec3 normal, t, b;
    explicit CosineRays(const glm::dvec3& n) : normal(n) {
      t = std::abs(n.x) > 0.5 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
      t = glm::normalize(glm::cross(t, n));
      b = glm::cross(n, t);
    }
    glm::dvec3 operator()(uint64_t seed, size_t k) const {
      const double u = uniformOpen01(seed, 2 * k), v = uniformOpen01(seed, 2 * k + 1);
      const double r = std::sqrt(u), phi = 2.0 * M_PI * v;
      return r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(1.0 - u) * normal;
    }
  };

  // Whether leaf r is inside a closed room: none of kEscapeRays cosine-distributed rays from
  // its points leaves the scene. A room's opening of form factor f goes unseen with probability
  // (1 - f)^64 (f = 5 %: 4 %), and then brightens that leaf by at most f.
  static constexpr int kEscapeRays = 64;
  bool closedAt(int r) {
    // Once per node and key: the refinement rounds ask again for the leaves they keep. A static
    // node's answer is the same at every key (the static geometry alone decides it), so it is
    // also taken over from the keys before (coherence).
    if (closed_[size_t(r)] >= 0) return closed_[size_t(r)] != 0;
    const ClosedNodeCache* before = moves(h_.node(r).id.top) ? nullptr : input_.reuseClosed;
    const auto known =
        before ? before->find(h_.node(r).id.packed()) : ClosedNodeCache::const_iterator();
    const bool closed = before && known != before->end() ? known->second : castEscapeRays(r);
    closed_[size_t(r)] = closed ? 1 : 0;
    return closed;
  }

  bool castEscapeRays(int r) const {
    if (!input_.visibility) return false;
    const PatchNode& n = h_.node(r);
    const Polygon& P = s_.world[size_t(r)];
    const glm::dvec3 normal = P.normal();
    if (normal == glm::dvec3(0.0)) return false;
    const CosineRays direction(normal);
    const uint64_t seed = splitMix64(receiverSeed(n.id) ^ 0x636c6f736564ull);  // "closed"
    const std::vector<glm::dvec3> points = VisibilityScene::samplePoints(P, kEscapeRays, seed);
    const double size = polygonSize(P);
    const glm::dvec3 centroid = P.centroid();
    for (size_t k = 0; k < points.size(); ++k) {
      const glm::dvec3 d = direction(seed, k);
      // A ray that escapes is cast again from 1 % of the way to the leaf's centroid and 1e-3 of
      // its size above it: a point 2e-5 m from the wall that the leaf's edge meets, whose ray
      // into that wall started within the ray's tnear of it, passed through (a floor leaf of a
      // closed cube); from there it meets the wall.
      if (input_.visibility->firstStaticHit(points[k], d * size, n.id.top) ==
              VisibilityScene::kNoSurface &&
          input_.visibility->firstStaticHit(
              points[k] + 0.01 * (centroid - points[k]) + normal * (1e-3 * size), d * size,
              n.id.top) == VisibilityScene::kNoSurface)
        return false;
    }
    return true;
  }

  // F(leaf r -> top q), integrated (closeLeaf looks in leafTopFormFactor_ first, which holds
  // the previous key's values under coherence: the same value recomputing gives).
  double leafToTop(int r, uint32_t q) const {
    if (opt_.quadratureOrder != kAutoOrder)
      return polygonToPolygonFormFactor(s_.world[size_t(r)], s_.world[q], opt_.quadratureOrder);
    return areaAverageFormFactor(s_.world[size_t(r)], s_.world[q],
                                 std::max(opt_.formFactorTolerance, 1e-4));
  }

  // A pair with a moving end would need its F(leaf -> top) at every key time (32 moving cubes
  // made that most of rad-global's time); moving objects are small against the rooms they
  // move in, and the closed rooms the closure is exact for are static.
  bool moves(uint32_t top) const {
    return top < input_.movingTops.size() && input_.movingTops[top];
  }

  struct TopShare {  // one top-level shooter's links in a leaf's chain
    uint32_t top = 0;
    double fv = 0;
    bool unoccluded = true;
    bool fromAncestor = false;  // some of them are at an ancestor (else F is the leaf's own)
  };

  void closeLeaf(int r) {
    std::vector<TopShare> shares;
    // Per top, its index in `shares` (first-seen order, so the sums below do not depend on
    // it), -1 elsewhere; one per thread, reset after each leaf.
    thread_local std::vector<int> slot;
    slot.resize(size_t(h_.topCount()), -1);
    for (int a = r; a >= 0; a = h_.node(a).parent)
      for (size_t k = adjStart_[size_t(a)]; k < adjStart_[size_t(a) + 1]; ++k) {
        const SolverLink& l = s_.links[adj_[k]];
        const uint32_t q = h_.node(l.shooter).id.top;
        if (slot[q] < 0) {
          slot[q] = int(shares.size());
          shares.push_back(TopShare{q, 0.0, true, false});
        }
        TopShare& t = shares[size_t(slot[q])];
        t.fv += l.fv();
        t.unoccluded = t.unoccluded && l.rayVisibility >= 1.0;
        t.fromAncestor = t.fromAncestor || a != r;
      }
    for (const TopShare& t : shares) slot[t.top] = -1;
    std::vector<std::pair<uint32_t, double>>& known = leafTopFormFactor_[size_t(r)];
    // Per top, its index in `known` (the slots reused; a linear search per share had been 14 %
    // of rad-global's time on the table scene at eps 1e-4).
    for (size_t i = 0; i < known.size(); ++i) slot[known[i].first] = int(i);
    glm::dvec2 own(0.0), averaged(0.0);  // (all, good)
    // Per top whose share is replaced, G_q / sum_k F V - 1 (0: kept), indexed like `slot`.
    thread_local std::vector<double> excess;
    excess.resize(size_t(h_.topCount()), 0.0);
    bool anyExcess = false;
    for (const TopShare& t : shares) {
      double g = t.fv;
      if (t.unoccluded && t.fromAncestor && !moves(t.top) && !moves(h_.node(r).id.top)) {
        int& at = slot[t.top];
        if (at < 0) {
          at = int(known.size());
          known.push_back({t.top, leafToTop(r, t.top)});
        }
        g = known[size_t(at)].second;
        if (t.fv > 0.0 && g != t.fv) {
          excess[t.top] = g / t.fv - 1.0;
          anyExcess = true;
        }
      }
      const double good = surfaces_[t.top].isEmitter() ? 0.0 : 1.0;
      own += glm::dvec2(g, good * g);
      averaged += glm::dvec2(t.fv, good * t.fv);
    }
    for (const std::pair<uint32_t, double>& k : known) slot[k.first] = -1;
    // Each replaced top's links are scaled by their own top's ratio, the others kept: a leaf
    // beside a wall sees much more of that dim wall than its ancestor's links say, and one
    // ratio for the whole row had scaled the light by the wall's share too (the bundled
    // scene's floor strip in front of the tall box came out 1.8x too bright, the box's foot on
    // the frames with it).
    std::vector<std::pair<size_t, double>>& extra = topExcess_[size_t(r)];
    extra.clear();
    if (anyExcess)
      for (int a = r; a >= 0; a = h_.node(a).parent) {
        const double e = exposure_[size_t(a)];
        if (!(e > 0.0)) continue;
        for (size_t k = adjStart_[size_t(a)]; k < adjStart_[size_t(a) + 1]; ++k) {
          const double x = excess[h_.node(s_.links[adj_[k]].shooter).id.top];
          if (x != 0.0) extra.emplace_back(adj_[k], x / e);
        }
      }
    for (const TopShare& t : shares) excess[t.top] = 0.0;
    // The good-link irradiance rad-movies interpolates (Gouraud layer) takes the good share's
    // ratio as one factor.
    if (averaged.y > 0.0) s_.goodClosure[size_t(r)] = own.y / averaged.y;
    if (opt_.closedRooms) closeRoomRow(r);
  }

  // A leaf's replaced tops' excess irradiance (topExcess_), (emitting shooters, the others).
  std::pair<glm::dvec3, glm::dvec3> excessIrradiance(int r) const {
    std::pair<glm::dvec3, glm::dvec3> H{glm::dvec3(0.0), glm::dvec3(0.0)};
    if (size_t(r) >= topExcess_.size()) return H;
    for (const auto& [k, c] : topExcess_[size_t(r)]) {
      const SolverLink& l = s_.links[k];
      (shooterEmits_[k] ? H.first : H.second) +=
          c * double(l.fv()) * l.shooterShape * B_[size_t(l.shooter)];
    }
    return H;
  }

  // A leaf inside a closed room sees the scene's surfaces and nothing else, so the row sum of
  // its exposed part is exactly 1, occluded links included. An occluded link's visibility is a
  // ratio estimate from a few ray pairs, and its error does not cancel within one receiver:
  // the closed 2 m furnace with a slab standing in it (make_furnace.py --partition) came out
  // 7.5 % too bright at rho = 0.99 with 16 rays, 36 % with 64 rays and 18 % too dark with the
  // slab floating; the cubic scene's leaves summed to 0.986 on average (0.80 .. 1.34), and its
  // frames were 1.6 % too dark. The links to emitting shooters keep the closure above (mostly
  // unoccluded, and recomputed per texel by the second pass); the others' factor fills the row
  // to 1, each node's links counted over its exposure as the gather divides them. Where every
  // shooter emits (the furnace), or the others' share cannot take the difference, the whole
  // row is scaled.
  void closeRoomRow(int r) {
    if (!(exposure_[size_t(r)] > 0.0)) return;
    glm::dvec2 coef(0.0);  // (emitting shooters, the others), the replaced tops' excess included
    for (int a = r; a >= 0; a = h_.node(a).parent) {
      const double e = exposure_[size_t(a)];
      if (!(e > 0.0)) continue;
      for (size_t k = adjStart_[size_t(a)]; k < adjStart_[size_t(a) + 1]; ++k)
        (shooterEmits_[adj_[k]] ? coef.x : coef.y) += s_.links[adj_[k]].fv() / e;
    }
    for (const auto& [k, c] : topExcess_[size_t(r)])
      (shooterEmits_[k] ? coef.x : coef.y) += c * s_.links[k].fv();
    if (!(coef.x + coef.y > 0.0) || !closedAt(r)) return;
    // The cluster links' share (gathered at the top, over its exposure) is taken as it is.
    const uint32_t top = h_.node(r).id.top;
    const double cluster = clusterRow_.empty() ? 0.0 : clusterRow_[top];
    if (!(cluster < 1.0)) return;
    const double good =
        coef.y > 0.0 ? (1.0 - cluster - s_.closure[size_t(r)] * coef.x) / coef.y : 0.0;
    if (good > 0.5 && good < 2.0) {
      goodFactor_[size_t(r)] = good;
    } else {
      s_.closure[size_t(r)] = (1.0 - cluster) / (coef.x + coef.y);
      goodFactor_[size_t(r)] = s_.closure[size_t(r)];
    }
    s_.goodClosure[size_t(r)] = goodFactor_[size_t(r)];
  }

  // Exposure (the darkening at contacts): a box standing on the floor covers part of the
  // floor's patches, whose links' shadow rays then start under the box and are blocked, so
  // the area-averaged H and B of a patch straddling the box's footprint mix the lit part with
  // the dark covered one; the camera sees only the lit part, and the ceiling and walls that
  // gather from that patch see only its lit part too. With the boxes of the bundled Cornell
  // scene that made every surface 6-20 % too dark (-0.4 % with the boxes removed). A node's
  // exposure e is the fraction of its ray start points (samplePoints, the same for all its
  // links) that are not covered: a point is covered when a cosine-distributed ray from it
  // first meets the back of a one-sided surface (the inside of a solid, the back of a wall).
  // The gather divides a node's links' irradiance by e, so B and H are those of the exposed
  // part (the covered points' pairs are exactly the ones removed), and a parent pulls its
  // children's B weighted by exposed area.
  void computeExposures() {
    const size_t N = size_t(h_.size());
    exposure_.resize(N, -1.0);
    std::vector<int> todo;
    for (size_t i = 0; i < N; ++i)
      if (exposure_[i] < 0.0 && s_.inTree(int(i), h_)) todo.push_back(int(i));
    tbb::parallel_for(size_t(0), todo.size(),
                      [&](size_t k) { exposure_[size_t(todo[k])] = exposureOf(todo[k]); });
  }

  double exposureOf(int i) const {
    if (!input_.visibility) return 1.0;
    const PatchNode& n = h_.node(i);
    const Polygon& P = s_.world[size_t(i)];
    const glm::dvec3 normal = P.normal();
    if (normal == glm::dvec3(0.0)) return 1.0;
    const CosineRays direction(normal);
    const std::vector<glm::dvec3> points =
        VisibilityScene::samplePoints(P, opt_.rays, receiverSeed(n.id));
    const uint64_t seed = splitMix64(receiverSeed(n.id));
    const double size = polygonSize(P);
    // Undecided rays (a front and a back at one distance: a partition flush with the ceiling,
    // a sheet of two back-to-back patches) go with the majority of the decided ones.
    int exposed = 0, inside = 0, undecided = 0;
    for (size_t k = 0; k < points.size(); ++k) {
      const glm::dvec3 d = direction(seed, k) * size;  // firstHit's tnear is relative to |d|
      const RayStart r = rayStart(*input_.visibility, points[k], d, n.id.top, [&](uint32_t hit) {
        return hit < uint32_t(h_.topCount()) && !surfaces_[hit].doubleSided &&
               glm::dot(s_.world[hit].normal(), d) > 0.0;
      });
      (r == RayStart::kOutside ? exposed : r == RayStart::kInside ? inside : undecided) += 1;
    }
    if (inside > exposed)
      inside += undecided;
    else
      exposed += undecided;
    return points.empty() ? 1.0 : double(exposed) / double(points.size());
  }

  // Per receiving node, its gathered (unrefined) links in link order: adj_[adjStart_[i] ..
  // adjStart_[i + 1]); per link, whether its shooter emits (shooterEmits_).
  void buildGatherLists() {
    const size_t N = size_t(h_.size());
    // The refined links go to one more row, left out.
    RowOrder byReceiver = sortByRow(s_.links.size(), uint32_t(N + 1), [&](size_t li) {
      const SolverLink& l = s_.links[li];
      return l.refined ? uint32_t(N) : uint32_t(l.receiver);
    });
    adjStart_.assign(byReceiver.rowStart.begin(), byReceiver.rowStart.end() - 1);
    adj_.swap(byReceiver.order);
    adj_.resize(adjStart_[N]);
    shooterEmits_.resize(s_.links.size());
    tbb::parallel_for(size_t(0), s_.links.size(), [&](size_t k) {
      shooterEmits_[k] = surfaces_[h_.node(s_.links[k].shooter).id.top].isEmitter() ? 1 : 0;
    });
  }

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

  Pulled gatherPushPull(int i, const Gathered& down) {
    Gathered H = down;
    const double e = exposure_[size_t(i)];
    if (e > 0.0)
      for (size_t k = adjStart_[size_t(i)]; k < adjStart_[size_t(i) + 1]; ++k) {
        const uint32_t shooter = sweepShooter_[k] & ~kSweepEmits;
        const glm::dvec3 term = sweepCoefficient_[k] * B_[shooter] / e;
        (sweepShooter_[k] & kSweepEmits ? H.light : H.good) += term;
      }
    if (!s_.split[size_t(i)]) {
      if (e > 0.0) {
        const auto [light, good] = excessIrradiance(i);
        H.light += light;
        H.good += good;
      }
      const glm::dvec3 irradiance =
          H.cluster + (s_.closure.empty()
                           ? H.light + H.good
                           : s_.closure[size_t(i)] * H.light + goodFactor_[size_t(i)] * H.good);
      irr_[size_t(i)] = irradiance;
      const SurfaceProperties& sp = surfaces_[h_.node(i).id.top];
      glm::dvec3 b = sp.emission + sp.reflectance * irradiance;
      nonFinite_ |= !(std::isfinite(b.x) && std::isfinite(b.y) && std::isfinite(b.z));
      maxDelta_ = std::max(maxDelta_, maxComponent(glm::abs(b - B_[size_t(i)])));
      maxB_ = std::max(maxB_, maxComponent(glm::abs(b)));
      B_[size_t(i)] = b;
      const double exposedArea = e * s_.area[size_t(i)];
      return {b * exposedArea, exposedArea};
    }
    irr_[size_t(i)] = H.light + H.good + H.cluster;
    int first = h_.node(i).firstChild;
    Pulled sum;
    double areaSum = 0;
    glm::dvec3 plain(0.0);  // area-weighted, for a node whose children are all covered
    for (int c = 0; c < 4; ++c) {
      Pulled child = gatherPushPull(first + c, H);
      sum.power += child.power;
      sum.area += child.area;
      areaSum += s_.area[size_t(first + c)];
      plain += B_[size_t(first + c)] * s_.area[size_t(first + c)];
    }
    B_[size_t(i)] = sum.area > 0    ? sum.power / sum.area
                    : areaSum > 0.0 ? plain / areaSum
                                    : B_[size_t(first)];
    return {B_[size_t(i)] * sum.area, sum.area};
  }

  // The sweeps' links in gather order, each its shooter (kSweepEmits set when it emits) and
  // F V times its shooter shape: 12 bytes read in order instead of a 64-byte SolverLink and a
  // flag reached through adj_ (the sweeps are serial, and were a quarter of the 10k-triangle
  // hall's rad-global). The same products, so the same B bit for bit. The shooters overwrite
  // adj_ (the next buildGatherLists makes it again): rad-global's peak is in the solve.
  static constexpr uint32_t kSweepEmits = 0x80000000u;
  void buildSweepLists() {
    sweepCoefficient_.resize(adj_.size());
    tbb::parallel_for(size_t(0), adj_.size(), [&](size_t k) {
      const SolverLink& l = s_.links[adj_[k]];
      sweepCoefficient_[k] = double(l.fv()) * l.shooterShape;
      adj_[k] = uint32_t(l.shooter) | (shooterEmits_[adj_[k]] ? kSweepEmits : 0u);
    });
    sweepShooter_.swap(adj_);
  }

  // Gauss-Seidel sweeps of gather + push-pull over the top-level patches until the relative
  // change of B is below the stop rule (or maxIterations).
  void solve() {
    buildGatherLists();
    buildSweepLists();
    irr_.assign(size_t(h_.size()), glm::dvec3(0.0));
    for (int it = 0; it < opt_.maxIterations; ++it) {
      maxDelta_ = maxB_ = 0;
      // Cluster links gather from the B of the sweep before (Jacobi for them, Gauss-Seidel
      // for the patch links).
      if (clusters_) clusters_->gather(B_, exposure_, clusterH_);
      for (int t = 0; t < h_.topCount(); ++t) {
        Gathered top;
        if (clusters_) top.cluster = clusterH_[size_t(t)];
        gatherPushPull(t, top);
      }
      ++s_.iterations;
      // Bad input, not a bug: surfaces that overlap (coincident triangles facing each other, a
      // strip or fan read from a triangle list) or a reflectance near 1 with the refinement's
      // row-sum error make the form factors of a row sum past 1 / rho (exit 5 had called the
      // mode-5/6 mutants of issue 18 a bug).
      if (nonFinite_ || maxB_ > radiosityBound_)
        throw Error(ExitCode::kBadInput, "",
                    "the radiosity solve diverges (B reached " + numberText(maxB_) +
                        " W/m^2, a million times E/(1 - rho) = " + numberText(radiosityBound_) +
                        "): the refined links' form factors sum to more than 1/reflectance "
                        "somewhere; use a lower reflectance or a coarser refinement threshold");
      s_.lastChange = maxB_ > 0 ? maxDelta_ / maxB_ : 0.0;
      if (s_.lastChange < stopChange_) break;
    }
    std::vector<uint32_t>().swap(sweepShooter_);  // adj_ is now empty: gather lists made anew
    std::vector<double>().swap(sweepCoefficient_);
  }

  KeySolution finish() {
    for (const SolverLink& l : s_.links) {
      (l.reused ? s_.linksReused : s_.linksComputed)++;
      s_.linksVisibilityOnly += l.visibilityOnly ? 1 : 0;
    }
    if (clusters_) {  // at the final B, as the merge gathers the patch links
      clusters_->gather(B_, exposure_, clusterH_);
      s_.topClusterIrradiance = clusterH_;
      s_.clusterLinks = clusters_->size();
      s_.clusterLinksReused = clusters_->reusedCount();
      s_.clusterBounds = clusters_->clusterBounds();
      // Moved out, and the rest of the cluster links (their gather lists) freed here, not when
      // the solver goes: a copy beside them had made rad-global's peak on the 10k-triangle
      // hall (+47 MB at the end of each key's solve).
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
    s_.exposure = std::move(exposure_);
    s_.exposure.resize(size_t(h_.size()), 1.0);
    for (double& e : s_.exposure)
      if (e < 0.0) e = 1.0;  // not in this key's tree
    s_.irradiance = std::move(irr_);
    s_.irradiance.resize(size_t(h_.size()), glm::dvec3(0.0));
    return std::move(s_);
  }

  PatchHierarchy& h_;
  const std::vector<SurfaceProperties>& surfaces_;
  const KeySolveInput& input_;
  // input_.reuseRayPairs until the first round has copied them (releaseRayPairs).
  const std::vector<LinkRayPair>* reuseRayPairs_ = input_.reuseRayPairs;
  const RadiosityOptions& opt_;
  KeySolution s_;
  std::vector<glm::dvec3> B_;  // per dense node: radiosity (W/m^2), area average of a parent
  size_t evaluated_ = 0;       // links [0, evaluated_) have their estimate and visibility
  double epsAbs_ = 0;          // eps * Phi
  bool refineOn_ = false;
  double stopChange_ = 0;  // tol * (1 - rho_max)
  std::vector<size_t> adjStart_;
  std::vector<LinkIndex> adj_;
  std::vector<glm::dvec3> irr_;   // per dense node: H gathered at it and its ancestors
  std::vector<double> exposure_;  // per dense node: exposureOf once computed, else < 0
  // Per dense node: the closure factor of a leaf's links to shooters that do not emit (its
  // closure factor, or the closed-room one).
  std::vector<double> goodFactor_;
  // Per leaf: its chain's links whose top's share the closure replaces (link index, the top's
  // G_q / sum F V - 1 over the exposure of the node that gathers it).
  std::vector<std::vector<std::pair<size_t, double>>> topExcess_;
  std::vector<int8_t> closed_;          // per dense node: closedAt once cast (0 or 1), else -1
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
};

}  // namespace

KeySolution solveKeyTime(PatchHierarchy& h, const std::vector<SurfaceProperties>& surfaces,
                         const KeySolveInput& input, const RadiosityOptions& opt) {
  const int T = h.topCount();
  if (int(surfaces.size()) != T || int(input.topToWorld.size()) != T)
    throw Error(ExitCode::kInternal, "", "solveKeyTime: per-top arrays have the wrong size");
  return KeyTimeSolver(h, surfaces, input, opt).run();
}

std::vector<char> movingTopsOf(const Scene& scene, const PatchHierarchy& hierarchy, double t0,
                               double t1) {
  std::unordered_map<int, bool> dynamic;
  for (int node : scene.meshNodes()) dynamic[node] = scene.isDynamic(node, t0, t1);
  std::vector<char> out(size_t(hierarchy.topCount()), 0);
  for (int t = 0; t < hierarchy.topCount(); ++t) {
    auto it = dynamic.find(hierarchy.top(t).node);
    out[size_t(t)] = it != dynamic.end() && it->second;
  }
  return out;
}

ClusterLinkCache reusableClusterLinks(const KeySolution& prev, const ClusterTree& tree,
                                      const PatchHierarchy& h, const Scene& scene, double t0,
                                      double t1) {
  const std::vector<char> moving = movingTopsOf(scene, h, t0, t1);
  std::vector<std::array<glm::dvec3, 2>> swept;
  for (int node : scene.meshNodes())
    if (scene.isDynamic(node, t0, t1)) swept.push_back(scene.sweptBounds(node, t0, t1));
  // A cluster below the root holds one mesh node's patches (or only static ones).
  auto isStatic = [&](ClusterRef r) {
    if (!isCluster(r)) return !moving[size_t(r)];
    const ClusterNode& n = tree.node(clusterIndex(r));
    return clusterIndex(r) != tree.root() && !moving[tree.members()[n.first]];
  };
  auto box = [&](ClusterRef r) {
    return isCluster(r) ? prev.clusterBounds[size_t(clusterIndex(r))]
                        : polygonBounds(prev.world[size_t(r)]);
  };
  const size_t T = size_t(h.topCount());
  // Per link, in parallel, whether it is kept; then the kept ones in link order.
  const std::vector<ClusterLink>& links = prev.clusterLinkValues;
  std::vector<char> kept(links.size());
  tbb::parallel_for(size_t(0), links.size(), [&](size_t i) {
    const ClusterLink& l = links[i];
    if (!l.evaluated || !isStatic(l.receiver) || !isStatic(l.shooter)) {
      kept[i] = 0;
      return;
    }
    const ClusterBounds a = box(l.receiver), b = box(l.shooter);
    const glm::dvec3 lo = glm::min(a.lo, b.lo), hi = glm::max(a.hi, b.hi);
    bool hit = false;
    for (const auto& s : swept)
      hit =
          hit || (glm::all(glm::lessThanEqual(s[0], hi)) && glm::all(glm::lessThanEqual(lo, s[1])));
    kept[i] = hit ? 0 : 1;
  });
  std::vector<std::pair<uint32_t, uint32_t>> keys;
  std::vector<CachedClusterLink> values;
  const size_t count = size_t(std::count(kept.begin(), kept.end(), char(1)));
  keys.reserve(count);
  values.reserve(count);
  ClusterLinkCache cache;
  for (size_t i = 0; i < links.size(); ++i)
    if (kept[i]) {
      const ClusterLink& l = links[i];
      keys.emplace_back(clusterLinkEnd(l.receiver, T), clusterLinkEnd(l.shooter, T));
      values.push_back(CachedClusterLink{l.direction, l.visibility, l.groupVisibility});
      if (l.memberVisibility != ClusterLink::kNoMemberVisibility) {
        values.back().memberVisibility = uint32_t(cache.memberVisibility.size());
        const auto from = prev.clusterMemberVisibility.begin() + long(l.memberVisibility);
        cache.memberVisibility.insert(cache.memberVisibility.end(), from,
                                      from + long(tree.node(clusterIndex(l.receiver)).count));
      }
    }
  cache.links =
      PairTable<CachedClusterLink>(keys, std::move(values), uint32_t(T + size_t(tree.size())));
  return cache;
}

ClusterTree clusterTreeOf(const Scene& scene, const PatchHierarchy& h, double t0, double t1) {
  const std::vector<glm::dmat4> m = topTransforms(scene, h, t0);
  std::vector<Polygon> world(size_t(h.topCount()));
  for (int t = 0; t < h.topCount(); ++t)
    world[size_t(t)] = h.top(t).local.transformed(m[size_t(t)]);
  return ClusterTree(h, world, movingTopsOf(scene, h, t0, t1));
}

std::vector<glm::dmat4> topTransforms(const Scene& scene, const PatchHierarchy& hierarchy,
                                      double t) {
  std::vector<glm::dmat4> out(size_t(hierarchy.topCount()), glm::dmat4(1.0));
  std::unordered_map<int, glm::dmat4> perNode;
  for (int i = 0; i < hierarchy.topCount(); ++i) {
    int node = hierarchy.top(i).node;
    if (node < 0) continue;
    auto it = perNode.find(node);
    if (it == perNode.end()) it = perNode.emplace(node, scene.worldTransform(node, t)).first;
    out[size_t(i)] = it->second;
  }
  return out;
}

SceneVisibility::SceneVisibility(const Scene& scene, const PatchHierarchy& h, double t0, double t1,
                                 bool split)
    : scene_(scene) {
  auto addPolygon = [](std::vector<VisibilityTriangle>& out, const Polygon& p, uint32_t id) {
    out.push_back({{p.v[0], p.v[1], p.v[2]}, id});
    if (p.count == 4) out.push_back({{p.v[0], p.v[2], p.v[3]}, id});
  };
  std::vector<VisibilityTriangle> statics;
  std::vector<int> dynamicNodes;
  std::unordered_map<int, std::vector<VisibilityTriangle>> local;
  std::unordered_map<int, bool> dynamic;
  for (int i = 0; i < h.topCount(); ++i) {
    const InputPolygon& top = h.top(i);
    int node = top.node;
    auto d = dynamic.find(node);
    if (d == dynamic.end())
      d = dynamic.emplace(node, node >= 0 && scene.isDynamic(node, t0, t1)).first;
    if (d->second) {
      if (!local.count(node)) dynamicNodes.push_back(node);
      addPolygon(local[node], top.local, uint32_t(i));
    } else {
      glm::dmat4 m = node >= 0 ? scene.worldTransform(node, t0) : glm::dmat4(1.0);
      addPolygon(statics, top.local.transformed(m), uint32_t(i));
    }
  }
  vis_ = std::make_unique<VisibilityScene>(statics);
  if (split) moving_ = std::make_unique<VisibilityScene>(std::vector<VisibilityTriangle>());
  VisibilityScene& withInstances = moving_ ? *moving_ : *vis_;
  for (int node : dynamicNodes)
    instances_.emplace_back(node,
                            withInstances.addInstance(local[node], scene.worldTransform(node, t0)));
  vis_->commit();
  if (moving_) moving_->commit();
}

void SceneVisibility::setTime(double t) {
  VisibilityScene& withInstances = moving_ ? *moving_ : *vis_;
  for (auto& [node, id] : instances_)
    withInstances.setInstanceTransform(id, scene_.worldTransform(node, t));
  withInstances.commit();
}

bool shaftMeetsBox(const Polygon& a, const Polygon& b, const glm::dvec3& lo, const glm::dvec3& hi) {
  // Shaft::meets' first test, on the same exact min/max, before building the shaft's hulls:
  // nearly every link of a coherent key misses the swept boxes here, and building a Shaft for
  // each was 0.9 s of the 10k-triangle hall's ~10 s per coherent key (a perf profile).
  glm::dvec3 sLo = a.v[0], sHi = a.v[0];
  for (int i = 0; i < a.count; ++i) sLo = glm::min(sLo, a.v[i]), sHi = glm::max(sHi, a.v[i]);
  for (int i = 0; i < b.count; ++i) sLo = glm::min(sLo, b.v[i]), sHi = glm::max(sHi, b.v[i]);
  for (int k = 0; k < 3; ++k)
    if (hi[k] < sLo[k] || lo[k] > sHi[k]) return false;
  return Shaft(a, b).meets(lo, hi);
}

Shaft::Shaft(const Polygon& a, const Polygon& b) {
  std::vector<glm::dvec3> pts;
  for (int i = 0; i < a.count; ++i) pts.push_back(a.v[i]);
  for (int i = 0; i < b.count; ++i) pts.push_back(b.v[i]);
  lo_ = hi_ = pts[0];
  for (const glm::dvec3& p : pts) lo_ = glm::min(lo_, p), hi_ = glm::max(hi_, p);
  scale_ = glm::length(hi_ - lo_);
  for (int k = 0; k < 3; ++k) {
    int i = (k + 1) % 3, j = (k + 2) % 3;
    std::vector<glm::dvec2> p2;
    for (const glm::dvec3& p : pts) p2.push_back({p[i], p[j]});
    std::vector<glm::dvec2> hull = convexHull2d(p2);
    if (hull.size() < 2) continue;
    for (size_t e = 0; e < hull.size(); ++e) {
      glm::dvec2 p0 = hull[e], p1 = hull[(e + 1) % hull.size()];
      glm::dvec2 d = p1 - p0;
      glm::dvec2 outward(d.y, -d.x);  // right of a CCW edge
      double len = glm::length(outward);
      if (len == 0) continue;
      edges_.push_back({k, p0, outward / len});
    }
  }
}

bool Shaft::meets(const glm::dvec3& lo, const glm::dvec3& hi) const {
  for (int k = 0; k < 3; ++k)
    if (hi[k] < lo_[k] || lo[k] > hi_[k]) return false;
  const double tol = 1e-12 * (scale_ + glm::length(hi - lo));
  for (const Edge& e : edges_) {
    const int i = (e.axis + 1) % 3, j = (e.axis + 2) % 3;
    const glm::dvec2 corners[4] = {{lo[i], lo[j]}, {hi[i], lo[j]}, {hi[i], hi[j]}, {lo[i], hi[j]}};
    bool allOutside = true;
    for (const glm::dvec2& c : corners)
      if (glm::dot(e.out, c - e.p0) <= tol) {
        allOutside = false;
        break;
      }
    if (allOutside) return false;
  }
  return true;
}

}  // namespace rad
