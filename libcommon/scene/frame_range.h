// Frames of an animation and the key frames inside them: the one rule every stage shares
// (docs/design.md §1 "Defaults: frames = the scene's whole animation", §4 "frame f is at f / fps").
//
// rad-global's key times (paper §4.2) and rad-movies' key textures (paper §5) are both
// `keyFrames(first, last, step)`; every tool without --frames covers `animationFrames`.
#pragma once

#include <string>
#include <vector>

namespace rad {

class Scene;

// An inclusive range of frame numbers, first <= last.
struct FrameRange {
  int first = 0, last = 0;
  int count() const { return last - first + 1; }
  bool covers(const FrameRange& other) const { return first <= other.first && other.last <= last; }
  std::string toString() const;  // "0-95"
};

// The frames every tool covers without --frames (docs/design.md §1 "The default frame range"):
// the frames whose times f / fps lie in [0, endTime), i.e. 0 .. ceil(endTime x fps) - 1, so an
// animation of 4 s at 24 fps is 96 frames, 0-95, a video of exactly its length (a looping
// animation's frame 96 would repeat frame 0). An animation shorter than a frame, or a static
// scene, is the one frame 0. The ceiling forgives 1e-9 of rounding, so an end of exactly 4 s at
// 24 fps ends at frame 95, not 96. `rad-inspect --default-frames SCENE [--fps F]` prints it.
FrameRange animationFrames(const Scene& scene, double fps);

// Key frames first, first + step, first + 2 step, ... below last, and always last itself;
// step < 1 counts as 1. keyFrames(0, 24, 6) = {0, 6, 12, 18, 24}; keyFrames(3, 10, 6) =
// {3, 9, 10}.
std::vector<int> keyFrames(int first, int last, int step);

}  // namespace rad
