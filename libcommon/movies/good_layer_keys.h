// The good layer of a movie keyed more finely than its indirect light changes: a movie whose
// bad links' shadows move is keyed every --moving-shadow-key-step frames (paper §5, Figure 6:
// the dynamic blockers' transmittance once per frame), while the good layer, the gathered
// indirect light (good_link_gather.h), is gathered only every --good-layer-key-step frames and
// interpolated linearly in time at the keys between, as rad-compose interpolates between keys.
//
// Why: a moving blocker's shadow interpolated between two keys several frames apart shows at
// both places half dark (a double shadow), which the structured error of docs/design.md §10.4
// reads as blotches; keying its movie every frame removes them, but the per-texel gather is
// most of a key's cost, and the indirect light it carries changes slowly (the global solution is
// itself linear between its key times). Gathering it at every fine key would double rad-movies'
// time on a scene of moving objects (issue 56; docs/results.md, "Moving shadows keyed every
// frame").
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/movies/good_link_gather.h"

namespace rad {

// The times at which a movie's good layer is gathered: the key frames goodStep apart (a
// multiple of the movie's key step, so that each is a key) and the last, over fps; empty when
// goodStep is not larger than the key step (gathered at every key).
std::vector<double> goodLayerGatherTimes(int firstFrame, int lastFrame, int keyStep, int goodStep,
                                         double fps);

class GoodLayerKeys {
 public:
  // gatherTimes: increasing, holding the movie's first and last key times (goodLayerGatherTimes);
  // empty: the good layer is gathered at every time asked.
  GoodLayerKeys(const GoodLinkGather& gather, std::vector<double> gatherTimes);

  // acc[x] = G(x, t): gathered when t is one of the gather times (or there are none), else
  // (1 - w) G(x, t0) + w G(x, t1) between the gather times t0 < t < t1 around it. The result
  // depends on t alone, not on the order of the calls (a piece of a movie bakes some of its
  // keys only, and each must come out as in the whole movie's bake).
  void at(double t, std::vector<glm::dvec3>& acc);

  long gathers() const { return gathers_; }

 private:
  // G at gather time t, kept with the one asked before (a key between two gather times needs
  // both; the keys come in increasing time).
  const std::vector<glm::dvec3>& gathered(double t, size_t texels);

  const GoodLinkGather& gather_;
  std::vector<double> times_;
  struct Kept {
    bool valid = false;
    double t = 0.0;
    std::vector<glm::dvec3> g;
  };
  std::array<Kept, 2> kept_;
  int next_ = 0;  // the slot the next gather replaces
  long gathers_ = 0;
};

}  // namespace rad
