// A test frame sequence against its references, frame by frame (docs/design.md §10): the error
// figures of each frame and pooled over the sequence, the temporal flicker, and, where an item
// buffer gives a frame's surfaces, the figures that need the geometry: edge and interior
// pixels (§10.3), the structured error (§10.4) and the seams (§10.5).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "libcommon/reference/frame_surfaces.h"
#include "libcommon/reference/image_difference.h"
#include "libcommon/reference/seam_steps.h"
#include "libcommon/reference/structured_error.h"
#include "libcommon/reference/temporal_error.h"

namespace rad {

struct FrameDifference {
  int frame = 0;
  DifferenceStats stats;  // test against the (first) reference, every sample
  ErrorFigures error;     // docs/design.md §10; regions filled when the frame has surfaces
  std::optional<StructuredError> structured;  // when the frame has surfaces
};

struct SequenceDifference {
  std::vector<FrameDifference> frames;  // in the order given
  DifferenceStats total;                // pooled over all frames
  ErrorFigures totalError;              // pooled sums over all frames
  FlickerStats flicker;                 // over pairs of consecutive frame numbers
  TemporalError temporal;               // over the same pairs (§10.6)
  SeamSteps seams;                      // pooled over the frames with surfaces, by patch pair
  bool haveSurfaces = false;            // some frame had surfaces
};

// One frame's images; reference2 empty (0x0) when there is no second reference, emitterMask
// empty when the rule decides which pixels are emitters.
struct FrameImages {
  FloatImage test, reference, reference2, emitterMask;
  PixelGroups groups;      // empty (count 0): no per-surface figures
  FrameSurfaces surfaces;  // empty: no edge, structured or seam figures
  // When set (and the frame has surfaces), receives the smoothed difference image of
  // measureStructuredError.
  std::function<void(const FloatImage& smoothed)> smoothedSink;
  // Names for messages (a file's path); empty: "frame N", "frame N: second reference",
  // "frame N: emitter mask".
  std::string testWhere, reference2Where, maskWhere;
};

// Compares a sequence frame by frame. `load(frame)` returns the images of one frame number
// (only two frames are held at a time, so memory is flat in sequence length). `frames` must
// be ascending; flicker and the temporal error use the pairs (n, n+1) that are both listed.
SequenceDifference compareSequence(const std::vector<int>& frames,
                                   const std::function<FrameImages(int frame)>& load,
                                   double staticTolerance = 0.0, const EmitterRule& rule = {});

// The same with one reference: `load(frame)` returns {test, reference}.
SequenceDifference compareSequence(
    const std::vector<int>& frames,
    const std::function<std::pair<FloatImage, FloatImage>(int frame)>& load,
    double staticTolerance = 0.0, const EmitterRule& rule = {});

}  // namespace rad
