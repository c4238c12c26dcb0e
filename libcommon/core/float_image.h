// A float image in memory: interleaved channels, row 0 at the top (the camera_projection.h
// pixel convention). What the reference renderer produces and what image comparison reads.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace rad {

struct FloatImage {
  int width = 0, height = 0;
  std::vector<std::string> channels;  // e.g. {"R", "G", "B"}
  std::vector<float> pixels;          // width * height * channels.size(), row-major

  FloatImage() = default;
  FloatImage(int w, int h, std::vector<std::string> names)
      : width(w),
        height(h),
        channels(std::move(names)),
        pixels(std::size_t(w) * std::size_t(h) * channels.size(), 0.0f) {}

  int channelCount() const { return int(channels.size()); }
  std::size_t sampleCount() const { return pixels.size(); }
  float& at(int x, int y, int c) {
    return pixels[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * channels.size() +
                  std::size_t(c)];
  }
  float at(int x, int y, int c) const {
    return pixels[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * channels.size() +
                  std::size_t(c)];
  }
};

}  // namespace rad
