// intervals.rti: the texture-movie extents rad-intervals writes (container kind "intervals").
// Arrays and metadata: formats/texture_intervals.md. Paper §4.1, §4.3.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/container.h"
#include "libcommon/scene/patch_hierarchy.h"

namespace rad {

constexpr const char* kTextureIntervalsKind = "intervals";
constexpr int kTextureIntervalsMajor = 1;
constexpr int kTextureIntervalsMinor = 0;

// Why a movie ended (paper §4.1 events, plus the window end of a split run).
enum class CloseReason : uint8_t {
  kLeftFrustum = 0,  // no pixel of it in the frustum any more
  kHidden = 1,       // in the frustum but covered by other patches
  kLevelChange = 2,  // represented by its children (or its parent) from the next frame
  kResize = 3,       // texture resolution changed beyond the hysteresis
  kMaxLength = 4,    // reached --max-length frames
  kWindow = 5,       // still open at the end of the --frames window
};
constexpr int kCloseReasonCount = 6;
const char* closeReasonName(CloseReason r);  // "left_frustum", "hidden", ...

struct TextureInterval {
  uint32_t movie = 0;                     // movie id, 0.. in order of (firstFrame, patch)
  PatchId patch;                          // the patch node the movie textures
  int32_t firstFrame = 0, lastFrame = 0;  // inclusive
  int32_t width = 1, height = 1;          // texels; texel (i, j) centre at node (u,v) =
                                          // ((i + 0.5) / width, (j + 0.5) / height)
  CloseReason reason = CloseReason::kWindow;
  int level() const { return patch.level(); }
  int frameCount() const { return lastFrame - firstFrame + 1; }
};

struct TextureIntervals {
  int firstFrame = 0, lastFrame = 0;  // the window computed
  double fps = 24.0;
  int imageWidth = 0, imageHeight = 0;
  std::vector<TextureInterval> movies;  // sorted by id
  double frameTime(int frame) const { return frame / fps; }
};

void writeTextureIntervals(const std::string& path, const TextureIntervals& intervals,
                           const Provenance& provenance, const nlohmann::json& metadata);
// Validates: frames inside the window, first <= last, sizes >= 1, ids 0..n-1 in order, known
// reasons. Errors are rad::inputError(path, ...).
TextureIntervals readTextureIntervals(const ContainerReader& reader);
TextureIntervals readTextureIntervals(const std::string& path);

// rad-inspect's summary: movies, mean length, texels per frame, levels, close reasons.
nlohmann::json summarizeTextureIntervals(const ContainerReader& reader);

}  // namespace rad
