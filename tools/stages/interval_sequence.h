// rad-intervals' frame loop (paper §4.1, §4.3; docs/design.md §6.2 rad-intervals), next to
// frame_sequence (rad-compose's): every frame through one TextureIntervalsBuilder
// (libcommon/intervals/texture_intervals_builder.h), optionally writing each frame's item
// buffer as DIR/NNNN.exr, then the extents as the intervals.rti record.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/texture_intervals.h"
#include "formats/visible_samples.h"
#include "libcommon/intervals/texture_intervals_builder.h"
#include "libcommon/scene/scene.h"

namespace rad {

struct IntervalSequence {
  TextureIntervals intervals;  // what intervals.rti stores: the window, fps, size, movies
  nlohmann::json metadata;     // its metadata: top_patches, patch_nodes, max_level, camera,
                               // frame_step
  // For the report.
  int frames = 0;  // frames added
  // Frames whose item buffer shows no surface (the camera's clip planes or view miss the whole
  // scene): their final frames would be black, which the tool warns about.
  std::vector<int> emptyFrames;
  int topPatches = 0;
  long patchNodes = 0;  // of the full subdivision to --max-level, which the item buffers draw
  // The tops some frame showed, and the nodes made for them (seen_subdivision.h): the others
  // have no visible sample, so no movie and no level to choose.
  int topPatchesSeen = 0;
  long patchNodesMade = 0;
  double itemBufferSeconds = 0.0;   // total render + readback
  long continuedOverGaps = 0;       // hidden gaps a movie was kept over (--hidden-gap)
  std::vector<double> itemSeconds;  // per frame, in frame order
  double setupSeconds = 0.0;        // builder set-up (GL context, hierarchy)
  double totalSeconds = 0.0;        // set-up and every frame
};

// Runs `frames` (strictly increasing) from camera node `cameraNode`. With a non-empty
// `itemBuffersDir` (created; rad::outputError if it cannot be) each frame's item buffer is
// written there as NNNN.exr carrying `provenanceJson`. `frameDone` is called after each frame.
IntervalSequence computeIntervalSequence(const Scene& scene, int cameraNode,
                                         const std::vector<int>& frames,
                                         const TextureIntervalsOptions& options,
                                         const std::string& itemBuffersDir,
                                         const std::string& provenanceJson,
                                         const std::function<void()>& frameDone = {});

// The same from visible samples counted elsewhere (rad-intervals --merge of --window files):
// counted[i] is frames[i]'s; no item buffer is drawn. The same intervals as the run above.
IntervalSequence computeIntervalSequence(const Scene& scene, int cameraNode,
                                         const std::vector<int>& frames,
                                         const TextureIntervalsOptions& options,
                                         const std::vector<VisibleSamplesFrame>& counted,
                                         const std::function<void()>& frameDone = {});

// rad-intervals --window: the visible samples of each of `frames`, from item buffers drawn as
// the run above draws them; `parameters` (the run's provenance parameters) go into the record.
VisibleSamples computeVisibleSamples(const Scene& scene, int cameraNode,
                                     const std::vector<int>& frames,
                                     const TextureIntervalsOptions& options,
                                     const nlohmann::json& parameters,
                                     const std::function<void()>& frameDone = {});

// rad-intervals' --report: summarizeTextureIntervals of the file written at `output` (read
// back, which also checks it) plus the run's counts (empty_frames: how many frames show no
// surface) and times.
nlohmann::json intervalSequenceReport(const IntervalSequence& run, const std::string& output);

}  // namespace rad
