// The texels beyond a triangle's long edge. Contracts in triangle_texels.h.
#include "libcommon/movies/triangle_texels.h"

#include <algorithm>
#include <cstddef>

namespace rad {

bool texelBeyondTriangle(int i, int j, int w, int h) {
  return (i + 0.5) / w + (j + 0.5) / h >= 1.0 - 1e-9;
}

void extendBeyondTriangle(std::vector<float>& rgb, int w, int h) {
  auto at = [&](int i, int j, int c) -> float& { return rgb[(size_t(j) * w + i) * 3 + c]; };
  // Row by row: a texel's left, lower and lower-left neighbours, and the two before it in its row
  // and column, come before it, inside the triangle or already extended.
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      if (!texelBeyondTriangle(i, j, w, h)) continue;
      for (int c = 0; c < 3; ++c) {
        float v;
        if (i >= 1 && j >= 1)
          v = at(i - 1, j, c) + at(i, j - 1, c) - at(i - 1, j - 1, c);
        else if (j >= 2)
          v = 2.0f * at(i, j - 1, c) - at(i, j - 2, c);
        else if (i >= 2)
          v = 2.0f * at(i - 1, j, c) - at(i - 2, j, c);
        else if (j == 1)
          v = at(i, 0, c);
        else if (i == 1)
          v = at(0, j, c);
        else
          continue;  // a 1 x 1 texture: nothing inside to continue
        at(i, j, c) = std::max(v, 0.0f);
      }
    }
}

}  // namespace rad
