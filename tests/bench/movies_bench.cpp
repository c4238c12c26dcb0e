// Coherent vs per-key texture-movie baking (docs/design.md §8 "speed-up of coherent over
// from-scratch"): a tiled floor under an area light, static boxes ("chairs") and M cubes
// moving across the room. Prints the time of both, the render passes and the max relative
// texel difference between them (exact merge: expected 0).
//
//   movies_bench [moving cubes = 1] [frames = 96] [tiles per side = 6] [texels = 32]
//                [baseline key step = 6]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "formats/form_factor_scratch_file.h"
#include "libcommon/movies/texture_movie_baker.h"

using namespace rad;

namespace {

void addQuad(Mesh& m, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d, int material) {
  MeshTriangle t1, t2;
  t1.p = {a, b, c};
  t2.p = {a, c, d};
  t1.material = t2.material = material;
  m.triangles.push_back(t1);
  m.triangles.push_back(t2);
}

int addNode(Scene& s, Mesh m) {
  s.meshes.push_back(std::move(m));
  Node n;
  n.mesh = int(s.meshes.size()) - 1;
  s.nodes.push_back(n);
  return int(s.nodes.size()) - 1;
}

// Axis-aligned box centred at the origin of its node, outward faces CCW.
Mesh box(glm::dvec3 h) {
  Mesh m;
  glm::dvec3 p[8];
  for (int i = 0; i < 8; ++i)
    p[i] = {(i & 1) ? h.x : -h.x, (i & 2) ? h.y : -h.y, (i & 4) ? h.z : -h.z};
  addQuad(m, p[0], p[2], p[3], p[1], 0);  // -z
  addQuad(m, p[4], p[5], p[7], p[6], 0);  // +z
  addQuad(m, p[0], p[1], p[5], p[4], 0);  // -y
  addQuad(m, p[2], p[6], p[7], p[3], 0);  // +y
  addQuad(m, p[0], p[4], p[6], p[2], 0);  // -x
  addQuad(m, p[1], p[3], p[7], p[5], 0);  // +x
  return m;
}

}  // namespace

// The bench's room: a tiled floor under one square lamp, four chairs and a table, and `moving`
// cubes crossing it over the run; floorNodes gets the floor tiles' nodes.
static Scene benchScene(int moving, int frames, int tiles, double fps,
                        std::vector<int>& floorNodes) {
  Scene s;
  Material white, lamp;
  white.reflectance = glm::dvec3(0.6);
  lamp.emission = glm::dvec3(5.0);
  s.materials = {white, lamp};
  const double room = 4.0, tile = room / tiles;
  for (int j = 0; j < tiles; ++j)
    for (int i = 0; i < tiles; ++i) {
      Mesh m;
      double x0 = -room / 2 + i * tile, y0 = -room / 2 + j * tile;
      addQuad(m, {x0, y0, 0}, {x0 + tile, y0, 0}, {x0 + tile, y0 + tile, 0}, {x0, y0 + tile, 0}, 0);
      floorNodes.push_back(addNode(s, m));
    }
  {
    Mesh m;
    addQuad(m, {-0.6, -0.6, 2.5}, {-0.6, 0.6, 2.5}, {0.6, 0.6, 2.5}, {0.6, -0.6, 2.5}, 1);
    addNode(s, m);
  }
  // Four static "chairs" (boxes on the floor) and a table.
  const glm::dvec3 chairs[5] = {
      {-1, -1, 0.3}, {1, -1, 0.3}, {-1, 1, 0.3}, {1, 1, 0.3}, {0, 0, 0.6}};
  for (int c = 0; c < 5; ++c) {
    int n = addNode(s, box(c == 4 ? glm::dvec3(0.5, 0.5, 0.05) : glm::dvec3(0.2, 0.2, 0.3)));
    s.nodes[size_t(n)].translation = chairs[c];
  }
  const double duration = (frames - 1) / fps;
  for (int k = 0; k < moving; ++k) {
    int n = addNode(s, box(glm::dvec3(0.12)));
    AnimationChannel ch;
    ch.node = n;
    ch.path = AnimationPath::kTranslation;
    ch.times = {0.0, std::max(duration, 1e-3)};
    double y = -1.6 + 3.2 * (k + 0.5) / moving, z = 0.9 + 0.3 * (k % 3);
    ch.values = {-2.2, y, z, 2.2, -y, z};
    s.channels.push_back(ch);
  }

  return s;
}

