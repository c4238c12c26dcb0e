// rad-inspect --inputs (spec: formats/gltf_scene.md "Inputs").
#include "formats/gltf_inputs.h"

#include <set>

#include "formats/gltf_scene_file.h"
#include "formats/provenance.h"
#include "libcommon/core/error.h"

namespace rad {

std::vector<GltfInput> gltfInputs(const std::string& scenePath) {
  const GltfSceneFile file = readGltfSceneFile(scenePath, /*requireJson=*/true);
  std::vector<GltfInput> inputs;
  inputs.push_back({hashFile(scenePath), scenePath});
  std::set<std::string> listed = {scenePath};
  for (const GltfExternalFile& f : file.externalFiles) {
    if (!f.scheme.empty() || !listed.insert(f.path).second) continue;
    // Checked before hashFile opens it: open() on a FIFO blocks.
    const std::string why = regularFileProblem(f.path);
    if (!why.empty()) {
      if (f.kind == GltfExternalFile::Kind::kBuffer)
        throw inputError(scenePath,
                         "buffer " + std::to_string(f.index) + " '" + f.path + "': " + why);
      inputs.push_back({"missing", f.path});
      continue;
    }
    inputs.push_back({hashFile(f.path), f.path});
  }
  return inputs;
}

std::string gltfInputsText(const std::vector<GltfInput>& inputs) {
  std::string text;
  for (const GltfInput& in : inputs) text += in.hash + "\t" + in.path + "\n";
  return text;
}

}  // namespace rad
