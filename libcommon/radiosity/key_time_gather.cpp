// The key-time solver's gather + push-pull (HSA'91 §5) and its Gauss-Seidel sweeps over the
// top-level patches. See key_time_solver.h.
#include "libcommon/radiosity/key_time_solver.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "libcommon/core/error.h"
#include "libcommon/radiosity/pair_table.h"
#include "libcommon/radiosity/visibility.h"

namespace rad {

// Per receiving node, its gathered (unrefined) links in link order: adj_[adjStart_[i] ..
// adjStart_[i + 1]); per link, whether its shooter emits (shooterEmits_).
void KeyTimeSolver::buildGatherLists() {
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

KeyTimeSolver::Pulled KeyTimeSolver::gatherPushPull(int i, const Gathered& down) {
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
    // The lamps' direct E (key_time_lamps.cpp), over the exposure as the links' H.
    const glm::dvec3 lamp = e > 0.0 ? lampE_[size_t(i)] / e : glm::dvec3(0.0);
    glm::dvec3 b = sp.emission + sp.reflectance * (irradiance + lamp);
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

// The irradiance each top gathers through cluster links, with a cluster row above 1 scaled down
// to 1 (closeRow's reason): near cluster links kept at the link bound, each a point form factor
// of the shooter's facing groups, summed past 1 on the tops beside them.
void KeyTimeSolver::gatherClusterLight() {
  clusters_->gather(B_, exposure_, clusterH_);
  if (!opt_.closure) return;
  for (size_t t = 0; t < clusterH_.size() && t < clusterRow_.size(); ++t)
    if (clusterRow_[t] > 1.0) clusterH_[t] /= clusterRow_[t];
}

void KeyTimeSolver::buildSweepLists() {
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
void KeyTimeSolver::solve() {
  buildGatherLists();
  buildSweepLists();
  irr_.assign(size_t(h_.size()), glm::dvec3(0.0));
  for (int it = 0; it < opt_.maxIterations; ++it) {
    maxDelta_ = maxB_ = 0;
    // Cluster links gather from the B of the sweep before (Jacobi for them, Gauss-Seidel
    // for the patch links).
    if (clusters_) gatherClusterLight();
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

}  // namespace rad
