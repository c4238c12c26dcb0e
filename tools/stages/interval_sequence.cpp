#include "tools/stages/interval_sequence.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include <tbb/global_control.h>

#include "formats/container.h"
#include "formats/item_buffer_exr.h"
#include "libcommon/core/error.h"
#include "libcommon/core/stopwatch.h"

namespace rad {

namespace {

TextureIntervals intervalsRecord(const std::vector<MovieExtent>& extents,
                                 const std::vector<int>& frames,
                                 const TextureIntervalsOptions& options) {
  TextureIntervals iv;
  iv.firstFrame = frames.front();
  iv.lastFrame = frames.back();
  iv.fps = options.fps;
  iv.imageWidth = options.imageSize.width;
  iv.imageHeight = options.imageSize.height;
  iv.sampling = options.sampling;
  iv.movies = extents;  // one record (MovieExtent): finish() numbers them 0..n-1
  return iv;
}

// Whether any pixel centre of `samples` (a buffer of `grid`) shows a surface: pixelCentreSamples'
// ids not all kNoItem, without making that buffer every frame.
bool showsSurfaceAtPixelCentres(const ItemBuffer& samples, const SampleGrid& grid) {
  for (int row = 0; row < grid.image.height; ++row) {
    const uint32_t* line = samples.id.data() + size_t(grid.centre(row)) * samples.width;
    for (int col = 0; col < grid.image.width; ++col)
      if (line[grid.centre(col)] != kNoItem) return true;
  }
  return false;
}

// Item buffers drawn by one GL context a thread (TextureIntervalsBuilder::addFrames).
size_t renderersForThisProcess() {
  return std::clamp<size_t>(
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism), 1, 4);
}

void finishSequence(IntervalSequence& run, TextureIntervalsBuilder& builder, const Scene& scene,
                    int cameraNode, const std::vector<int>& frames,
                    const TextureIntervalsOptions& options,
                    std::chrono::steady_clock::time_point start);

}  // namespace

IntervalSequence computeIntervalSequence(const Scene& scene, int cameraNode,
                                         const std::vector<int>& frames,
                                         const TextureIntervalsOptions& options,
                                         const std::string& itemBuffersDir,
                                         const std::string& provenanceJson,
                                         const std::function<void()>& frameDone) {
  if (!itemBuffersDir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(itemBuffersDir, ec);
    if (ec) throw outputError(itemBuffersDir, ec.message());
  }

  IntervalSequence run;
  const auto start = std::chrono::steady_clock::now();
  TextureIntervalsOptions built = options;
  built.itemBufferDepth = !itemBuffersDir.empty();  // depth only for the files
  TextureIntervalsBuilder builder(scene, cameraNode, built);
  const SampleGrid grid = options.sampling.grid(options.imageSize);
  run.setupSeconds = secondsSince(start);
  builder.addFrames(
      frames, renderersForThisProcess(),
      [&](const IntervalFrame& fr) {
        run.itemSeconds.push_back(fr.itemBufferSeconds);
        // The pixel centres: what the frame shows (the grid's margin lies outside it).
        if (!showsSurfaceAtPixelCentres(*fr.itemBuffer, grid)) run.emptyFrames.push_back(fr.frame);
        if (itemBuffersDir.empty()) return;
        // The pixel-sized buffer rad-diff --surfaces reads.
        const ItemBuffer centres = pixelCentreSamples(*fr.itemBuffer, grid);
        char name[32];
        std::snprintf(name, sizeof name, "/%04d.exr", fr.frame);
        writeItemBufferExr(itemBuffersDir + name, centres, fr.frame, fr.time, provenanceJson);
      },
      frameDone);
  finishSequence(run, builder, scene, cameraNode, frames, options, start);
  return run;
}

IntervalSequence computeIntervalSequence(const Scene& scene, int cameraNode,
                                         const std::vector<int>& frames,
                                         const TextureIntervalsOptions& options,
                                         const std::vector<VisibleSamplesFrame>& counted,
                                         const std::function<void()>& frameDone) {
  if (counted.size() != frames.size())
    throw Error(ExitCode::kInternal, "", "visible samples: not one record a frame");
  IntervalSequence run;
  const auto start = std::chrono::steady_clock::now();
  TextureIntervalsOptions built = options;
  built.itemBufferDepth = false;
  TextureIntervalsBuilder builder(scene, cameraNode, built);
  run.setupSeconds = secondsSince(start);
  for (size_t i = 0; i < frames.size(); ++i) {
    const VisibleSamplesFrame& c = counted[i];
    if (c.frame != frames[i])
      throw Error(ExitCode::kInternal, "", "visible samples: frames out of order");
    builder.addVisibleSamples(c.frame, c.leaf, c.count, c.itemBufferSeconds);
    run.itemSeconds.push_back(c.itemBufferSeconds);
    if (c.empty) run.emptyFrames.push_back(c.frame);
    if (frameDone) frameDone();
  }
  finishSequence(run, builder, scene, cameraNode, frames, options, start);
  return run;
}

