// The key-time solver's punctual lamps (docs/design.md §4 "Lights", §6.1): each leaf of the
// key's tree gets the lamps' direct irradiance E (lamp_irradiance.h), a first-pass term of
// $B = B_e + \rho (E + H)$ with no patch and no link; the oracle subdivides a receiver while a
// lamp's E varies across it by more than the refinement threshold allows (under the lamp, at
// its shadow boundaries). Values whose geometry and shadows did not change since the previous
// key are taken over (KeySolveInput::reuseLamps): equal to recomputing them, so the coherent
// solve stays bit-identical to --no-coherence. See key_time_solver.h.
#include <tbb/parallel_for.h>

#include "libcommon/radiosity/key_time_solver.h"

namespace rad {

double KeyTimeSolver::lampPower() const {
  glm::dvec3 sum(0.0);
  for (const PlacedPunctualLight* lamp : input_.lamps) sum += lamp->power();
  return maxComponent(sum);
}

// The oracle of a lamp's receiver: the power its spread could misplace, $\rho A \Delta E$,
// against eps Phi, as a link's $B F A$ (hierarchical_radiosity.h).
bool KeyTimeSolver::lampWantsSplit(int i) const {
  if (!refineOn_) return false;
  const double rho = maxComponent(surfaces_[h_.node(i).id.top].reflectance);
  return rho * s_.area[size_t(i)] * lampSpread_[size_t(i)] > epsAbs_ &&
         s_.area[size_t(i)] > opt_.minArea && h_.node(i).id.level() < PatchId::kMaxLevel;
}

void KeyTimeSolver::splitForLamps(int i, std::vector<int>& next) {
  const bool fresh = !s_.split[size_t(i)];
  const int first = h_.subdivide(i);
  addNewNodes();
  s_.split[size_t(i)] = 1;
  if (fresh)  // as splitLink: children enter this key's tree with their parent's radiosity
    for (int c = 0; c < 4; ++c) B_[size_t(first + c)] = B_[size_t(i)];
  for (int c = 0; c < 4; ++c) next.push_back(first + c);
}

// Every leaf of this key's tree without its lamp values gets them (taken over or computed, in
// parallel: pure functions of the node and the lamps), then the ones the oracle splits, serially
// in node order, and their children in turn. Returns the number of nodes split.
size_t KeyTimeSolver::refineLamps() {
  if (input_.lamps.empty()) return 0;
  std::vector<int> work;
  for (int i = 0; i < h_.size(); ++i)
    if (!s_.split[size_t(i)] && !lampKnown_[size_t(i)] && s_.inTree(i, h_)) work.push_back(i);
  size_t splits = 0;
  while (!work.empty()) {
    std::vector<std::vector<LampValue>> values(work.size());
    std::vector<int> reused(work.size(), 0);
    tbb::parallel_for(size_t(0), work.size(), [&](size_t j) {
      const int i = work[j];
      const Polygon& world = s_.world[size_t(i)];
      const glm::dvec3 n = world.normal();
      values[j].resize(input_.lamps.size());
      for (size_t l = 0; l < input_.lamps.size(); ++l) {
        if (input_.reuseLamps) {
          const auto it = input_.reuseLamps->find(lampValueKey(i, int(l)));
          if (it != input_.reuseLamps->end()) {
            values[j][l] = it->second;
            ++reused[j];
            continue;
          }
        }
        values[j][l] =
            lampIrradiance(*input_.lamps[l], world, n, input_.visibility, h_.node(i).id.top);
      }
    });
    std::vector<int> next;
    for (size_t j = 0; j < work.size(); ++j) {
      const int i = work[j];
      glm::dvec3 sum(0.0);
      double spread = 0.0;
      for (size_t l = 0; l < values[j].size(); ++l) {
        sum += values[j][l].mean;
        spread = std::max(spread, values[j][l].spread);
        s_.lampValues.emplace(lampValueKey(i, int(l)), values[j][l]);
      }
      lampE_[size_t(i)] = sum;
      lampSpread_[size_t(i)] = spread;
      lampKnown_[size_t(i)] = 1;
      s_.lampValuesReused += size_t(reused[j]);
      if (!lampWantsSplit(i)) continue;
      splitForLamps(i, next);
      ++splits;
    }
    // A child split before (by a link or another key's lamps) may already be known or split.
    std::vector<int> unknown;
    for (int i : next)
      if (!s_.split[size_t(i)] && !lampKnown_[size_t(i)]) unknown.push_back(i);
    work.swap(unknown);
  }
  return splits;
}

}  // namespace rad
