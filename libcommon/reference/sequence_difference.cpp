// docs/design.md §10: a frame sequence against its references, with the figures an item
// buffer makes possible.
#include "libcommon/reference/sequence_difference.h"

#include <utility>
#include <vector>

#include "libcommon/core/error.h"
#include "libcommon/reference/edge_pixels.h"

namespace rad {

namespace {

// What the temporal error (§10.6) keeps of a frame for the next one: its images and which of its
// pixels are emitters and edges.
struct KeptFrame {
  int frame = 0;
  FloatImage test, reference, reference2;
  std::vector<uint8_t> emitter, edge;
  bool hasEdges = false;
  TemporalFrame view() const {
    return {&test, &reference, reference2.pixels.empty() ? nullptr : &reference2, &emitter,
            hasEdges ? &edge : nullptr};
  }
};

// The frame's error figure (§10.1), and with surfaces its regions (§10.3), structured error
// (§10.4) and seams (§10.5), added to `seams`.
FrameDifference measureFrame(int frame, const FrameImages& im, const EmitterRule& rule,
                             SeamSteps& seams, KeptFrame& kept) {
  const std::string frameName = "frame " + std::to_string(frame);
  const std::string where = im.testWhere.empty() ? frameName : im.testWhere;
  const std::string where2 =
      im.reference2Where.empty() ? frameName + ": second reference" : im.reference2Where;
  const std::string whereMask = im.maskWhere.empty() ? frameName + ": emitter mask" : im.maskWhere;
  const FloatImage* reference2 = im.reference2.pixels.empty() ? nullptr : &im.reference2;
  const FloatImage* mask = im.emitterMask.pixels.empty() ? nullptr : &im.emitterMask;
  const PixelGroups* groups = im.groups.count > 0 ? &im.groups : nullptr;
  FrameDifference fd;
  fd.frame = frame;
  fd.stats = compareImages(im.test, im.reference, where);
  if (im.surfaces.empty()) {
    fd.error = measureError(im.test, im.reference, reference2, rule, where, where2, mask, whereMask,
                            groups);
    kept.emitter = findEmitterPixels(im.reference, reference2, rule, mask).isEmitter;
    return fd;
  }
  if (im.surfaces.width != im.reference.width || im.surfaces.height != im.reference.height)
    throw inputError(where, "item buffer surfaces are not of the image's size");
  const EdgePixels edges = findEdgePixels(im.surfaces);
  const PixelGroups regions = edges.regions();
  fd.error = measureError(im.test, im.reference, reference2, rule, where, where2, mask, whereMask,
                          groups, &regions);
  EmitterPixels emitters = findEmitterPixels(im.reference, reference2, rule, mask);
  FloatImage smoothed;
  fd.structured = measureStructuredError(im.test, im.reference, reference2, emitters.isEmitter,
                                         edges, im.smoothedSink ? &smoothed : nullptr);
  if (im.smoothedSink) im.smoothedSink(smoothed);
  seams.merge(measureSeams(im.test, im.reference, reference2, emitters.isEmitter, im.surfaces,
                           edges, frame));
  kept.emitter = std::move(emitters.isEmitter);
  kept.edge = edges.edge;
  kept.hasEdges = true;
  return fd;
}

}  // namespace

SequenceDifference compareSequence(const std::vector<int>& frames,
                                   const std::function<FrameImages(int frame)>& load,
                                   double staticTolerance, const EmitterRule& rule) {
  SequenceDifference result;
  KeptFrame previous, current;
  bool havePrevious = false;
  for (int frame : frames) {
    FrameImages im = load(frame);
    result.haveSurfaces = result.haveSurfaces || !im.surfaces.empty();
    current = KeptFrame{};
    FrameDifference fd = measureFrame(frame, im, rule, result.seams, current);
    result.total.merge(fd.stats);
    result.totalError.merge(fd.error);
    result.frames.push_back(std::move(fd));
    current.frame = frame;
    current.test = std::move(im.test);
    current.reference = std::move(im.reference);
    current.reference2 = std::move(im.reference2);
    if (havePrevious && frame == previous.frame + 1) {
      result.flicker.addPair(previous.test, current.test, previous.reference, current.reference,
                             staticTolerance);
      result.temporal.addPair(previous.view(), current.view());
    }
    std::swap(previous, current);
    havePrevious = true;
  }
  return result;
}

SequenceDifference compareSequence(
    const std::vector<int>& frames,
    const std::function<std::pair<FloatImage, FloatImage>(int frame)>& load, double staticTolerance,
    const EmitterRule& rule) {
  return compareSequence(frames, std::function<FrameImages(int)>([&](int frame) {
                           FrameImages im;
                           std::tie(im.test, im.reference) = load(frame);
                           return im;
                         }),
                         staticTolerance, rule);
}

}  // namespace rad
