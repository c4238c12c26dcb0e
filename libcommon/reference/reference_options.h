// rad-reference's options (docs/design.md §8 "error vs converged reference"): the command line
// binds each flag to a field here, and toJson() is the provenance parameters of every frame it
// writes, so a flag's name and default are written once (docs/conventions.md §7 "Stages with one
// shape").
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "libcommon/core/parameter_table.h"

#include "libcommon/reference/path_tracer.h"

namespace rad {

struct ReferenceOptions {
  std::string scene;   // glTF scene
  std::string output;  // directory for NNNN.exr
  // FIRST-LAST[xSTEP]; empty: the scene's whole animation (animationFrames), filled in by the
  // tool before toJson() so the provenance records the frames in effect.
  std::string frames;
  double fps = 24.0;  // frame f is at time f / fps
  std::string size = "352x240";
  std::string camera;  // node or camera name; empty: the first camera
  int spp = 256;       // samples per pixel
  int maxDepth = 64;   // reflections per path
  std::uint64_t seed = 0;
  bool decorrelateFrames = false;
  // The pixel filter, importance-sampled (pixel_filter.h): rad-compose's default, Blender's.
  // --pixel-centres, the old spelling of --pixel-filter none, is the tool's.
  PixelFilter filter;

  // The path tracer's options (samples, depth, seed, decorrelation, pixel filter).
  PathTracerOptions pathTracer() const;
  // Provenance parameters: referenceParameters() under their flags' names.
  nlohmann::json toJson() const;
};

// rad-reference's parameters, declared once (libcommon/core/parameter_table.h).
const ParameterTable<ReferenceOptions>& referenceParameters();

}  // namespace rad
