// What the toolchain sees in a scene, as rad-inspect prints it: patch count, emitters with
// their power, dynamic nodes with their motion bounds, cameras, time range and warnings.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "libcommon/scene/scene.h"

namespace rad {

// Emitted power of a one-sided Lambertian emitter: $\Phi = \pi L_e A$ per channel, in watts.
glm::dvec3 emittedPower(const Scene& scene, const InputPolygon& polygon, double t);

// JSON summary; also lists problems a tool would refuse (no camera, no emitter) as warnings.
nlohmann::json summarizeScene(const Scene& scene);
// The same as readable text.
std::string sceneSummaryText(const nlohmann::json& summary);

}  // namespace rad
