// The sub-pixel sample grid. Contracts in sample_grid.h.
#include "libcommon/scene/sample_grid.h"

#include <algorithm>
#include <cmath>

#include "libcommon/core/error.h"

namespace rad {

SampleGrid PixelSampling::grid(ImageSize image) const {
  SampleGrid g;
  g.image = image;
  if (filter.isNone()) return g;
  g.perAxis = samplesPerAxis;
  g.margin = std::max(1, int(std::ceil(filter.radius() - 0.5)));
  return g;
}

bool PixelSampling::covers(const SampleGrid& outer, const SampleGrid& inner) {
  // Sample a of `inner` is at (a + 1/2) / s_i - m_i; it is sample b of `outer` when
  // b + 1/2 = ((a + 1/2) / s_i - m_i + m_o) s_o, an integer b for every a iff s_o / s_i is an
  // odd integer; and the margins must nest.
  if (outer.image != inner.image) return false;
  if (outer.perAxis % inner.perAxis != 0 || (outer.perAxis / inner.perAxis) % 2 == 0) return false;
  return inner.margin <= outer.margin;
}

void PixelSampling::validate() const {
  filter.validate();
  if (samplesPerAxis < 1 || samplesPerAxis > 15 || samplesPerAxis % 2 == 0)
    throw Error(ExitCode::kUsage, "",
                "--pixel-samples " + std::to_string(samplesPerAxis) +
                    ": expected an odd number in [1, 15] (samples a pixel along each axis, so "
                    "that the pixel centre is one)");
}

std::string PixelSampling::toString() const {
  if (filter.isNone()) return filter.toString() + " (pixel centres)";
  return filter.toString() + ", " + std::to_string(samplesPerAxis) + "x" +
         std::to_string(samplesPerAxis) + " samples a pixel";
}

}  // namespace rad