int main(int argc, char** argv) {
  const int moving = argc > 1 ? std::atoi(argv[1]) : 1;
  const int frames = argc > 2 ? std::atoi(argv[2]) : 96;
  const int tiles = argc > 3 ? std::atoi(argv[3]) : 6;
  const int texels = argc > 4 ? std::atoi(argv[4]) : 32;
  // The baseline's key step: 6 (same keys, every blocker per key) or 1 (every frame, the
  // paper's per-frame static method).
  const int baselineKeyStep = argc > 5 ? std::atoi(argv[5]) : 6;
  const double fps = 24.0;

  std::vector<int> floorNodes;
  const Scene s = benchScene(moving, frames, tiles, fps, floorNodes);

  GlobalSolution g;
  g.keyTimes = {0.0};
  g.hierarchy = PatchHierarchy(s.inputPolygons());
  const int n = g.hierarchy.topCount();
  int lightTop = -1;
  for (int i = 0; i < n; ++i) {
    bool emits = g.hierarchy.top(i).material == 1;
    if (emits) lightTop = i;
    g.nodeRadiosity.push_back(emits ? glm::vec3(15.7f) : glm::vec3(0.5f));
    g.leafRow.push_back(i);
    for (int c = 0; c < 4; ++c) g.leafVertexGoodIrradiance.push_back(glm::vec3(0.4f));
  }
  std::vector<MovieExtent> requests;
  for (int i = 0; i < n; ++i) {
    int node = g.hierarchy.top(i).node;
    if (std::find(floorNodes.begin(), floorNodes.end(), node) == floorNodes.end()) continue;
    g.badPairs.push_back({uint32_t(i), uint32_t(lightTop)});
    MovieExtent r;
    r.movie = uint32_t(requests.size());
    r.patch = PatchId{uint32_t(i), 1u};
    r.firstFrame = 0;
    r.lastFrame = frames - 1;
    r.width = r.height = texels;
    requests.push_back(r);
  }
  std::sort(g.badPairs.begin(), g.badPairs.end());
  g.validate("bench");

  std::printf("scene: %d top-level patches, %d moving cubes, %d movies of %dx%d, %d frames\n", n,
              moving, int(requests.size()), texels, texels, frames);
  double seconds[2] = {0, 0};
  std::vector<BakedMovie> out[2];
  TextureMovieBakerStats stats[2];
  for (int mode = 0; mode < 2; ++mode) {
    TextureMovieBakerOptions o;
    o.coherence = mode == 0;
    if (mode == 1) o.keyStep = baselineKeyStep;
    TextureMovieBakerBackends backends;
    backends.formFactorSpill = formFactorScratchFiles();  // as rad-movies bakes
    TextureMovieBaker baker(s, g, fps, o, backends);
    auto t = std::chrono::steady_clock::now();
    for (const MovieExtent& r : requests) out[mode].push_back(baker.bake(r));
    seconds[mode] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
    stats[mode] = baker.stats();
    std::printf(
        "%-12s %8.3f s  passes %6ld  sample-passes %8ld  saved %6ld  keys %5ld  "
        "constant %3ld  (ff %.3f s, transmittance %.3f s, good %.3f s)\n",
        mode == 0 ? "coherent" : "no-coherence", seconds[mode], stats[mode].passes,
        stats[mode].samplePasses, stats[mode].passesSavedByCoherence, stats[mode].keys,
        stats[mode].constantMovies, stats[mode].secondsFormFactor, stats[mode].secondsTransmittance,
        stats[mode].secondsGood);
  }
  // Max relative texel difference over every frame (linear between keys).
  double worst = 0.0;
  for (size_t m = 0; m < requests.size(); ++m)
    for (int f = 0; f < frames; ++f) {
      double t = f / fps;
      auto at = [&](const BakedMovie& b, size_t i) {
        if (b.keys.size() == 1) return double(b.keys[0][i]);
        size_t k1 = 1;
        while (k1 + 1 < b.keyTimes.size() && b.keyTimes[k1] < t) ++k1;
        double w =
            std::clamp((t - b.keyTimes[k1 - 1]) / (b.keyTimes[k1] - b.keyTimes[k1 - 1]), 0.0, 1.0);
        return (1 - w) * b.keys[k1 - 1][i] + w * b.keys[k1][i];
      };
      for (size_t i = 0; i < out[0][m].keys[0].size(); ++i) {
        double a = at(out[0][m], i), b = at(out[1][m], i);
        worst = std::max(worst, std::abs(a - b) / std::max(std::abs(b), 1e-30));
      }
    }
  std::printf("speed-up %.2f   max relative texel difference %.3g\n", seconds[1] / seconds[0],
              worst);
  return 0;
}
