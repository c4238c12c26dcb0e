// The door for shadow methods in the texture-movie bake (paper §3.1 "Transmittance Texture
// Computation", §5; docs/design.md §6.3 "rad-movies").
//
// The baker (texture_movie_baker.h) asks one question per bad pair and key: which shooter
// samples does a set of blocker triangles hide from each texel of the receiver? The answer is
// one SampleMask per texel (bit s: sample s is occluded). Masks of disjoint blocker sets merge
// exactly by OR, which is what lets the baker render a pair's static blockers once per movie
// and its dynamic ones per key (§5).
//
// Implementations: TransmittanceRenderer (transmittance.h: OSMesa projective shadows into
// integer bit masks), RayCastMaskRenderer (ray_cast_masks.h: the same masks by exact segment
// tests on the CPU) and AdaptiveMaskRenderer, the default, which picks one of the two by the
// mask's size. A further method, or a layer that adds to the masks, is a new subclass handed to
// the baker through TextureMovieBakerBackends::maskRenderer; bake() is not edited.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "libcommon/scene/geometry.h"

namespace rad {

// One bit per shooter sample; sample s is bit s.
using SampleMask = uint64_t;
constexpr int kMaxTransmittanceSamples = 64;

using BlockerTriangle = std::array<glm::dvec3, 3>;

class OcclusionMaskRenderer {
 public:
  virtual ~OcclusionMaskRenderer() = default;

  // Occlusion masks of a width x height receiver texture (world-space receiver polygon,
  // vertices in the patch_hierarchy.h (u,v) order; texel (i, j) centre at (u,v) =
  // ((i+.5)/w, (j+.5)/h)): out[j * width + i] gets bit s when a blocker triangle (world
  // space, either side) crosses the segment from samples[s] to the texel's point on the
  // receiver plane, strictly in front of the plane. Samples behind the plane get no bits.
  // samples.size() in 1..64; an empty blocker list gives all-zero masks. out is resized.
  virtual void render(const Polygon& receiver, int width, int height,
                      const std::vector<glm::dvec3>& samples,
                      const std::vector<BlockerTriangle>& blockers,
                      std::vector<SampleMask>& out) = 0;

  // Cost figures of the report: renders that drew, and renders x samples.
  virtual long passes() const = 0;
  virtual long samplePasses() const = 0;
  // What did the rendering, for the report ("" when unknown).
  virtual std::string rendererName() const = 0;
};

// Makes the renderer on the baker's first need (a scene without bad pairs never makes one).
// May throw rad::Error(kEnvironment).
using OcclusionMaskRendererFactory = std::function<std::unique_ptr<OcclusionMaskRenderer>()>;

}  // namespace rad
