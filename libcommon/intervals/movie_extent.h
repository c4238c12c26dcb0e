// One texture movie's extent: which patch node, from which frame to which, at what size, and
// why it ended (Martín, Pueyo, Tost, "Frame rate independent texture movies for animated
// radiosity", §4.1 events, §4.3 representation). The one record of the pipeline's second
// half: rad-intervals' builder makes it (texture_intervals_builder.h), intervals.rti stores it
// (formats/texture_intervals.h stores it as it is), rad-movies bakes it
// (TextureMovieBaker::bake in libcommon/movies/texture_movie_baker.h) and rad-compose plays it.
#pragma once

#include <cstdint>

#include "libcommon/scene/patch_hierarchy.h"

namespace rad {

// Why a movie ended (paper §4.1 events, plus the window end of a split run). The codes are
// intervals.rti's movie_close_reason values (formats/texture_intervals.md): do not renumber.
enum class MovieEnd : uint8_t {
  kLeftFrustum = 0,  // no pixel of it in the frustum any more
  kHidden = 1,       // in the frustum but covered by other patches
  kLevelChange = 2,  // represented by its children (or its parent) from the next frame
  kResize = 3,       // texture resolution changed beyond the hysteresis
  kMaxLength = 4,    // reached --max-length frames
  kWindow = 5,       // still open at the end of the --frames window
};
constexpr int kMovieEndCount = 6;
const char* movieEndName(MovieEnd e);  // "left_frustum", "hidden", ...

struct MovieExtent {
  uint32_t movie = 0;                     // id, 0.. in order of (firstFrame, patch.packed())
  PatchId patch;                          // the patch node the movie textures
  int32_t firstFrame = 0, lastFrame = 0;  // inclusive
  int32_t width = 1, height = 1;          // texels; texel (i, j) centre at node (u,v) =
                                          // ((i + 0.5) / width, (j + 0.5) / height)
  MovieEnd end = MovieEnd::kWindow;
  int level() const { return patch.level(); }
  int frameCount() const { return lastFrame - firstFrame + 1; }
  bool operator==(const MovieExtent& o) const {
    return movie == o.movie && patch == o.patch && firstFrame == o.firstFrame &&
           lastFrame == o.lastFrame && width == o.width && height == o.height && end == o.end;
  }
};

}  // namespace rad
