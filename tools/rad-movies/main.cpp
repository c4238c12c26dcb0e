// rad-movies: bakes the texture movies of intervals.rti from the global solution (paper §3.1
// transmittance textures, §5 frame-to-frame coherence; DESIGN.md §6 "rad-movies"). One
// multi-part OpenEXR per movie (formats/texture_movie.md), streamed key by key as the baker
// produces the keys (TextureMovieWriter) and committed atomically when the movie is done, so
// peak memory is one key's working buffers whatever the animation's length.
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>

#include "formats/atomic_file.h"
#include "formats/gltf_scene.h"
#include "formats/link_hierarchy.h"
#include "formats/provenance.h"
#include "formats/texture_intervals.h"
#include "formats/texture_movie.h"
#include "libcommon/movies/texture_movie_baker.h"
#include "tools/common/tool_main.h"

namespace {

constexpr const char* kTool = "rad-movies";

struct Options {
  std::string scene, global, intervals, outDir;
  int keyStep = 6;
  int minSamples = 4;
  int maxSamples = 64;
  double samplesPerFormFactor = 256.0;
  std::string merge = "exact";
  bool noCoherence = false;
  std::string shard = "0/1";
  double maxTextureMemory = 1024.0;  // MiB
  std::string report;
};

std::pair<int, int> parseShard(const std::string& s) {
  int i = -1, n = -1;
  char slash = 0, extra = 0;
  if (std::sscanf(s.c_str(), "%d%c%d%c", &i, &slash, &n, &extra) != 3 || slash != '/' || n < 1 ||
      i < 0 || i >= n)
    throw rad::Error(rad::ExitCode::kUsage, "--shard",
                     "'" + s + "'; expected i/n with 0 <= i < n, e.g. 0/4");
  return {i, n};
}

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

int run(const Options& o, int argc, char** argv) {
  auto start = Clock::now();
  const auto [shardIndex, shardCount] = parseShard(o.shard);
  rad::TextureMovieBakerOptions bo;
  bo.keyStep = o.keyStep;
  bo.minSamples = o.minSamples;
  bo.maxSamples = o.maxSamples;
  bo.samplesPerFormFactor = o.samplesPerFormFactor;
  bo.merge = rad::parseMergeMode(o.merge);
  bo.coherence = !o.noCoherence;
  bo.maxTextureMemoryMiB = o.maxTextureMemory;

  rad::Scene scene = rad::readGltfScene(o.scene);
  rad::GlobalSolution solution = rad::readLinkHierarchy(o.global, scene);
  rad::TextureIntervals intervals = rad::readTextureIntervals(o.intervals);
  const double secondsRead = since(start);

  nlohmann::json parameters = bo.toJson();
  parameters["shard"] = o.shard;
  parameters["output"] = o.outDir;
  rad::Provenance provenance = rad::makeProvenance(kTool, argc, argv, parameters);
  rad::addInput(provenance, o.scene);
  rad::addInput(provenance, o.global);
  rad::addInput(provenance, o.intervals);
  const std::string provenanceJson = provenance.toJson().dump();

  std::error_code ec;
  std::filesystem::create_directories(o.outDir, ec);
  if (ec || !std::filesystem::is_directory(o.outDir))
    throw rad::outputError(
        o.outDir, "cannot create the movie directory" + (ec ? ": " + ec.message() : std::string()));

  rad::TextureMovieBaker baker(scene, solution, intervals.fps, bo);
  std::vector<const rad::TextureInterval*> mine;
  for (const rad::TextureInterval& m : intervals.movies)
    if (int(m.movie % uint32_t(shardCount)) == shardIndex) mine.push_back(&m);

  // Streams each baked key into the movie's file (constant movies collapse to one key when
  // coherence is on, as the baker's in-memory bake does).
  struct MovieFileSink : rad::BakedKeySink {
    rad::TextureMovie meta;
    std::string path;
    bool collapse = false;
    double secondsWrite = 0.0;
    std::unique_ptr<rad::TextureMovieWriter> writer;
    void begin(const rad::BakedMovie& plan) override {
      auto t = Clock::now();
      meta.keyFrames = plan.keyFrames;
      meta.keyTimes = plan.keyTimes;
      writer = std::make_unique<rad::TextureMovieWriter>(path, meta, collapse,
                                                         rad::AtomicFile::Durability::kDeferred);
      secondsWrite += since(t);
    }
    void key(size_t k, const std::vector<float>& texture) override {
      auto t = Clock::now();
      writer->writeKey(k, texture);
      secondsWrite += since(t);
    }
    size_t finish() override {
      auto t = Clock::now();
      size_t stored = writer->commit();
      writer.reset();
      secondsWrite += since(t);
      return stored;
    }
  } sink;
  sink.collapse = bo.coherence;

  rad::Progress progress("rad-movies", long(mine.size()));
  for (const rad::TextureInterval* m : mine) {
    rad::MovieRequest r;
    r.movie = m->movie;
    r.patch = m->patch;
    r.firstFrame = m->firstFrame;
    r.lastFrame = m->lastFrame;
    r.width = m->width;
    r.height = m->height;
    sink.meta = rad::TextureMovie();
    sink.meta.movie = m->movie;
    sink.meta.patch = m->patch;
    sink.meta.firstFrame = m->firstFrame;
    sink.meta.lastFrame = m->lastFrame;
    sink.meta.width = m->width;
    sink.meta.height = m->height;
    sink.meta.provenanceJson = provenanceJson;
    sink.path = rad::textureMoviePath(o.outDir, m->movie);
    try {
      baker.bake(r, sink);
    } catch (const rad::Error& e) {
      sink.writer.reset();  // the half-written movie is discarded
      // Name the file the bad movie came from.
      if (e.code() == rad::ExitCode::kBadInput) throw rad::inputError(o.intervals, e.what());
      throw;
    }
    progress.advance();
  }
  progress.done();
  {
    // One sync for all movies (AtomicFile::Durability::kDeferred) before the tool reports
    // success: Make's movies/.done stamp follows our exit status.
    auto t = Clock::now();
    rad::syncFileSystemOf(o.outDir);
    sink.secondsWrite += since(t);
  }
  const rad::TextureMovieBakerStats& stats = baker.stats();
  for (const std::string& w : stats.warnings) std::cerr << kTool << ": warning: " << w << "\n";

  if (!o.report.empty()) {
    nlohmann::json report = stats.toJson();
    report["tool"] = kTool;
    report["shard"] = o.shard;
    report["movies_in_file"] = intervals.movies.size();
    report["parameters"] = parameters;
    report["renderer"] = baker.rendererName();
    report["seconds"]["read"] = secondsRead;
    report["seconds"]["write"] = sink.secondsWrite;
    report["seconds"]["total"] = since(start);
    report["peak_memory_mb"] = rad::peakMemoryMb();
    rad::writeTextFile(o.report, report.dump(1) + "\n");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Bakes the texture movies of intervals.rti: per key frame the good-link irradiance of the "
      "global solution plus every bad link's shooter radiosity x form factor x transmittance "
      "(projective shadows with OSMesa; static blockers rendered once per movie)."};
  Options o;
  rad::setUpApp(app, kTool,
                "rad-movies scene.gltf out/global.rlh out/intervals.rti -o out/movies "
                "--key-step 6 --report out/movies.json");
  app.add_option("SCENE", o.scene, "glTF 2.0 scene (.gltf/.glb)")->required();
  app.add_option("GLOBAL", o.global, "global solution (global.rlh from rad-global)")->required();
  app.add_option("INTERVALS", o.intervals, "texture-movie intervals (intervals.rti)")->required();
  app.add_option("-o,--output", o.outDir, "directory for the movies (NNNNNN.exr)")->required();
  app.add_option("--key-step", o.keyStep, "frames between key textures")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--min-samples", o.minSamples, "shooter samples per bad link, at least")
      ->capture_default_str();
  app.add_option("--max-samples", o.maxSamples, "shooter samples per bad link, at most (<= 64)")
      ->capture_default_str();
  app.add_option("--samples-per-form-factor", o.samplesPerFormFactor,
                 "samples = this x the largest texel-to-shooter form factor (paper §3.1)")
      ->capture_default_str();
  app.add_option("--merge", o.merge,
                 "static/dynamic occlusion merge: exact (bit masks ORed), or the approximate "
                 "max, sum, independent")
      ->capture_default_str();
  app.add_flag("--no-coherence", o.noCoherence,
               "re-render every blocker and recompute every form factor at every key, store every "
               "key (the per-frame baseline)");
  app.add_option("--shard", o.shard, "bake only movies with id % n == i")->capture_default_str();
  app.add_option("--max-texture-memory", o.maxTextureMemory,
                 "MiB of working memory per movie: one key's texel buffers plus, per bad shooter "
                 "of a static pair, its form factors and static-blocker masks (independent of "
                 "the number of keys); a movie that needs more is refused (exit 4)")
      ->capture_default_str();
  app.add_option("--report", o.report, "write timings and counts as JSON to this file");
  if (int rc = rad::parseCommandLine(app, kTool, argc, argv); rc >= 0) return rc;
  return rad::runTool(kTool, [&]() { return run(o, argc, argv); });
}