VisibleSamples computeVisibleSamples(const Scene& scene, int cameraNode,
                                     const std::vector<int>& frames,
                                     const TextureIntervalsOptions& options,
                                     const nlohmann::json& parameters,
                                     const std::function<void()>& frameDone) {
  VisibleSamples out;
  out.parameters = parameters;
  TextureIntervalsOptions built = options;
  built.itemBufferDepth = false;
  TextureIntervalsBuilder builder(scene, cameraNode, built);
  const SampleGrid grid = options.sampling.grid(options.imageSize);
  const PatchHierarchy& ph = builder.hierarchy();
  const int maxLevel = options.maxLevel;
  builder.addFrames(
      frames, renderersForThisProcess(),
      [&](const IntervalFrame& fr) {
        VisibleSamplesFrame f;
        f.frame = fr.frame;
        f.empty = !showsSurfaceAtPixelCentres(*fr.itemBuffer, grid);
        f.itemBufferSeconds = fr.itemBufferSeconds;
        // The leaves of the full subdivision by number (the tops made are a builder's own).
        const std::vector<long>& visible = *fr.visiblePixels;
        std::vector<std::pair<uint32_t, uint32_t>> leaves;
        for (int i = 0; i < ph.size(); ++i)
          if (visible[i] > 0 && ph.node(i).id.level() == maxLevel)
            leaves.push_back({uint32_t(builder.numberOf(i)), uint32_t(visible[i])});
        std::sort(leaves.begin(), leaves.end());
        for (const auto& [leaf, count] : leaves) {
          f.leaf.push_back(leaf);
          f.count.push_back(count);
        }
        out.frames.push_back(std::move(f));
      },
      frameDone);
  return out;
}

namespace {

void finishSequence(IntervalSequence& run, TextureIntervalsBuilder& builder, const Scene& scene,
                    int cameraNode, const std::vector<int>& frames,
                    const TextureIntervalsOptions& options,
                    std::chrono::steady_clock::time_point start) {
  const std::vector<MovieExtent> extents = builder.finish();
  run.totalSeconds = secondsSince(start);

  run.intervals = intervalsRecord(extents, frames, options);
  const PatchHierarchy& ph = builder.hierarchy();
  run.metadata = {{"top_patches", ph.topCount()},
                  {"patch_nodes", long(builder.fullNodeCount())},
                  {"max_level", options.maxLevel},
                  {"camera", scene.nodes[cameraNode].name},
                  {"frame_step", frames.size() > 1 ? frames[1] - frames[0] : 1}};
  run.frames = builder.framesAdded();
  run.topPatches = ph.topCount();
  run.patchNodes = long(builder.fullNodeCount());
  run.topPatchesSeen = builder.topsSeen();
  run.patchNodesMade = ph.size();
  run.itemBufferSeconds = builder.itemBufferSeconds();
  run.continuedOverGaps = builder.moviesContinuedOverGaps();
}

}  // namespace

nlohmann::json intervalSequenceReport(const IntervalSequence& run, const std::string& output) {
  nlohmann::json report = summarizeTextureIntervals(ContainerReader::open(output));
  const int n = run.frames;
  report["output"] = output;
  report["frames"] = n;
  report["empty_frames"] = run.emptyFrames.size();
  report["image_size"] = {run.intervals.imageWidth, run.intervals.imageHeight};
  report["top_patches"] = run.topPatches;
  report["patch_nodes"] = run.patchNodes;
  report["top_patches_seen"] = run.topPatchesSeen;
  report["patch_nodes_made"] = run.patchNodesMade;
  report["hidden_gaps_continued"] = run.continuedOverGaps;
  report["item_buffer_ms_per_frame"] = 1e3 * run.itemBufferSeconds / n;
  // The first frame pays for shader compilation and driver warm-up: the median is the figure.
  std::vector<double> itemSeconds = run.itemSeconds;
  std::sort(itemSeconds.begin(), itemSeconds.end());
  report["item_buffer_ms_median"] = 1e3 * itemSeconds[itemSeconds.size() / 2];
  report["item_buffer_ms_max"] = 1e3 * itemSeconds.back();
  report["setup_seconds"] = run.setupSeconds;
  report["total_seconds"] = run.totalSeconds;
  report["ms_per_frame"] = 1e3 * (run.totalSeconds - run.setupSeconds) / n;
  return report;
}

}  // namespace rad
