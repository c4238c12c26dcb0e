// rad-intervals' options (paper §4.1, §4.3; docs/design.md §6.2 rad-intervals): the command line
// binds each flag to a field here (the algorithm's own in `build`), and toJson() is the provenance
// parameters of intervals.rti, so a flag's name and default are written once (docs/conventions.md
// §7 "Stages with one shape"). The frame loop is tools/stages/interval_sequence.h.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "libcommon/core/parameter_table.h"
#include "libcommon/intervals/texture_intervals_builder.h"

namespace rad {

struct IntervalsOptions {
  std::string scene;   // glTF scene
  std::string output;  // intervals.rti
  // FIRST-LAST[xSTEP]; empty: the scene's whole animation at build.fps (animationFrames),
  // filled in by the tool before toJson() so the provenance records the frames in effect.
  std::string frames;
  std::string size = "352x240";  // item buffer size WxH, parsed into build.imageSize
  std::string camera;            // node or camera name; empty: the first camera
  std::string itemBuffers;       // also write each frame's item buffer here; empty: no
  std::string report;            // JSON report file; empty: none
  // The samples rad-compose will shade (sample_grid.h), copied into build.sampling: Blender's
  // default filter on a 3 x 3 grid.
  PixelSampling sampling;
  TextureIntervalsOptions build;

  // Provenance parameters: intervalsParameters() under their flags' names.
  nlohmann::json toJson() const;
};

// rad-intervals' parameters, declared once (libcommon/core/parameter_table.h). It has no
// quality preset: the README's recommended settings leave it as shipped.
const ParameterTable<IntervalsOptions>& intervalsParameters();

}  // namespace rad
