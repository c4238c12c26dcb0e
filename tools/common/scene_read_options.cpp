#include "tools/common/scene_read_options.h"

#include <iostream>
#include <set>

#include "formats/gltf_scene.h"
#include "tools/common/tool_main.h"

namespace rad {

CLI::Option* addSceneReadOptions(CLI::App& app) {
  // Declared here once, for every tool, so every stage reads a scene's lamps alike; what it
  // gives is recorded by the scene digests' lights part (the lamps' intensities as read).
  app.add_option_function<std::string>(
         "--light-units",
         [](const std::string& name) {
           defaultGltfReadOptions().lightUnits = parseLightUnits(name);
         },
         "units of KHR_lights_punctual lamps: gltf (cd, lux as W/sr, W/m^2), blender (as "
         "Blender's exporter wrote them: / 683, Cycles' spot profile), auto (blender when "
         "asset.generator is Blender's exporter, else gltf)")
      ->default_str(lightUnitsName(defaultGltfReadOptions().lightUnits))
      ->check(CLI::IsMember({"auto", "gltf", "blender"}));
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
