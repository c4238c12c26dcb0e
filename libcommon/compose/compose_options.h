// rad-compose's options (paper §3.1 last step; docs/design.md §6.4 "rad-compose"): the command line
// binds each flag to a field here, and toJson() is the provenance parameters of every frame,
// so a flag's name is written once (docs/conventions.md §7 "Stages with one shape"). The defaults
// that come from the inputs (the intervals' window, fps and size, the scene's first camera) are
// filled in by the tool once the inputs are read, before toJson(), so the provenance records
// every value in effect. The frame loop is tools/stages/frame_sequence.h.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "libcommon/core/parameter_table.h"
#include "libcommon/scene/pixel_filter.h"

namespace rad {

struct ComposeOptions {
  std::string scene;               // glTF scene
  std::string global;              // global.rlh (rad-global)
  std::string intervals;           // intervals.rti (rad-intervals)
  std::string movies;              // MOVIES_DIR (rad-movies)
  std::string output;              // FRAMES_DIR for NNNN.exr / NNNN.png
  std::string frames;              // FIRST-LAST[xSTEP]; empty: the intervals' window
  std::optional<double> fps;       // frame f at f / fps; empty: the intervals'
  std::string size;                // WIDTHxHEIGHT; empty: the intervals'
  std::string camera;              // node or camera name; empty: the first camera
  std::optional<double> exposure;  // PNG exposure in EV; empty: 0 (or --auto-exposure)
  bool autoExposure = false;
  bool half = false;  // HALF EXR channels
  std::string compression = "none";
  bool noPng = false;
  // Pixel sampling (footprint_filter.h); each empty: intervals.rti's, whose item buffers saw
  // those samples.
  std::optional<PixelFilterType> pixelFilter;
  std::optional<double> filterWidth;
  std::optional<int> pixelSamples;
  bool everySample = false;  // shade every sample (no shortcut on uniform footprints)
  std::string report;        // JSON report file; empty: none

  // Provenance parameters: composeParameters() under their flags' names, and output. An unset
  // fps or exposure is null.
  nlohmann::json toJson() const;
};

// rad-compose's parameters, declared once (libcommon/core/parameter_table.h). It has no quality
// preset: the README's recommended settings leave it as shipped.
const ParameterTable<ComposeOptions>& composeParameters();

}  // namespace rad
