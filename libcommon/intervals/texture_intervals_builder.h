// Texture-movie extents from per-frame item buffers (Martín, Pueyo, Tost, "Frame rate
// independent texture movies for animated radiosity", §4.1 "texture movies" and §4.3 "item
// buffer"; docs/design.md §6.2 rad-intervals).
//
// Each top-level patch is subdivided regularly down to maxLevel; every leaf is rendered into
// an item buffer with its own id (its number + 1, seen_subdivision.h). A top's nodes are made
// when a frame first shows one of its leaves: a top no frame shows gets no movie (issue 58). Per
// frame:
//  * visible pixels per node = sum over the leaves below it;
//  * projected area per node (projected_area.h, occlusion ignored), twice: the part inside the
//    frustum (zero: the node left the frustum), and the whole patch's image, clipped only at
//    the near and far planes (in practice: the side planes are moved 64 image sizes out, so an
//    edge-on patch crossing the eye plane still has a bounded area);
//  * visible fraction = visible pixels / whole projected area. As the paper says (§4.1 item 2),
//    a patch leaving the frustum has a shrinking visible fraction and goes down to its
//    children, whose parts outside the frustum then need no texture;
//  * representation (§4.3): a top-level patch stands for itself when its visible fraction is
//    >= minVisibleFraction (theta), else its children do, recursively down to maxLevel; nodes
//    without visible pixels get no movie. A node seen on fewer than 4 minSize^2 pixels stands
//    for itself whatever its fraction (beyond the paper): its four children's smallest
//    textures would hold more texels than it covers, so splitting it only adds movies. Every
//    visible pixel is therefore covered by exactly one chosen node (the ancestor-or-self of its
//    leaf where the descent stopped);
//  * texture size: n = sqrt(whole projected area x texelDensity) texels per side (at least one
//    texel per covered pixel: the texture spans the whole patch, so its texels per pixel are
//    n^2 / whole area wherever the patch is on screen), rounded up to the ladder of sides
//    round(r^k), r = sizeRatio, and clamped to [minSize, maxSize]. The paper takes powers of
//    two (r = 2: up to 4 texels per pixel, 2.2 on average over sizes spread evenly in log);
//    r = sqrt 2 holds the same pixels with at most 2 (1.4 on average), so fewer texels per
//    frame. The n^2 texels go to the two sides in the shape of the node's (u,v) map
//    (TextureShape, below; texture_size.cpp), each side rounded and clamped the same way;
//  * events (§4.1): a movie opens when its node becomes chosen and closes when the node leaves
//    the frustum, is hidden, is replaced by an ancestor or descendant (level change), needs
//    another size, or has lasted maxLength frames; movies open at the end of the window close
//    with kWindow.
//
// Level hysteresis (levelHysteresis = h, beyond the paper, default 0.4): a node represented by
// itself in the previous frame stays so while its visible fraction is >= theta - h; a node
// represented by its descendants in the previous frame goes back to one texture only when its
// fraction is >= theta + h. Other nodes use theta. This keeps patches whose fraction hovers around
// theta from switching level every frame: each switch ends the movies of one level and starts the
// other's, and a new movie pays its whole setup (links, per-texel form factors, static shadows)
// whatever its length. With the paper's rule (h = 0) level changes end many movies early (most of
// them in a scene of small moving cubes); h = 0.4 (children below 10 % visible, the node again from
// 90 %) makes far fewer movies for a few more texels per frame. The from-scratch baseline
// (maxLength 1) keeps no movie from frame to frame, so it takes theta alone: each frame's choice is
// its own.
//
// Hidden gaps (hiddenGap = g, beyond the paper): a node hidden behind a nearer surface (in the
// frustum, no relative chosen) for at most g consecutive frames, then chosen again at the same
// size, keeps its movie over the gap, which then spans frames where no pixel shows it. Tiny patches
// flicker in and out of the item buffer behind a frame's chairs and desks: most movies closed as
// hidden would be followed within a few frames by a movie of the same node and size, each a new
// movie's setup (links, form factors, static shadows) for a few texels. While the node is hidden a
// relative chosen, a gap past g, or a resize or maxLength on return closes the movie as hidden at
// its last visible frame, so a node and its relatives still never overlap.
//
// Size hysteresis: a movie of size s (a rung of the ladder) is right for ideal sizes n in
// (s/r, s]. It keeps s while n stays in (s / (r (1 + tol)), s (1 + tol)], i.e. within a factor
// (1 + tol) of the interval it was rounded from, so small zooms do not close movies every frame.
//
// Deterministic: rendering, counting and events are sequential per frame; the result depends
// only on the scene, the frames and the options.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "libcommon/gl/item_buffer.h"
#include "libcommon/intervals/movie_extent.h"
#include "libcommon/scene/camera_projection.h"
#include "libcommon/scene/patch_hierarchy.h"
#include "libcommon/scene/scene.h"

