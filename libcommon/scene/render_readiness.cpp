// The pipeline's pre-flight check (render_readiness.h).
#include "libcommon/scene/render_readiness.h"

#include "libcommon/core/error.h"

namespace rad {

std::vector<std::string> renderReadinessProblems(const Scene& scene) {
  std::vector<std::string> problems;
  if (scene.cameraNodes().empty())
    problems.push_back(
        "no camera: add a camera in Blender and tick \"Cameras\" in the glTF export "
        "(Include > Data)");
  if (!missingEmitterMessage(scene).empty())
    problems.push_back(
        "nothing emits light: give a surface an emissive material (Emission Strength above 0), "
        "or add a lamp and tick \"Punctual Lights\" in the glTF export (Include > Data)");
  return problems;
}

void requireRenderReadiness(const Scene& scene) {
  const std::vector<std::string> problems = renderReadinessProblems(scene);
  if (problems.empty()) return;
  std::string what;
  for (const std::string& p : problems) what += (what.empty() ? "" : "; ") + p;
  throw inputError(scene.path, what);
}

}  // namespace rad
