// docs/design.md §10: a frame sequence against its references, with the figures an item
// buffer makes possible.
#include "libcommon/reference/sequence_difference.h"

#include "libcommon/core/error.h"
#include "libcommon/reference/edge_pixels.h"

namespace rad {

namespace {

// The frame's error figure (§10.1), and with surfaces its regions (§10.3), structured error
// (§10.4) and seams (§10.5), added to `seams`.
FrameDifference measureFrame(int frame, const FrameImages& im, const EmitterRule& rule,
                             SeamSteps& seams) {
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
    return fd;
  }
  if (im.surfaces.width != im.reference.width || im.surfaces.height != im.reference.height)
    throw inputError(where, "item buffer surfaces are not of the image's size");
  const EdgePixels edges = findEdgePixels(im.surfaces);
  const PixelGroups regions = edges.regions();
  fd.error = measureError(im.test, im.reference, reference2, rule, where, where2, mask, whereMask,
                          groups, &regions);
  const EmitterPixels emitters = findEmitterPixels(im.reference, reference2, rule, mask);
  FloatImage smoothed;
  fd.structured = measureStructuredError(im.test, im.reference, reference2, emitters.isEmitter,
                                         edges, im.smoothedSink ? &smoothed : nullptr);
  if (im.smoothedSink) im.smoothedSink(smoothed);
  seams.merge(measureSeams(im.test, im.reference, reference2, emitters.isEmitter, im.surfaces,
                           edges, frame));
  return fd;
}

}  // namespace

SequenceDifference compareSequence(const std::vector<int>& frames,
                                   const std::function<FrameImages(int frame)>& load,
                                   double staticTolerance, const EmitterRule& rule) {
  SequenceDifference result;
  FloatImage previousTest, previousReference;
  int previousFrame = 0;
  bool havePrevious = false;
  for (int frame : frames) {
    FrameImages im = load(frame);
    result.haveSurfaces = result.haveSurfaces || !im.surfaces.empty();
    FrameDifference fd = measureFrame(frame, im, rule, result.seams);
    result.total.merge(fd.stats);
    result.totalError.merge(fd.error);
    result.frames.push_back(std::move(fd));
    if (havePrevious && frame == previousFrame + 1)
      result.flicker.addPair(previousTest, im.test, previousReference, im.reference,
                             staticTolerance);
    previousTest = std::move(im.test);
    previousReference = std::move(im.reference);
    previousFrame = frame;
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
