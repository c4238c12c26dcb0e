// What every tool that reads a glTF scene shares (formats/gltf_scene.md): the texture bound and
// the scene's warnings on stderr.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace rad {

// Adds --light-units and --max-texture-pixels (bound to defaultGltfReadOptions(), which
// readGltfScene(path) uses); returns the latter. Called by parseCommandLine, so every tool has
// them.
CLI::Option* addSceneReadOptions(CLI::App& app);
// Installs a warning handler that prints each warning of each scene read, once per run, as
// `tool: SCENE: warning: TEXT` on stderr. Called by setUpApp.
void setGltfWarnings(const std::string& tool);

}  // namespace rad
