// Object culling against the view volume before an item buffer draw (issue 58: a floor of
// furnished rooms, most of whose mesh nodes lie outside any one frame's view; drawing them cost
// OSMesa its vertex work for no fragment).
#pragma once

#include <array>

#include <glm/glm.hpp>

namespace rad {

// Local-frame bounds of the vertices one draw call sends: {min, max}.
using LocalBounds = std::array<glm::vec3, 2>;

// Whether every point of the box lies strictly outside one of the side planes of the clip
// volume (x > w, x < -w, y > w or y < -w) under clipFromLocal, the matrix the vertex shader
// applies. Clip coordinates are linear in the local point, so when the 8 corners are outside one
// plane every triangle inside the box is clipped away whole and draws no fragment: skipping it
// leaves the buffer bit-identical. The test runs in double with a margin above the float
// rounding of the shader's product (1e-5 of the magnitude of its terms), so a corner the GPU
// could place on the inside is never taken as outside. An empty box (min > max) is outside.
bool outsideClipVolume(const glm::mat4& clipFromLocal, const LocalBounds& bounds);

}  // namespace rad
