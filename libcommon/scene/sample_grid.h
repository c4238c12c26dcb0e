// The sub-pixel samples rad-compose shades and rad-intervals makes sure are covered (docs/design.md
// §6.2, §6.4): a regular grid of s x s samples a pixel, over the image and a margin of whole
// pixels around it, so that the filter of a pixel on the image's border has its whole support,
// as in Cycles, whose border pixels draw samples outside the image too.
//
// Sample (i, j) of the grid (i = column, j = row, row 0 at the top, as camera_projection.h's
// pixels) lies at continuous image-pixel coordinates ((i + 0.5) / s - m, (j + 0.5) / s - m).
// s is odd, so each pixel's centre (col + 0.5, row + 0.5) is a sample of the grid: sample
// (s (col + m) + (s - 1) / 2, s (row + m) + (s - 1) / 2), at exactly the centre's coordinates.
// With s = 1 and m = 0 the grid is the pixel centres, bit for bit (pixel (col, row) at
// (col + 0.5, row + 0.5)).
//
// A grid is rendered (item_buffer.h) with the image's projection and the image's NDC scaled by
// ndcScale(), so its margin lies outside the image's frustum.
#pragma once

#include <glm/glm.hpp>

#include "libcommon/scene/camera_projection.h"
#include "libcommon/scene/pixel_filter.h"

namespace rad {

struct SampleGrid {
  ImageSize image;
  int perAxis = 1;  // s: odd, >= 1
  int margin = 0;   // m: whole pixels on each side

  // The grid's size in samples: (s (W + 2m)) x (s (H + 2m)).
  ImageSize size() const {
    return {perAxis * (image.width + 2 * margin), perAxis * (image.height + 2 * margin)};
  }
  // Image-pixel coordinates of sample (i, j).
  glm::dvec2 position(int i, int j) const {
    return glm::dvec2((i + 0.5) / perAxis - margin, (j + 0.5) / perAxis - margin);
  }
  // The grid column (row) of the centre of image column (row) `pixel` (-m <= pixel < W + m).
  int centre(int pixel) const { return perAxis * (pixel + margin) + (perAxis - 1) / 2; }
  // Image NDC x, y times these give the grid's NDC: W / (W + 2m), H / (H + 2m).
  glm::dvec2 ndcScale() const {
    return glm::dvec2(double(image.width) / (image.width + 2 * margin),
                      double(image.height) / (image.height + 2 * margin));
  }
  // The pixel centres alone: s = 1, m = 0.
  bool isPixelCentres() const { return perAxis == 1 && margin == 0; }
};

// How a tool samples its pixels: the filter and, for the grid, the samples per axis.
struct PixelSampling {
  PixelFilter filter;
  int samplesPerAxis = 3;  // odd, 1..15 (not used by filter none)

  // One sample through each pixel centre: the frames before filtering, bit for bit.
  static PixelSampling pixelCentres() { return {PixelFilter::pixelCentre(), 1}; }
  // The grid over `image` that holds every sample of every pixel's filter support, and each
  // pixel's neighbours' centres (rad-compose's shortcut on uniform footprints needs them): s =
  // samplesPerAxis, m = max(1, ceil(radius - 1/2)); filter none: the pixel centres.
  SampleGrid grid(ImageSize image) const;
  // Whether every sample of `inner` is a sample of `outer` (the same image): rad-intervals made
  // sure of coverage on `outer`, rad-compose shades `inner`.
  static bool covers(const SampleGrid& outer, const SampleGrid& inner);
  // Throws rad::Error(kUsage) naming the flag of the first invalid value.
  void validate() const;
  std::string toString() const;  // "blackman-harris 1.5, 3x3 samples"
};

}  // namespace rad