namespace rad {

struct TextureIntervalsOptions {
  ImageSize imageSize{352, 240};
  double fps = 24.0;                // frame f is at time f / fps
  int maxLevel = 2;                 // depth of the regular subdivision (0 = top-level only)
  double minVisibleFraction = 0.5;  // theta of §4.3
  // Hysteresis on the level choice (0 = the paper's rule): see the header comment.
  double levelHysteresis = 0.4;
  double texelDensity = 1.0;       // texels per covered pixel
  int minSize = 4, maxSize = 256;  // texture side bounds (need not be rungs of the ladder)
  double resizeTolerance = 0.5;    // hysteresis factor (see above)
  // Texture sides are round(sizeRatio^k) (see above). sqrt 2, not the paper's 2: fewer texels per
  // frame for about the same error against the references, a little more where a big tile carries
  // many small shadows (a hall's floor under its chairs' legs).
  double sizeRatio = 1.4142135623730951;
  int maxLength = 0;  // frames per movie; 0 = unlimited
  // A movie whose node is hidden for at most this many consecutive frames (of those added)
  // and then chosen again at the same size continues over them (see above); 0: the paper's
  // rule, every hidden frame closes the movie.
  int hiddenGap = 6;
  // The samples whose coverage the item buffers decide (sample_grid.h): rad-compose shades
  // samples of this grid, so every one of them must lie in a movie. The item buffer is the
  // grid's, visible counts are in samples, and every rule above that counts pixels takes
  // samples / s^2; projected areas, and so texel density, stay in pixels.
  PixelSampling sampling = PixelSampling::pixelCentres();
  // Not a parameter: whether IntervalFrame::itemBuffer carries depth (the caller writes the
  // buffers); without it the depth target is neither drawn nor read back.
  bool itemBufferDepth = true;

  // Throws rad::Error(kUsage) naming the flag of the first invalid value.
  void validate() const;
};

// What one frame looked like (for reports, tests and --item-buffers).
struct IntervalFrame {
  int frame = 0;
  double time = 0.0;
  double itemBufferSeconds = 0.0;  // render + readback
  // Of options.sampling's grid (sample_grid.h); nullptr for addVisibleSamples' frames.
  const ItemBuffer* itemBuffer = nullptr;
  // Per dense node index of the builder's hierarchy (the tops, and the subtrees of the tops shown
  // so far): visible pixels, projected area of the whole patch (pixels, see
  // above) and the part of it inside the frustum. The areas are computed only where the
  // algorithm needs them (nodes with visible pixels; the frustum area of nodes whose movie
  // closed) and are -1 elsewhere.
  const std::vector<long>* visiblePixels = nullptr;
  const std::vector<double>* projectedArea = nullptr;
  const std::vector<double>* areaInFrustum = nullptr;
  // Dense node indices chosen this frame (ascending) and, parallel to it, the index into the
  // builder's movie list of the movie covering each.
  const std::vector<int>* chosen = nullptr;
  const std::vector<int>* chosenMovie = nullptr;
};

class TextureIntervalsBuilder {
 public:
  // cameraNode: a scene node carrying a camera (Scene::cameraNode). Makes the GL context
  // (throws rad::Error(kEnvironment) when it cannot).
  TextureIntervalsBuilder(const Scene& scene, int cameraNode, TextureIntervalsOptions options);
  ~TextureIntervalsBuilder();
  TextureIntervalsBuilder(const TextureIntervalsBuilder&) = delete;
  TextureIntervalsBuilder& operator=(const TextureIntervalsBuilder&) = delete;

