// What a scene needs before the pipeline's first stage runs (issue 57): a camera to render from
// and something that emits. Blender's glTF exporter leaves cameras and lamps out by default
// ("Cameras" and "Punctual Lights" are unticked), and without this check the pipeline found out
// only in rad-intervals, after rad-global's whole solve (docs/design.md §7 "Pre-flight").
#pragma once

#include <string>
#include <vector>

#include "libcommon/scene/scene.h"

namespace rad {

// What the scene lacks for the pipeline, one sentence each that says what to export (empty: it
// can be rendered). Something emits as the stages see it (missingEmitterMessage: a mesh of the
// displayed scene with an emissive material, or a KHR_lights_punctual lamp on one of its nodes).
// A camera is any camera node of the displayed scene. No solve: it takes the time of reading the
// file.
std::vector<std::string> renderReadinessProblems(const Scene& scene);

// Throws rad::Error (kBadInput) `path: problem; problem` when renderReadinessProblems is not
// empty.
void requireRenderReadiness(const Scene& scene);

}  // namespace rad
