// The texels beyond a triangle's long edge continue the texels inside (triangle_texels.h).
#include "libcommon/movies/triangle_texels.h"

#include <gtest/gtest.h>

namespace rad {
namespace {

TEST(TriangleTexels, TheLongEdgeAndBeyondAreTheTexelsOnOrPastUPlusVOne) {
  EXPECT_FALSE(texelBeyondTriangle(0, 0, 4, 4));
  EXPECT_FALSE(texelBeyondTriangle(2, 0, 4, 4));
  EXPECT_TRUE(texelBeyondTriangle(3, 0, 4, 4));  // centre (7/8, 1/8): on the edge
  EXPECT_TRUE(texelBeyondTriangle(3, 3, 4, 4));
  EXPECT_TRUE(texelBeyondTriangle(0, 0, 1, 1));
  EXPECT_FALSE(texelBeyondTriangle(7, 0, 16, 2));  // 7.5 / 16 + 1 / 4 < 1
  EXPECT_TRUE(texelBeyondTriangle(12, 0, 16, 2));  // 12.5 / 16 + 1 / 4 > 1
}

// A linear irradiance a + b u + c v is continued exactly on and beyond the edge, square or not;
// the texels inside are left as they are; a continuation below zero is clamped to it.
TEST(TriangleTexels, ALinearFieldIsContinuedExactly) {
  for (auto [w, h] : {std::pair(8, 8), std::pair(16, 3), std::pair(2, 9)}) {
    std::vector<float> rgb(size_t(w) * h * 3, -7.0f), want(rgb.size());
    for (int j = 0; j < h; ++j)
      for (int i = 0; i < w; ++i)
        for (int c = 0; c < 3; ++c) {
          const size_t x = (size_t(j) * w + i) * 3 + size_t(c);
          want[x] = float(10.0 + (1 + c) * (i + 0.5) / w - 2.0 * (j + 0.5) / h);
          if (!texelBeyondTriangle(i, j, w, h)) rgb[x] = want[x];
        }
    extendBeyondTriangle(rgb, w, h);
    for (size_t x = 0; x < rgb.size(); ++x) EXPECT_NEAR(rgb[x], want[x], 1e-4) << w << "x" << h;
  }
  std::vector<float> steep(4 * 4 * 3, 0.0f);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i)
      for (int c = 0; c < 3; ++c) steep[(size_t(j) * 4 + i) * 3 + size_t(c)] = float(3 - i - j);
  extendBeyondTriangle(steep, 4, 4);
  for (float v : steep) EXPECT_GE(v, 0.0f);
  std::vector<float> one = {1.0f, 2.0f, 3.0f};
  extendBeyondTriangle(one, 1, 1);
  EXPECT_EQ(one, (std::vector<float>{1.0f, 2.0f, 3.0f})) << "nothing inside to continue";
}

}  // namespace
}  // namespace rad
