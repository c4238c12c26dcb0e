// The sRGB encoding of frames (declared in frame_composer.h). Its own file because the PNG
// writer in formats/frame_image.cpp needs it without the composer's GL and Embree code: the
// fuzz build (tests/fuzz) links the frame reader with neither.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "libcommon/compose/frame_composer.h"

namespace rad {

double srgbEncode(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
}

namespace {

uint8_t srgbCode(double v) { return uint8_t(std::lround(255.0 * srgbEncode(v))); }

uint32_t floatBits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

float bitsFloat(uint32_t u) {
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}

// srgbCode of a float at exposure 0 by its 255 thresholds instead of a pow and an lround per
// channel: t[c] is the least float with srgbCode >= c, found by bisection over the non-negative
// floats (ordered as their bits). The code is monotonic in the value (pow's error is below one
// ulp), so between thresholds it is constant; `exact` checks that around each threshold, 64 floats
// either side, where a non-monotonic pow could show, and pow is used instead if not. Every float of
// [0, 1.125] was checked once against srgbCode (no difference);
// Srgb.ExposureZeroTableEqualsPowOnFloats checks every 61st.
struct SrgbThresholds {
  float t[256];
  bool exact = true;
  SrgbThresholds() {
    t[0] = 0.0f;
    const uint32_t one = floatBits(1.0f);
    for (int c = 1; c < 256; ++c) {
      uint32_t lo = 0, hi = one;  // srgbCode(0) = 0 < c <= 255 = srgbCode(1)
      while (hi - lo > 1) {
        const uint32_t mid = lo + (hi - lo) / 2;
        (srgbCode(double(bitsFloat(mid))) >= c ? hi : lo) = mid;
      }
      t[c] = bitsFloat(hi);
      for (int64_t d = -64; d <= 64; ++d) {
        const int64_t u = int64_t(hi) + d;
        if (u < 0 || u > int64_t(one)) continue;
        if ((srgbCode(double(bitsFloat(uint32_t(u)))) >= c) != (d >= 0)) exact = false;
      }
    }
    exact = exact && t[255] <= 1.0f;
    fillBuckets();
  }
  // The largest c with t[c] <= f (f finite; 0 for f <= 0): from the code at the start of f's
  // bucket (its float's top 16 bits), then past the thresholds within the bucket (at most a
  // couple: near 1 a bucket is 1/128 of the value wide, a code step about twice that).
  uint8_t code(float f) const {
    const uint32_t u = floatBits(f);
    if (u & 0x80000000u) return 0;         // negative, -0
    if (u >= kOneBits) return 255;         // 1 and above: t[255] <= 1
    int c = bucketCode[u >> 16];
    while (c < 255 && t[c + 1] <= f) ++c;
    return uint8_t(c);
  }
  static constexpr uint32_t kOneBits = 0x3F800000u;  // 1.0f
  uint8_t bucketCode[(kOneBits >> 16) + 1];
  void fillBuckets() {
    for (uint32_t b = 0; b <= (kOneBits >> 16); ++b) {
      const float f = bitsFloat(b << 16);
      int c = 0;
      for (int step = 128; step > 0; step >>= 1)
        if (t[c + step] <= f) c += step;
      bucketCode[b] = uint8_t(c);
    }
  }
};

}  // namespace

uint8_t srgb8AtExposureZero(float linear) {
  static const SrgbThresholds table;
  if (!std::isfinite(linear)) return 0;
  return table.exact ? table.code(linear) : srgbCode(double(linear));
}

std::vector<uint8_t> toSrgb8(const std::vector<float>& rgb, double exposureEV) {
  const double scale = std::exp2(exposureEV);
  std::vector<uint8_t> out(rgb.size());
  if (scale == 1.0) {  // v = double(rgb[i]) exactly: the float thresholds decide
    for (size_t i = 0; i < rgb.size(); ++i) out[i] = srgb8AtExposureZero(rgb[i]);
    return out;
  }
  for (size_t i = 0; i < rgb.size(); ++i) {
    double v = std::isfinite(rgb[i]) ? double(rgb[i]) * scale : 0.0;
    out[i] = srgbCode(v);
  }
  return out;
}

}  // namespace rad
