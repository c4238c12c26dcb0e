// Visible samples per leaf and frame: what rad-intervals' item buffers give its builder
// (libcommon/intervals/texture_intervals_builder.h), written by a farm task that draws the item
// buffers of one window of frames (`rad-intervals --window`) and read by the pass that decides
// the movies (`--merge`), which then draws nothing (docs/design.md §7). Layout and version:
// formats/visible_samples.md.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/container.h"

namespace rad {

constexpr const char* kVisibleSamplesKind = "visiblesamples";
constexpr int kVisibleSamplesMajor = 1;
constexpr int kVisibleSamplesMinor = 0;

struct VisibleSamplesFrame {
  int frame = 0;
  // No pixel centre shows a surface (the tool's empty-frame warning).
  bool empty = false;
  double itemBufferSeconds = 0.0;  // render and readback, for the report
  // Leaves (dense node index) with at least one visible sample, ascending, and their counts.
  std::vector<uint32_t> leaf, count;
};

struct VisibleSamples {
  // The parameters the counts were made with (rad-intervals' provenance parameters, scene
  // digests included); a reader takes counts only made with its own.
  nlohmann::json parameters;
  std::vector<VisibleSamplesFrame> frames;  // strictly increasing frame numbers
};

// Throws rad::outputError(path, ...) when it cannot write.
void writeVisibleSamples(const std::string& path, const VisibleSamples& samples,
                         const Provenance& provenance);
// Throws rad::inputError(path, ...) naming the first problem (kind, shapes, order).
VisibleSamples readVisibleSamples(const std::string& path);

}  // namespace rad
