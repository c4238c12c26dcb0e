// rad-movies' lamp term (contract in lamp_direct_term.h).
#include "libcommon/movies/lamp_direct_term.h"

#include <algorithm>
#include <atomic>

#include <tbb/parallel_for.h>

namespace rad {

bool lampShadowsMove(const Scene& scene, const std::vector<InputPolygon>& tops,
                     const SceneEmitters& emitters, int receiverNode, const Polygon& receiver,
                     double t0, double t1) {
  if (emitters.lamps().empty()) return false;
  if (scene.isDynamic(receiverNode, t0, t1)) return true;
  std::vector<std::array<glm::dvec3, 2>> swept;
  for (int node : movingNodesOf(scene, tops, t0, t1))
    swept.push_back(scene.sweptBounds(node, t0, t1));
  for (int lamp : emitters.lamps()) {
    const Emitter& e = emitters[size_t(lamp)];
    if (e.moves(t0, t1)) return true;
    AxisBox shaft = boxOf(receiver);
    const auto b = e.bounds(t0, t1);
    growBox(shaft, b[0]);
    growBox(shaft, b[1]);
    for (const auto& s : swept)
      if (boxesMeet(shaft, AxisBox{s[0], s[1]})) return true;
  }
  return false;
}

glm::dvec3 lampDirectAt(const PlacedEmitter& lamp, const glm::dvec3& p, const glm::dvec3& n,
                        const VisibilityScene& visibility, std::uint32_t receiverTop) {
  const glm::dvec3 E = lamp.irradiance(p, n);
  if (!(std::max(E.x, std::max(E.y, E.z)) > 0.0)) return glm::dvec3(0.0);
  return visibility.occluded(p, lamp.shadowTarget(p), receiverTop) ? glm::dvec3(0.0) : E;
}

LampDirectTerm::LampDirectTerm(const SceneEmitters& emitters, const MovieGeometry& geometry,
                               SceneVisibility& visibility, std::uint32_t receiverTop)
    : emitters_(emitters), geo_(geometry), vis_(visibility), receiverTop_(receiverTop) {
  const double t0 = geo_.keyTime(0), t1 = geo_.keyTime(geo_.keys() - 1);
  receiverMoves_ = geo_.receiverDynamic();
  for (int lamp : emitters_.lamps()) lampMoves_.push_back(emitters_[size_t(lamp)].moves(t0, t1));
  staticOpen_.resize(lampMoves_.size());
}

void LampDirectTerm::add(int k, double t, std::vector<glm::dvec3>& acc) {
  const size_t texels = geo_.texels();
  const bool moving = vis_.dynamicNodeCount() > 0;
  if (moving) vis_.setTime(t);
  std::atomic<long> rays{0};
  for (size_t l = 0; l < lampMoves_.size(); ++l) {
    const std::unique_ptr<PlacedEmitter> placed = emitters_[size_t(emitters_.lamps()[l])].at(t);
    if (!placed) continue;
    const PlacedEmitter& lamp = *placed;
    // Static lamp and receiver: the static blockers once a movie (paper §5).
    const bool keep = !lampMoves_[l] && !receiverMoves_;
    std::vector<char>& open = staticOpen_[l];
    const bool fresh = !keep || open.empty();
    if (fresh) open.assign(texels, 0);
    std::vector<glm::dvec3> add(texels, glm::dvec3(0.0));
    tbb::parallel_for(size_t(0), texels, [&](size_t x) {
      const glm::dvec3 p = geo_.texelPoint(k, x);
      const glm::dvec3 E = lamp.irradiance(p, geo_.texelNormal(k, x));
      if (!(std::max(E.x, std::max(E.y, E.z)) > 0.0)) return;
      const glm::dvec3 target = lamp.shadowTarget(p);
      long cast = 0;
      if (fresh) {
        open[x] = vis_.staticPart().occluded(p, target, receiverTop_) ? 0 : 1;
        ++cast;
      }
      if (open[x] && moving) {
        ++cast;
        if (vis_.movingPart().occluded(p, target, receiverTop_)) cast = -cast;
      }
      rays += cast < 0 ? -cast : cast;
      if (open[x] && cast >= 0) add[x] = E;
    });
    // Added lamp by lamp in texel order: the same sums whatever the threads.
    for (size_t x = 0; x < texels; ++x) acc[x] += add[x];
  }
  rays_ += rays.load();
}

}  // namespace rad