  // The tops and the subtrees made so far (seen_subdivision.h): a top's subtree is made by the
  // first frame that shows it, so a dense index names a node only within this builder.
  const PatchHierarchy& hierarchy() const;
  const TextureIntervalsOptions& options() const;
  // Dense index of the leaf an item id shows: -1 for kNoItem, an id out of range, or a leaf whose
  // top no frame added so far has shown. Item id = the leaf's number + 1.
  int nodeOfItem(uint32_t id) const;
  // The number of dense node i in the full subdivision (seen_subdivision.h): what item ids (+1)
  // and visible samples files name.
  uint64_t numberOf(int node) const;
  // Nodes of the full subdivision to maxLevel (intervals.rti's patch_nodes), and the tops whose
  // subtrees were made (those some frame showed; hierarchy().size() nodes in all).
  uint64_t fullNodeCount() const;
  int topsSeen() const;

  // Processes one frame; frames must be strictly increasing. With a step between frames, a
  // movie is taken to cover the skipped frames between two frames where it is chosen.
  // `observer` (may be empty) sees the frame before the next one is rendered.
  void addFrame(int frame, const std::function<void(const IntervalFrame&)>& observer = {});
  // The same for each of `frames` in order, their item buffers rendered ahead by up to
  // `renderers` GL contexts on as many threads (one: addFrame's own); the same results whatever
  // the count. `frameDone` (may be empty) is called after each frame.
  void addFrames(const std::vector<int>& frames, size_t renderers,
                 const std::function<void(const IntervalFrame&)>& observer = {},
                 const std::function<void()>& frameDone = {});
  // The same as addFrame for a frame whose item buffer was counted elsewhere (a farm task,
  // formats/visible_samples.h): leaves[k] (numbers of leaves, seen_subdivision.h, each once) showed
  // counts[k] samples of the grid, every other leaf none. The observer sees itemBuffer nullptr.
  // Throws rad::Error(kInternal) for a number that is not a leaf's or lists of different sizes.
  void addVisibleSamples(int frame, const std::vector<uint32_t>& leaves,
                         const std::vector<uint32_t>& counts, double itemBufferSeconds,
                         const std::function<void(const IntervalFrame&)>& observer = {});
  // Closes the movies still open (kWindow) and returns all, in id order: sorted by
  // (firstFrame, patch.packed()), MovieExtent::movie = the index (intervals.rti's ids).
  std::vector<MovieExtent> finish();

  // Movies so far (open ones have end == kWindow and lastFrame = the last frame added), in
  // creation order; their ids (MovieExtent::movie) are given by finish() and are 0 here.
  const std::vector<MovieExtent>& movies() const;
  double itemBufferSeconds() const;  // total over the frames added
  int framesAdded() const;
  long moviesContinuedOverGaps() const;  // hidden gaps a movie was kept over (hiddenGap)

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Convenience: every frame of `frames` (increasing) through one builder.
std::vector<MovieExtent> buildTextureIntervals(
    const Scene& scene, int cameraNode, const std::vector<int>& frames,
    const TextureIntervalsOptions& options,
    const std::function<void(const IntervalFrame&)>& observer = {});

// The size rule above for a square texture: next side for a movie of current side `current`
// (0 = new movie) when the projected area is `projectedPixels`.
int textureSideFor(double projectedPixels, int current, const TextureIntervalsOptions& options);

// A node's texture is not square where its (u,v) map is not (issue 56): the n^2 texels of the
// size rule go to the two axes in proportion to the node's edges along u and v, and grow by
// 1 / sin of the angle between them, so that texels lie as far apart along u as along v, as far
// as a square's do on a square patch. A square patch's texture is n x n as before; a 4 m x 4 cm
// tube lamp's face gets its texels along its length, not 1/10 of them; a triangle's texture
// keeps the half square's budget of a right triangle at v0. `u`, `v`: the factors of n per axis
// (u v = 1 / sin: a sheared map needs more texels for the same spacing).
struct TextureShape {
  double u = 1.0, v = 1.0;
};
// Of a node's polygon (its own (u,v) map, patch_hierarchy.h: a triangle's edges v0v1 and v0v2,
// a quad's mean opposite edges); {1, 1} for a degenerate one.
TextureShape textureShapeOf(const Polygon& node);
struct TextureSize {
  int width = 0, height = 0;  // 0 x 0: none yet
  bool operator==(const TextureSize& o) const { return width == o.width && height == o.height; }
};
// The size rule per axis: each side is the ladder's rung for n x shape.u (n x shape.v) with
// textureSideFor's hysteresis about the current side (0 = new movie), n = sqrt(projected area x
// texelDensity).
TextureSize textureSizeFor(double projectedPixels, TextureShape shape, TextureSize current,
                           const TextureIntervalsOptions& options);

}  // namespace rad
