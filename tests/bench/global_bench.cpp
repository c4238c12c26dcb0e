// rad-global's accuracy knob and coherence, measured (issue 3 item 10; docs/design.md §8): on a
// scene (default: the bundled moving Cornell box, 96 frames, a key every 4), for --eps over a
// decade and a half (1e-2 .. 1e-4, the last the "finest" reference), the time, the link count
// and the error of every top-level patch's radiosity at every key against the finest setting;
// then, at the default eps, the links reused per key time and the coherent vs --no-coherence
// time ratio (the two solutions are bit-identical; checked here too).
//
//   global_bench [scene.gltf] [frames = 96] [key step = 4]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "formats/gltf_scene.h"
#include "libcommon/radiosity/space_time_radiosity.h"

using namespace rad;

namespace {

double seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Area-weighted relative L2 of the top-level patches' radiosity over all keys (green channel).
double relativeError(const GlobalSolution& a, const GlobalSolution& ref) {
  double num = 0, den = 0;
  for (int t = 0; t < ref.hierarchy.topCount(); ++t) {
    double area = ref.hierarchy.node(t).local.area();
    for (int k = 0; k < ref.keyCount(); ++k) {
      double x = a.radiosityAtKey(t, k).y, y = ref.radiosityAtKey(t, k).y;
      num += area * (x - y) * (x - y);
      den += area * y * y;
    }
  }
  return den > 0 ? std::sqrt(num / den) : 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string path =
      argc > 1 ? argv[1] : std::string(RAD_SOURCE_DIR) + "/pipelines/scenes/cornell-moving.gltf";
  int frames = argc > 2 ? std::atoi(argv[2]) : 96;
  int step = argc > 3 ? std::atoi(argv[3]) : 4;
  Scene scene = readGltfScene(path);
  std::vector<double> keys;
  for (int f = 0; f < frames - 1; f += step) keys.push_back(f / 24.0);
  keys.push_back((frames - 1) / 24.0);
  double largest = 0;
  for (const InputPolygon& p : scene.inputPolygons()) {
    glm::dmat4 m = p.node >= 0 ? scene.worldTransform(p.node, 0.0) : glm::dmat4(1.0);
    largest = std::max(largest, p.local.transformed(m).area());
  }
  SpaceTimeOptions base;
  base.radiosity.minArea = 1e-4 * largest;  // rad-global's default
  std::printf("global_bench: %s, %d frames, %zu key times\n", path.c_str(), frames, keys.size());

  // eps sweep, coherent; the finest is the reference.
  const double epsValues[] = {1e-2, 3e-3, 1e-3, 3e-4, 1e-4};
  std::vector<GlobalSolution> solutions;
  std::vector<double> times;
  std::vector<size_t> links;
  for (double eps : epsValues) {
    SpaceTimeOptions o = base;
    o.radiosity.eps = eps;
    SpaceTimeReport rep;
    auto t0 = std::chrono::steady_clock::now();
    solutions.push_back(solveSpaceTime(scene, keys, o, &rep));
    times.push_back(seconds(t0));
    size_t n = 0;
    for (const KeyTimeReport& k : rep.keys) n += k.links;
    links.push_back(n / rep.keys.size());
  }
  std::printf("\n  %-8s %9s %12s %20s\n", "eps", "seconds", "links/key", "error vs eps 1e-4");
  for (size_t i = 0; i < solutions.size(); ++i)
    std::printf("  %-8.0e %9.2f %12zu %19.3f%%\n", epsValues[i], times[i], links[i],
                100.0 * relativeError(solutions[i], solutions.back()));

  // Coherence at the default eps.
  SpaceTimeOptions o = base;
  SpaceTimeReport coherentReport, scratchReport;
  auto t0 = std::chrono::steady_clock::now();
  GlobalSolution coherent = solveSpaceTime(scene, keys, o, &coherentReport);
  double tc = seconds(t0);
  o.coherence = false;
  t0 = std::chrono::steady_clock::now();
  GlobalSolution scratch = solveSpaceTime(scene, keys, o, &scratchReport);
  double ts = seconds(t0);
  std::printf("\n  key  links  reused  visibility-only  recomputed  reused %%\n");
  size_t reused = 0, total = 0;
  for (size_t k = 0; k < coherentReport.keys.size(); ++k) {
    const KeyTimeReport& r = coherentReport.keys[k];
    reused += r.reused;
    total += r.links;
    std::printf("  %3zu %6zu %7zu %16zu %11zu %8.1f\n", k, r.links, r.reused, r.visibilityOnly,
                r.recomputed, 100.0 * double(r.reused) / double(std::max<size_t>(1, r.links)));
  }
  bool identical = coherent.nodeRadiosity == scratch.nodeRadiosity &&
                   coherent.linkSampleValues == scratch.linkSampleValues;
  std::printf(
      "\n  reused %.1f %% of all link evaluations; coherent %.2f s, --no-coherence %.2f s: "
      "%.2fx; solutions %s\n",
      100.0 * double(reused) / double(std::max<size_t>(1, total)), tc, ts, ts / tc,
      identical ? "bit-identical" : "DIFFER");
  return identical ? 0 : 1;
}
