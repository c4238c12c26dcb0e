// The sRGB encoding of frames (declared in frame_composer.h). Its own file because the PNG
// writer in formats/frame_image.cpp needs it without the composer's GL and Embree code: the
// fuzz build (tests/fuzz) links the frame reader with neither.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "libcommon/compose/frame_composer.h"

namespace rad {

double srgbEncode(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
}

std::vector<uint8_t> toSrgb8(const std::vector<float>& rgb, double exposureEV) {
  const double scale = std::exp2(exposureEV);
  std::vector<uint8_t> out(rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i) {
    double v = std::isfinite(rgb[i]) ? double(rgb[i]) * scale : 0.0;
    out[i] = uint8_t(std::lround(255.0 * srgbEncode(v)));
  }
  return out;
}

}  // namespace rad
