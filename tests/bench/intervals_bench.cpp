// rad-intervals figures on the bundled scene (DESIGN.md §8): item-buffer pass time per frame
// at 352x240, whole-frame time (render + counting + projected areas + events), and the
// movies it produces: count, mean length, texels per frame, per level and close reason.
//
// Usage: intervals_bench [SCENE.gltf] [FRAMES, default 0-95] [WxH, default 352x240]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <string>

#include "formats/gltf_scene.h"
#include "libcommon/texture_intervals_builder.h"
#include "libcommon/tool_main.h"

int main(int argc, char** argv) {
  std::string path =
      argc > 1 && *argv[1] ? argv[1] : RAD_SOURCE_DIR "/pipelines/scenes/cornell-moving.gltf";
  std::vector<int> frames = rad::parseFrameRange(argc > 2 ? argv[2] : "0-95");
  auto [w, h] = rad::parseImageSize(argc > 3 ? argv[3] : "352x240");
  return rad::runTool("intervals_bench", [&]() {
    rad::Scene scene = rad::readGltfScene(path);
    rad::TextureIntervalsOptions o;
    o.imageSize = {w, h};
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
