#include "tools/common/scene_read_options.h"

#include <iostream>
#include <set>

#include "formats/gltf_scene.h"
#include "tools/common/tool_main.h"

namespace rad {

CLI::Option* addSceneReadOptions(CLI::App& app) {
  return app
      .add_option("--max-texture-pixels", defaultGltfReadOptions().maxTexturePixels,
                  "a scene's texture with more pixels (read from its header) is ignored with a "
                  "warning")
      ->capture_default_str()
      ->check(positiveInteger());
}

void setGltfWarnings(const std::string& tool) {  // A scene read twice in one run (rad-diff) prints
                                                 // its warnings once.
  setGltfWarningHandler([tool](const std::string& path, const std::string& warning) {
    static std::set<std::string> printed;
    if (printed.insert(path + '\n' + warning).second)
      std::cerr << tool << ": " << path << ": warning: " << warning << "\n";
  });
}

}  // namespace rad
