// Time per composed frame (docs/design.md §8: <= 0.2 s at 352x240, ~400 polygons): the pipeline's
// Cornell scene, every top-level patch split twice in the global solution, and one 16x16
// texture movie per level-1 node (or none: every pixel falls back).
// Usage: compose_bench [SCENE.gltf] [FRAMES]
#include <chrono>
#include <cstdio>
#include <string>

#include "formats/gltf_scene.h"
#include "libcommon/compose/frame_composer.h"

int main(int argc, char** argv) {
  using namespace rad;
  std::string path =
      argc > 1 ? argv[1] : std::string(RAD_SOURCE_DIR) + "/pipelines/scenes/cornell-moving.gltf";
  int frames = argc > 2 ? std::atoi(argv[2]) : 24;
  Scene scene = readGltfScene(path);
  GlobalSolution g;
  g.keyTimes = {0.0, 1.0};
  g.hierarchy = PatchHierarchy(scene.inputPolygons());
  const int tops = g.hierarchy.topCount();
  for (int t = 0; t < tops; ++t) {
    int first = g.hierarchy.subdivide(t);
    for (int k = 0; k < 4; ++k) g.hierarchy.subdivide(first + k);
  }
  int leaves = 0;
  for (int i = 0; i < g.hierarchy.size(); ++i) {
    g.leafRow.push_back(g.hierarchy.isLeaf(i) ? leaves++ : -1);
    for (int k = 0; k < 2; ++k) g.nodeRadiosity.push_back(glm::vec3(0.1f * (i % 7) + 0.2f));
  }
  g.leafVertexGoodIrradiance.assign(size_t(leaves) * 2 * 4, glm::vec3(0.0f));

  std::vector<float> texture(16 * 16 * 3);
  for (size_t i = 0; i < texture.size(); ++i) texture[i] = float(i % 13);
  std::vector<MovieTexture> movies;
  for (int t = 0; t < tops; ++t)
    for (int k = 0; k < 4; ++k)
      movies.push_back({PatchId{uint32_t(t), 1}.child(k), 16, 16, texture.data()});

  FrameComposer composer(scene, g, ImageSize{352, 240}, scene.cameraNode(""));
  for (int withMovies = 0; withMovies < 2; ++withMovies) {
    ComposedFrame f;
    composer.compose(0.0, withMovies ? movies : std::vector<MovieTexture>{}, f);  // warm up
    auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < frames; ++i)
      composer.compose(i / 24.0, withMovies ? movies : std::vector<MovieTexture>{}, f);
    double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("%d top-level patches, %s: %.2f ms/frame (%lld covered, %lld fallback pixels)\n",
                tops, withMovies ? "movies on every patch" : "all fallback", 1e3 * s / frames,
                f.coveredPixels, f.fallbackPixels);
  }
  return 0;
}
