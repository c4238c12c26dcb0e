// rad-intervals figures on the bundled scene (docs/design.md §8): item-buffer pass time per frame
// at 352x240, whole-frame time (render + counting + projected areas + events), and the
// movies it produces: count, mean length, texels per frame, per level and close reason.
//
// Usage: intervals_bench [SCENE.gltf | synthetic:N] [FRAMES, default 0-95] [WxH, default 352x240]
//                        [LEVEL_HYSTERESIS, default 0]
// synthetic:N builds N unit cubes (6 faces each, every third one moving) on a 2-D grid over a
// floor, seen by a camera that pans and dollies: N = 66 gives the ~400 polygons of docs/design.md
// §8.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "formats/gltf_scene.h"
#include "libcommon/intervals/texture_intervals_builder.h"
#include "tools/common/tool_main.h"

namespace {

// A cube of side 1 centred at the origin, faces outwards (CCW seen from outside).
rad::Mesh cubeMesh() {
  rad::Mesh m;
  m.name = "cube";
  for (int axis = 0; axis < 3; ++axis)
    for (int sign : {-1, 1}) {
      glm::dvec3 n(0.0), u(0.0), v(0.0);
      n[axis] = 0.5 * sign;
      u[(axis + 1) % 3] = 0.5;
      v[(axis + 2) % 3] = 0.5;
      if (sign < 0) std::swap(u, v);
      glm::dvec3 a = n - u - v, b = n + u - v, c = n + u + v, d = n - u + v;
      rad::MeshTriangle t1, t2;
      t1.p = {a, b, c};
      t2.p = {a, c, d};
      t1.material = t2.material = 0;
      m.triangles.push_back(t1);
      m.triangles.push_back(t2);
    }
  return m;
}

rad::AnimationChannel translation(int node, glm::dvec3 a, glm::dvec3 b, double t1) {
  rad::AnimationChannel ch;
  ch.node = node;
  ch.path = rad::AnimationPath::kTranslation;
  ch.times = {0.0, t1};
  ch.values = {a.x, a.y, a.z, b.x, b.y, b.z};
  return ch;
}

rad::Scene syntheticScene(int cubes) {
  rad::Scene s;
  s.path = "synthetic:" + std::to_string(cubes);
  s.materials.push_back(rad::Material{});
  s.meshes.push_back(cubeMesh());
  rad::Mesh floor;
  floor.name = "floor";
  rad::MeshTriangle f1, f2;
  f1.p = {glm::dvec3(-30, 0, 10), glm::dvec3(30, 0, 10), glm::dvec3(30, 0, -50)};
  f2.p = {glm::dvec3(-30, 0, 10), glm::dvec3(30, 0, -50), glm::dvec3(-30, 0, -50)};
  f1.material = f2.material = 0;
  floor.triangles = {f1, f2};
  s.meshes.push_back(floor);
  rad::Node fn;
  fn.name = "floor";
  fn.mesh = 1;
  s.nodes.push_back(fn);
  int side = int(std::ceil(std::sqrt(double(cubes))));
  for (int i = 0; i < cubes; ++i) {
    rad::Node n;
    n.name = "cube" + std::to_string(i);
    n.mesh = 0;
    n.translation = glm::dvec3(2.0 * (i % side) - side, 0.5, -3.0 - 2.0 * (i / side));
    s.nodes.push_back(n);
    if (i % 3 == 0)
      s.channels.push_back(translation(int(s.nodes.size()) - 1, n.translation,
                                       n.translation + glm::dvec3(3.0, 0.0, 0.0), 4.0));
  }
  rad::Camera lens;
  lens.name = "camera";
  s.cameras.push_back(lens);
  rad::Node cam;
  cam.name = "camera";
  cam.camera = 0;
  cam.rotation = glm::angleAxis(-0.35, glm::dvec3(1, 0, 0));
  s.nodes.push_back(cam);
  s.channels.push_back(
      translation(int(s.nodes.size()) - 1, glm::dvec3(-4, 5, 6), glm::dvec3(4, 3, 0), 4.0));
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  std::string path =
      argc > 1 && *argv[1] ? argv[1] : RAD_SOURCE_DIR "/pipelines/scenes/cornell-moving.gltf";
  std::vector<int> frames = rad::parseFrameRange(argc > 2 ? argv[2] : "0-95");
  auto [w, h] = rad::parseImageSize(argc > 3 ? argv[3] : "352x240");
  return rad::runTool("intervals_bench", [&]() {
    rad::Scene scene = path.rfind("synthetic:", 0) == 0 ? syntheticScene(std::stoi(path.substr(10)))
                                                        : rad::readGltfScene(path);
    rad::TextureIntervalsOptions o;
    o.imageSize = {w, h};
    if (argc > 4) o.levelHysteresis = std::stod(argv[4]);
    auto t0 = std::chrono::steady_clock::now();
    rad::TextureIntervalsBuilder b(scene, scene.cameraNode(""), o);
    auto t1 = std::chrono::steady_clock::now();
    std::vector<double> item;
    for (int f : frames)
      b.addFrame(f, [&](const rad::IntervalFrame& fr) { item.push_back(fr.itemBufferSeconds); });
    std::vector<rad::MovieExtent> movies = b.finish();
    auto t2 = std::chrono::steady_clock::now();
    std::sort(item.begin(), item.end());
    double sum = 0;
    for (double s : item) sum += s;
    double frameLength = 0, texels = 0;
    std::map<int, int> levels, reasons;
    for (const rad::MovieExtent& m : movies) {
      int n = m.lastFrame - m.firstFrame + 1;
      frameLength += n;
      texels += double(m.width) * m.height * n;
      levels[m.patch.level()]++;
      reasons[int(m.end)]++;
    }
    int window = frames.back() - frames.front() + 1;
    std::printf("scene %s: %d top patches, %d nodes, %zu frames at %dx%d\n", path.c_str(),
                b.hierarchy().topCount(), b.hierarchy().size(), frames.size(), w, h);
    std::printf("setup (hierarchy, GL context, upload): %.1f ms\n",
                1e3 * std::chrono::duration<double>(t1 - t0).count());
    std::printf("item buffer pass: mean %.3f ms/frame, median %.3f, max %.3f\n",
                1e3 * sum / item.size(), 1e3 * item[item.size() / 2], 1e3 * item.back());
    std::printf("whole frame (render, counts, areas, events): %.3f ms/frame\n",
                1e3 * std::chrono::duration<double>(t2 - t1).count() / frames.size());
    std::printf("movies %zu, mean length %.2f frames, texels per frame %.0f (%.2f x pixels)\n",
                movies.size(), movies.empty() ? 0.0 : frameLength / movies.size(), texels / window,
                texels / window / (double(w) * h));
    std::printf("movies per level:");
    for (auto [l, c] : levels) std::printf(" %d:%d", l, c);
    std::printf(
        "\nclose reasons (0 left_frustum 1 hidden 2 level_change 3 resize 4 max_length "
        "5 window):");
    for (auto [r, c] : reasons) std::printf(" %d:%d", r, c);
    std::printf("\n");
    return 0;
  });
}
