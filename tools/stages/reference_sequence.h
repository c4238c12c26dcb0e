// rad-reference's frame loop (docs/design.md §8): path-traces each frame of a range and writes it
// as OUTDIR/NNNN.exr (linear radiance, the provenance as attributes), next to frame_sequence (the
// same for rad-compose). The renderer is libcommon/reference/path_tracer.h.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "libcommon/reference/reference_options.h"
#include "libcommon/scene/scene.h"

namespace rad {

struct ReferenceFrame {
  int frame = 0;
  double time = 0.0;     // frame / fps
  std::string path;      // the EXR written
  double seconds = 0.0;  // wall time to render and write it
};

// Renders `frames` (in the order given) from camera node `cameraNode` at options.fps, size
// `size`, into options.output (created if missing; rad::outputError if it cannot be), each EXR
// carrying `provenanceJson` as rad.provenance. `frameDone` is called after each frame.
void renderReferenceSequence(const Scene& scene, int cameraNode, ImageSize size,
                             const std::vector<int>& frames, const ReferenceOptions& options,
                             const std::string& provenanceJson,
                             const std::function<void(const ReferenceFrame&)>& frameDone);

}  // namespace rad
