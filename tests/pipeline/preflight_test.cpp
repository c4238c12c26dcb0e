// The pipeline's pre-flight check (issue 57, docs/design.md §7): a scene Blender exported with its
// defaults (no camera, no lamps) fails before the first stage, in seconds, with one line that
// says what to export. Before the check, `make` spent rad-global's whole solve and then failed
// in rad-intervals with `no camera`.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/cli/cli_util.h"
#include "tests/pipeline/pipeline_util.h"

namespace rad::test {
namespace {

namespace fs = std::filesystem;

const std::string kScene = std::string(RAD_SOURCE_DIR) + "/pipelines/scenes/cornell-moving.gltf";

nlohmann::json bundledScene() {
  std::ifstream in(kScene);
  return nlohmann::json::parse(in);
}

// The bundled scene without its camera node in the displayed scene (as Blender's default export,
// "Cameras" unticked).
nlohmann::json withoutCamera(nlohmann::json g) {
  nlohmann::json kept = nlohmann::json::array();
  for (const auto& n : g["scenes"][0]["nodes"])
    if (!g["nodes"][n.get<size_t>()].contains("camera")) kept.push_back(n);
  g["scenes"][0]["nodes"] = kept;
  return g;
}

// The bundled scene with no emissive material.
nlohmann::json withoutEmission(nlohmann::json g) {
  for (auto& m : g["materials"]) {
    m.erase("emissiveFactor");
    m.erase("extensions");
  }
  return g;
}

std::string writeScene(const fs::path& dir, const std::string& name, const nlohmann::json& g) {
  const fs::path path = dir / name;
  std::ofstream(path) << g.dump();
  return path.string();
}

struct MakeRun {
  CommandResult result;
  double seconds = 0.0;
};

MakeRun runPipeline(const fs::path& out, const std::string& scene) {
  const auto start = std::chrono::steady_clock::now();
  MakeRun run;
  run.result = runCommand(makeCommand(out, RAD_BIN_DIR, "SCENE=" + scene));
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

class Preflight : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(missingStages().empty()) << "stage not built: " << missingStages().front();
  }
};

TEST_F(Preflight, SceneWithoutCameraFailsBeforeTheFirstStage) {
  const fs::path dir = freshDir("preflight_camera");
  const std::string scene = writeScene(dir, "no-camera.gltf", withoutCamera(bundledScene()));
  const MakeRun run = runPipeline(dir / "out", scene);
  EXPECT_NE(run.result.exitCode, 0);
  EXPECT_NE(run.result.err.find("rad-inspect: " + scene +
                                ": no camera: add a camera in Blender and tick \"Cameras\" in "
                                "the glTF export"),
            std::string::npos)
      << run.result.err;
  // No stage ran: nothing of rad-global's, and no stage's output.
  EXPECT_EQ(run.result.err.find("rad-global"), std::string::npos) << run.result.err;
  EXPECT_EQ(run.result.out.find("rad-global"), std::string::npos) << run.result.out;
  EXPECT_FALSE(fs::exists(dir / "out" / "global.rlh"));
  EXPECT_FALSE(fs::exists(dir / "out" / "scene.params"));
  EXPECT_LT(run.seconds, 20.0);
  fs::remove_all(dir);
}

TEST_F(Preflight, SceneWithoutEmitterFailsBeforeTheFirstStageNamingBothProblems) {
  const fs::path dir = freshDir("preflight_emitter");
  const std::string scene =
      writeScene(dir, "dark.gltf", withoutEmission(withoutCamera(bundledScene())));
  const MakeRun run = runPipeline(dir / "out", scene);
  EXPECT_NE(run.result.exitCode, 0);
  // One line with both problems.
  EXPECT_NE(run.result.err.find("no camera: add a camera in Blender and tick \"Cameras\" in the "
                                "glTF export (Include > Data); nothing emits light: give a "
                                "surface an emissive material"),
            std::string::npos)
      << run.result.err;
  EXPECT_EQ(run.result.out.find("rad-global"), std::string::npos) << run.result.out;
  EXPECT_FALSE(fs::exists(dir / "out" / "global.rlh"));
  fs::remove_all(dir);
}

TEST_F(Preflight, CheckPassesTheBundledSceneAndCountsPunctualLightsAsEmitters) {
  CommandResult ok = runCommand(tool("rad-inspect") + " --preflight " + kScene);
  EXPECT_EQ(ok.exitCode, 0) << ok.err;
  EXPECT_EQ(ok.out, kScene + ": ok\n");
  // A lamp and no emissive surface: something emits (the stages that need light say themselves
  // whether they support lamps).
  const fs::path dir = freshDir("preflight_lamp");
  nlohmann::json g = withoutEmission(bundledScene());
  g["extensionsUsed"] = {"KHR_lights_punctual"};
  g["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}, {"intensity", 100}}};
  g["nodes"][5]["extensions"]["KHR_lights_punctual"]["light"] = 0;
  const std::string lamp = writeScene(dir, "lamp.gltf", g);
  CommandResult r = runCommand(tool("rad-inspect") + " --preflight " + lamp);
  EXPECT_EQ(r.exitCode, 0) << r.err;
  CommandResult dark = runCommand(tool("rad-inspect") + " --preflight " +
                                  writeScene(dir, "dark.gltf", withoutEmission(bundledScene())));
  EXPECT_EQ(dark.exitCode, 1);
  EXPECT_EQ(countLines(dark.err), 1) << dark.err;
  EXPECT_NE(dark.err.find(": nothing emits light: "), std::string::npos) << dark.err;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rad::test
