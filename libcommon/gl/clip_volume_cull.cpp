// Object culling against the clip volume's side planes. Contract in clip_volume_cull.h.
#include "libcommon/gl/clip_volume_cull.h"

#include <cmath>

namespace rad {

bool outsideClipVolume(const glm::mat4& clipFromLocal, const LocalBounds& bounds) {
  const glm::vec3& lo = bounds[0];
  const glm::vec3& hi = bounds[1];
  if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) return true;
  // Per plane: whether every corner so far is outside it (x > w, -x > w, y > w, -y > w).
  bool allOutside[4] = {true, true, true, true};
  for (int c = 0; c < 8; ++c) {
    const glm::dvec4 p((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z, 1.0);
    glm::dvec4 clip(0.0), magnitude(0.0);
    for (int col = 0; col < 4; ++col)
      for (int row = 0; row < 4; ++row) {
        const double term = double(clipFromLocal[col][row]) * p[col];
        clip[row] += term;
        magnitude[row] += std::abs(term);
      }
    const double margin = 1e-5 * (magnitude.x + magnitude.y + magnitude.w) + 1e-30;
    allOutside[0] = allOutside[0] && clip.x - clip.w > margin;
    allOutside[1] = allOutside[1] && -clip.x - clip.w > margin;
    allOutside[2] = allOutside[2] && clip.y - clip.w > margin;
    allOutside[3] = allOutside[3] && -clip.y - clip.w > margin;
    if (!(allOutside[0] || allOutside[1] || allOutside[2] || allOutside[3])) return false;
  }
  return true;
}

}  // namespace rad
