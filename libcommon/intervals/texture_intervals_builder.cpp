// Texture-movie extents from item buffers. Sources and rules in texture_intervals_builder.h.
#include "libcommon/intervals/texture_intervals_builder.h"
#include "libcommon/scene/gltf_item_label.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <map>
#include <mutex>
#include <thread>

#include "libcommon/core/error.h"
#include "libcommon/core/stopwatch.h"
#include "libcommon/intervals/projected_area.h"
#include "libcommon/intervals/seen_subdivision.h"

namespace rad {
namespace {

// Side planes of the "whole patch" projection are this many image widths / heights out: the
// area of a patch's image clipped only at the near and far planes, bounded so a patch that
// crosses the eye plane edge-on cannot have an unbounded area.
constexpr double kGuardBand = 64.0;

// Largest full subdivision the builder numbers. The item geometry of every leaf is drawn whether
// or not its top is made (seen_subdivision.h), so this bounds the GL and item geometry's memory
// (issue 58's bound of 8 GB a stage): room for the million-triangle floor of make_floor.py at the
// default --max-level 2 (the 2^21 of the 100k-triangle hall refused it).
constexpr uint64_t kMaxNodes = uint64_t(1) << 24;

}  // namespace

void TextureIntervalsOptions::validate() const {
  auto bad = [](const std::string& flag, const std::string& what) {
    return Error(ExitCode::kUsage, "", flag + ": " + what);
  };
  if (imageSize.width < 1 || imageSize.height < 1 || imageSize.width > 16384 ||
      imageSize.height > 16384)
    throw bad("--size", "must be between 1x1 and 16384x16384");
  if (!(fps > 0.0) || !std::isfinite(fps)) throw bad("--fps", "must be > 0");
  if (maxLevel < 0 || maxLevel > 8) throw bad("--max-level", "must be in [0, 8]");
  if (!(minVisibleFraction >= 0.0 && minVisibleFraction <= 1.0))
    throw bad("--min-visible-fraction", "must be in [0, 1]");
  if (!(texelDensity > 0.0) || !std::isfinite(texelDensity))
    throw bad("--texel-density", "must be > 0");
  if (minSize < 1) throw bad("--min-size", "must be >= 1");
  if (maxSize < minSize || maxSize > 16384)
    throw bad("--max-size", "must be in [--min-size, 16384]");
  if (!(levelHysteresis >= 0.0 && levelHysteresis <= 1.0))
    throw bad("--level-hysteresis", "must be in [0, 1]");
  if (!(resizeTolerance >= 0.0) || !std::isfinite(resizeTolerance))
    throw bad("--resize-tolerance", "must be >= 0");
  if (!(sizeRatio >= 1.2 && sizeRatio <= 4.0)) throw bad("--size-ratio", "must be in [1.2, 4]");
  if (maxLength < 0) throw bad("--max-length", "must be >= 0 (0 = unlimited)");
  if (hiddenGap < 0) throw bad("--hidden-gap", "must be >= 0 (0 = close when hidden)");
  sampling.validate();
  const ImageSize samples = sampling.grid(imageSize).size();
  if (samples.width > 16384 || samples.height > 16384)
    throw bad("--pixel-samples", "the sample grid, " + std::to_string(samples.width) + "x" +
                                     std::to_string(samples.height) +
                                     ", exceeds 16384 a side; use fewer samples or a smaller size");
}

namespace {

// A frame's camera and the item objects' placement (Impl::frameView), for its item buffer.
struct FrameView {
  int frame = 0;
  double time = 0.0;
  CameraView camera;
  std::vector<glm::dmat4> transforms;  // per item object
};

}  // namespace

struct TextureIntervalsBuilder::Impl {
  const Scene& scene;
  int cameraNode;
  TextureIntervalsOptions options;
  // The patch nodes, made for the tops a frame has shown (seen_subdivision.h); dense indices
  // below are its hierarchy's.
  SeenSubdivision subdivision;
  std::vector<int> meshNodes;    // scene mesh node of each item object
  std::vector<int> objectOfTop;  // per top-level patch: index into meshNodes
  std::unique_ptr<ItemBufferRenderer> renderer;
  bool uploaded = false;  // renderer has the geometry
  ItemBuffer buffer;      // addFrame's
  // (leaf number, samples) of a frame's runs whose top was not made yet (countVisibleSamples).
  std::vector<std::pair<uint64_t, long>> unmadeRuns;

  // Per-frame state, per dense node (grown as tops are made, growNodeState).
  std::vector<long> visible;
  std::vector<double> area, inFrustum;  // -1 = not computed this frame
  std::vector<glm::dmat4> clipFromObject, guardFromObject;
  std::vector<int> chosen, chosenMovie;
  // Open movie per dense node (-1 = none): index into movies.
  std::vector<int> openMovie;
  std::vector<int> openList;    // dense nodes with an open movie, ascending
  std::vector<char> openBelow;  // per node: a descendant had an open movie last frame
  // Movies whose node is hidden, kept over a gap of at most hiddenGap frames (header), with
  // the frames their node has been hidden so far (each node's independently of the others').
  struct HiddenMovie {
    int node = 0, movie = 0, frames = 0;
  };
  std::vector<HiddenMovie> hidden;
  long continuedOverGaps = 0;
  std::vector<MovieExtent> movies;
  int lastFrame = 0;
  int frames = 0;
  double itemSeconds = 0.0;

  Impl(const Scene& s, int cam, TextureIntervalsOptions o)
      : scene(s), cameraNode(cam), options(o) {}

  // The samples the item buffers hold, and how many make a pixel (s^2): counts of visible
  // samples are compared with pixel areas times this.
  SampleGrid grid() const { return options.sampling.grid(options.imageSize); }
  ItemBufferOptions itemBufferOptions() const {
    ItemBufferOptions o;
    o.readDepth = options.itemBufferDepth;
    return o;
  }
  double samplesPerPixel() const {
    const int s = grid().perAxis;
    return double(s) * double(s);
  }

  void build() {
    options.validate();
    if (cameraNode < 0 || cameraNode >= int(scene.nodes.size()) ||
        scene.nodes[cameraNode].camera < 0)
      throw inputError(scene.path, nodeLabel(scene, cameraNode) + " is not a camera");
    subdivision = SeenSubdivision(scene.inputPolygons(), options.maxLevel, kMaxNodes);
    const PatchHierarchy& h = subdivision.hierarchy();
    // One item object per mesh node that owns patches (scene order).
    std::map<int, int> objectOf;
    for (int t = 0; t < h.topCount(); ++t) objectOf.emplace(h.top(t).node, 0);
    for (auto& [node, obj] : objectOf) {
      obj = int(meshNodes.size());
      meshNodes.push_back(node);
    }
    objectOfTop.resize(size_t(h.topCount()));
    for (int t = 0; t < h.topCount(); ++t) objectOfTop[t] = objectOf.at(h.top(t).node);
    // The GL context is made here, so that a machine without one fails before any frame; the
    // geometry goes to it with the first addFrame (addFrames' renderers have their own).
    renderer = std::make_unique<ItemBufferRenderer>(grid(), itemBufferOptions());
    growNodeState();
  }

  const PatchHierarchy& hierarchy() const { return subdivision.hierarchy(); }
  int objectOf(int node) const { return objectOfTop[hierarchy().node(node).id.top]; }

  // The per-node state sized to the nodes made, new nodes without samples or movies.
  void growNodeState() {
    const size_t n = size_t(hierarchy().size());
    visible.resize(n, 0);
    area.resize(n, -1.0);
    inFrustum.resize(n, -1.0);
    openMovie.resize(n, -1);
    openBelow.resize(n, 0);
  }

  // The leaves of the full subdivision as item objects (one per mesh node, ids leaf number + 1,
  // seen_subdivision.h), made or not: a top no frame has shown yet may show in the next one, and
  // hides what lies behind it. Made for each renderer and dropped once uploaded, so that they are
  // not held through the frames. In each object, leaves in number order (the order the draw
  // breaks depth ties in).
  std::vector<ItemObject> itemObjects() const {
    const PatchHierarchy& h = subdivision.hierarchy();
    std::vector<ItemObject> objects(meshNodes.size());
    // Exact sizes first: at a million triangles the leaves' triangles are gigabytes, and growing
    // them by doubling held up to twice that (issue 58).
    const size_t leavesPerTop = size_t(1) << (2 * options.maxLevel);
    std::vector<size_t> triangles(meshNodes.size(), 0);
    for (int t = 0; t < h.topCount(); ++t)
      triangles[objectOfTop[t]] += leavesPerTop * size_t(h.top(t).local.count - 2);
    for (size_t k = 0; k < objects.size(); ++k) {
      objects[k].triangles.reserve(triangles[k]);
      objects[k].ids.reserve(triangles[k]);
    }
    const uint64_t firstLeaf = subdivision.fullNodeCount() - leavesPerTop * h.topCount();
    for (int t = 0; t < h.topCount(); ++t) {
      uint64_t number = firstLeaf + uint64_t(t) * leavesPerTop;
      for (const Polygon& leaf : subdivision.leafPolygons(t))
        objects[objectOfTop[t]].addPolygon(leaf, uint32_t(number++ + 1));
    }
    return objects;
  }

  FrameView frameView(int frame) const {
    FrameView v;
    v.frame = frame;
    v.time = frame / options.fps;
    v.camera = scene.cameraAt(cameraNode, v.time);
    v.transforms.resize(meshNodes.size());
    for (size_t o = 0; o < meshNodes.size(); ++o)
      v.transforms[o] = scene.worldTransform(meshNodes[o], v.time);
    return v;
  }

  // Whole-patch projected area (header: clipped at the near and far planes only).
  double wholeArea(int i) {
    if (area[i] < 0.0) {
      const Polygon& p = hierarchy().node(i).local;
      area[i] =
          kGuardBand * kGuardBand *
          projectedAreaPixels(guardFromObject[objectOf(i)], options.imageSize, p.v.data(), p.count);
    }
    return area[i];
  }
  double areaInFrustum(int i) {
    if (inFrustum[i] < 0.0) {
      const Polygon& p = hierarchy().node(i).local;
      inFrustum[i] =
          projectedAreaPixels(clipFromObject[objectOf(i)], options.imageSize, p.v.data(), p.count);
    }
    return inFrustum[i];
  }

  void choose(int i) {
    if (visible[i] == 0) return;
    wholeArea(i);
    // Level hysteresis: a node represented by itself last frame keeps it down to theta - h; a
    // node represented by descendants last frame needs theta + h to take over again.
    // From scratch (maxLength 1) no movie goes on to the next frame: no hysteresis either.
    const double h = options.maxLength == 1 ? 0.0 : options.levelHysteresis;
    double theta = options.minVisibleFraction;
    if (openMovie[i] >= 0)
      theta -= h;
    else if (openBelow[i])
      theta += h;
    bool enough = area[i] > 0.0 && double(visible[i]) >= theta * area[i] * samplesPerPixel();
    // A node seen on fewer pixels than its four children's smallest textures hold (4 minSize^2)
    // keeps one texture: splitting it adds movies, not resolution (partly hidden small triangles, a
    // chair's, would otherwise make most of a scene's movies). But only while its own texture is
    // small too (at most 4 minSize a side): a big patch leaving the frustum, a few pixels left on
    // screen, would keep its whole-area texture, where the children holding those pixels need a
    // sixteenth of it and carry on the movies they had.
    const bool tiny =
        double(visible[i]) < 4.0 * options.minSize * options.minSize * samplesPerPixel() &&
        textureSideFor(area[i], 0, options) <= 4 * options.minSize;
    if (enough || tiny || hierarchy().isLeaf(i)) {
      chosen.push_back(i);
      return;
    }
    int c = hierarchy().node(i).firstChild;
    for (int k = 0; k < 4; ++k) choose(c + k);
  }

  // True when an ancestor or a descendant of node i is chosen this frame.
  bool relativeChosen(int i, const std::vector<char>& isChosen) const {
    for (int p = hierarchy().node(i).parent; p >= 0; p = hierarchy().node(p).parent)
      if (isChosen[p]) return true;
    // Descendants: dense indices of a subtree are not contiguous, so walk it.
    std::vector<int> stack;
    if (!hierarchy().isLeaf(i)) stack.push_back(i);
    while (!stack.empty()) {
      int n = stack.back();
      stack.pop_back();
      int c = hierarchy().node(n).firstChild;
      for (int k = 0; k < 4; ++k) {
        if (isChosen[c + k]) return true;
        if (!hierarchy().isLeaf(c + k)) stack.push_back(c + k);
      }
    }
    return false;
  }

  // Whether movie m has lasted maxLength frames at `frame`.
  bool reachedMaxLength(const MovieExtent& m, int frame) const {
    return options.maxLength > 0 && frame - m.firstFrame >= options.maxLength;
  }

  // The movies of hidden nodes at this frame: a node chosen again at its movie's size takes
  // the movie back (the chosen nodes' loop then extends it over the gap); a relative chosen, a
  // gap past hiddenGap, or a return at another size or past maxLength ends it where it was last
  // seen, as hidden.
  void continueOverGaps(int frame, const std::vector<char>& isChosen) {
    std::vector<HiddenMovie> still;
    for (HiddenMovie h : hidden) {
      MovieExtent& m = movies[h.movie];
      if (isChosen[h.node]) {
        if (!reachedMaxLength(m, frame) && sizeFor(h.node, sizeOf(m)) == sizeOf(m)) {
          openMovie[h.node] = h.movie;
          m.end = MovieEnd::kWindow;  // open again: ends as an open movie does
          ++continuedOverGaps;
        }
      } else if (++h.frames <= options.hiddenGap && !relativeChosen(h.node, isChosen)) {
        still.push_back(h);
      }
    }
    hidden.swap(still);
  }

  // The texture size of node i this frame, from `current` (0 x 0: a new movie; TextureShape).
  TextureSize sizeFor(int i, TextureSize current) const {
    return textureSizeFor(area[i], textureShapeOf(hierarchy().node(i).local), current, options);
  }
  static TextureSize sizeOf(const MovieExtent& m) { return {m.width, m.height}; }

  int openNew(int node, int frame, TextureSize size) {
    MovieExtent m;
    m.patch = hierarchy().node(node).id;
    m.firstFrame = m.lastFrame = frame;
    m.width = size.width;
    m.height = size.height;
    m.end = MovieEnd::kWindow;
    movies.push_back(m);
    openMovie[node] = int(movies.size()) - 1;
    return openMovie[node];
  }

  void addFrame(int frame, const std::function<void(const IntervalFrame&)>& observer) {
    if (!uploaded) renderer->setGeometry(itemObjects());
    uploaded = true;
    const FrameView v = frameView(frame);
    auto start = std::chrono::steady_clock::now();
    renderer->render(v.camera, v.transforms, buffer);
    addRendered(v, buffer, secondsSince(start), observer);
  }

  // visible[i] = the samples of `ids` showing leaf i. Counted by runs of one id: a leaf covers
  // many neighbouring samples of a row (the grid has s^2 a pixel), so one add a run instead of
  // one a sample; the same sums. The tops first shown here are made after the pass (in top order,
  // whatever order the buffer shows them in), and their runs added then.
  void countVisibleSamples(const std::vector<uint32_t>& ids) {
    std::fill(visible.begin(), visible.end(), 0);
    unmadeRuns.clear();
    const size_t count = ids.size();
    for (size_t k = 0; k < count;) {
      const uint32_t id = ids[k];
      size_t end = k + 1;
      while (end < count && ids[end] == id) ++end;
      if (id != kNoItem) {
        const uint64_t number = uint64_t(id) - 1;
        if (!subdivision.isLeafNumber(number))
          throw Error(ExitCode::kInternal, "", "item buffer id out of range");
        const int node = subdivision.nodeOfLeafNumber(number);
        if (node >= 0)
          visible[node] += long(end - k);
        else
          unmadeRuns.push_back({number, long(end - k)});
      }
      k = end;
    }
    if (unmadeRuns.empty()) return;
    std::vector<int> tops;
    for (const auto& run : unmadeRuns) tops.push_back(subdivision.topOfLeafNumber(run.first));
    subdivision.make(std::move(tops));
    growNodeState();
    for (const auto& [number, samples] : unmadeRuns)
      visible[subdivision.nodeOfLeafNumber(number)] += samples;
  }

  // Frame v.frame, whose item buffer `items` was rendered at v in `seconds`.
  void addRendered(const FrameView& v, const ItemBuffer& items, double seconds,
                   const std::function<void(const IntervalFrame&)>& observer) {
    countVisibleSamples(items.id);
    addCounted(v, &items, seconds, observer);
  }

  // visible[leaf numbered leaves[k]] = counts[k] (addVisibleSamples' contract), 0 elsewhere;
  // the tops first shown are made first, as countVisibleSamples makes them.
  void setVisibleSamples(const std::vector<uint32_t>& leaves, const std::vector<uint32_t>& counts) {
    if (leaves.size() != counts.size())
      throw Error(ExitCode::kInternal, "", "visible samples: leaves and counts differ in number");
    std::vector<int> unmade;
    for (uint32_t number : leaves) {
      if (!subdivision.isLeafNumber(number))
        throw Error(ExitCode::kInternal, "", "visible samples: not a leaf of the subdivision");
      const int top = subdivision.topOfLeafNumber(number);
      if (!subdivision.made(top)) unmade.push_back(top);
    }
    if (!unmade.empty()) {
      subdivision.make(std::move(unmade));
      growNodeState();
    }
    std::fill(visible.begin(), visible.end(), 0);
    for (size_t k = 0; k < leaves.size(); ++k)
      visible[subdivision.nodeOfLeafNumber(leaves[k])] = long(counts[k]);
  }

  // Frame v.frame, whose leaves' visible samples are in `visible` (item buffer `items`, or
  // none when they were counted elsewhere).
  void addCounted(const FrameView& v, const ItemBuffer* items, double seconds,
                  const std::function<void(const IntervalFrame&)>& observer) {
    const int frame = v.frame;
    if (frames > 0 && frame <= lastFrame)
      throw Error(ExitCode::kInternal, "", "frames must be strictly increasing");
    const double t = v.time;
    const CameraView& view = v.camera;
    const std::vector<glm::dmat4>& transforms = v.transforms;
    itemSeconds += seconds;

    // Visible pixels per leaf summed up the tree (children come after parents).
    for (int i = hierarchy().size() - 1; i >= hierarchy().topCount(); --i)
      visible[hierarchy().node(i).parent] += visible[i];

    // Projected areas, computed only where needed (nodes with visible pixels, closing movies):
    // a frame then costs O(visible nodes), not O(all nodes).
    glm::dmat4 clip = clipFromWorld(view, options.imageSize);
    glm::dmat4 guard(1.0);
    guard[0][0] = guard[1][1] = 1.0 / kGuardBand;
    clipFromObject.resize(meshNodes.size());
    guardFromObject.resize(meshNodes.size());
    for (size_t o = 0; o < meshNodes.size(); ++o) {
      clipFromObject[o] = clip * transforms[o];
      guardFromObject[o] = guard * clipFromObject[o];
    }
    std::fill(area.begin(), area.end(), -1.0);
    std::fill(inFrustum.begin(), inFrustum.end(), -1.0);

    // Representation of each top-level patch.
    std::fill(openBelow.begin(), openBelow.end(), 0);
    for (int node : openList)
      for (int p = hierarchy().node(node).parent; p >= 0 && !openBelow[p];
           p = hierarchy().node(p).parent)
        openBelow[p] = 1;
    chosen.clear();
    for (int top = 0; top < hierarchy().topCount(); ++top) choose(top);
    std::sort(chosen.begin(), chosen.end());
    std::vector<char> isChosen(hierarchy().size(), 0);
    for (int i : chosen) isChosen[i] = 1;

    continueOverGaps(frame, isChosen);
    // Close the movies whose node is no longer chosen (§4.1 events); a hidden node's movie
    // waits for it over a gap (header).
    for (int node : openList) {
      if (isChosen[node]) continue;
      MovieExtent& m = movies[openMovie[node]];
      if (relativeChosen(node, isChosen))
        m.end = MovieEnd::kLevelChange;
      else if (areaInFrustum(node) <= 0.0)
        m.end = MovieEnd::kLeftFrustum;
      else
        m.end = MovieEnd::kHidden;
      if (m.end == MovieEnd::kHidden && options.hiddenGap > 0)
        hidden.push_back({node, openMovie[node], 1});
      openMovie[node] = -1;
    }
    // Continue, restart (size, length) or open the chosen nodes' movies.
    chosenMovie.assign(chosen.size(), -1);
    for (size_t c = 0; c < chosen.size(); ++c) {
      int node = chosen[c];
      int idx = openMovie[node];
      if (idx >= 0) {
        MovieExtent& m = movies[idx];
        const TextureSize size = sizeFor(node, sizeOf(m));
        const bool full = reachedMaxLength(m, frame);
        if (!full && size == sizeOf(m)) {
          m.lastFrame = frame;
          chosenMovie[c] = idx;
          continue;
        }
        m.end = full ? MovieEnd::kMaxLength : MovieEnd::kResize;
        chosenMovie[c] = openNew(node, frame, size);
      } else {
        chosenMovie[c] = openNew(node, frame, sizeFor(node, {}));
      }
    }
    openList = chosen;
    lastFrame = frame;
    ++frames;

    if (observer) {
      IntervalFrame f;
      f.frame = frame;
      f.time = t;
      f.itemBufferSeconds = seconds;
      f.itemBuffer = items;
      f.visiblePixels = &visible;
      f.projectedArea = &area;
      f.areaInFrustum = &inFrustum;
      f.chosen = &chosen;
      f.chosenMovie = &chosenMovie;
      observer(f);
    }
  }
};

namespace {

// Item buffers rendered ahead of the builder on worker threads, frame i by worker i mod N into its
// slot, taken in frame order (take). Each worker makes and uses its own renderer: an OSMesa context
// is current on one thread at a time. A frame's buffer does not depend on the others', and llvmpipe
// draws one on about one core (drawing is most of a frame's time), so the workers draw N frames at
// once while the builder reads the last. The same buffers as one renderer's: the same driver and
// geometry, frame by frame.
class ItemBufferPipeline {
 public:
  using View = std::function<FrameView(int frame)>;

  struct Slot {
    FrameView view;
    ItemBuffer buffer;
    double seconds = 0.0;
    bool ready = false;
    std::exception_ptr error;
  };

  ItemBufferPipeline(size_t workers, SampleGrid size, ItemBufferOptions itemOptions,
                     const std::vector<ItemObject>& objects, std::vector<int> frames, View view)
      : itemOptions_(itemOptions),
        frames_(std::move(frames)),
        view_(std::move(view)),
        slots_(workers) {
    try {
      for (size_t k = 0; k < workers; ++k)
        threads_.emplace_back([this, k, size, &objects] { work(k, size, objects); });
    } catch (...) {
      // A thread that did not start (std::system_error): no destructor runs for a constructor
      // that throws, and a joinable std::thread destroyed unjoined aborts the process.
      stopAndJoin();
      throw;
    }
    // The objects are the caller's: every worker has uploaded them before this returns.
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return uploaded_ == threads_.size(); });
  }

  ~ItemBufferPipeline() { stopAndJoin(); }

  // Frame i's slot once rendered (rethrows a worker's error); release(i) hands it back.
  Slot& take(size_t i) {
    Slot& s = slots_[i % slots_.size()];
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return s.ready; });
    if (s.error) std::rethrow_exception(s.error);
    return s;
  }
  void release(size_t i) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      slots_[i % slots_.size()].ready = false;
    }
    changed_.notify_all();
  }

 private:
  void stopAndJoin() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    changed_.notify_all();
    for (std::thread& t : threads_) t.join();
  }

  void work(size_t k, SampleGrid size, const std::vector<ItemObject>& objects) {
    Slot& s = slots_[k];
    std::unique_ptr<ItemBufferRenderer> renderer;
    std::exception_ptr error;
    try {
      // One upload at a time: each converts the objects to its own vertex array before the driver
      // copies it, so uploads side by side held every worker's array at once (a floor of 10^6
      // triangles has some 16 M leaf triangles; issue 58's memory bound).
      std::lock_guard<std::mutex> one(uploading_);
      renderer = std::make_unique<ItemBufferRenderer>(size, itemOptions_);
      renderer->setGeometry(objects);
    } catch (...) {
      error = std::current_exception();
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++uploaded_;
    }
    changed_.notify_all();
    for (size_t i = k; i < frames_.size(); i += slots_.size()) {
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] { return stop_ || !s.ready; });
        if (stop_) return;
      }
      if (!error) try {
          s.view = view_(frames_[i]);
          auto start = std::chrono::steady_clock::now();
          renderer->render(s.view.camera, s.view.transforms, s.buffer);
          s.seconds = secondsSince(start);
        } catch (...) {
          error = std::current_exception();
        }
      {
        std::lock_guard<std::mutex> lock(mutex_);
        s.error = error;
        s.ready = true;
      }
      changed_.notify_all();
      if (error) return;
    }
  }

  const ItemBufferOptions itemOptions_;
  const std::vector<int> frames_;
  const View view_;
  std::vector<Slot> slots_;
  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::mutex uploading_;  // held by the worker uploading the geometry (work)
  std::condition_variable changed_;
  size_t uploaded_ = 0;
  bool stop_ = false;
};

}  // namespace

void TextureIntervalsBuilder::addFrames(const std::vector<int>& frames, size_t renderers,
                                        const std::function<void(const IntervalFrame&)>& observer,
                                        const std::function<void()>& frameDone) {
  Impl& b = *impl_;
  if (renderers < 2 || frames.size() < 2) {
    for (int f : frames) {
      b.addFrame(f, observer);
      if (frameDone) frameDone();
    }
    return;
  }
  ItemBufferPipeline pipeline(std::min(renderers, frames.size()), b.grid(), b.itemBufferOptions(),
                              b.itemObjects(), frames, [&b](int f) { return b.frameView(f); });
  for (size_t i = 0; i < frames.size(); ++i) {
    const ItemBufferPipeline::Slot& s = pipeline.take(i);
    b.addRendered(s.view, s.buffer, s.seconds, observer);
    pipeline.release(i);
    if (frameDone) frameDone();
  }
}

TextureIntervalsBuilder::TextureIntervalsBuilder(const Scene& scene, int cameraNode,
                                                 TextureIntervalsOptions options)
    : impl_(std::make_unique<Impl>(scene, cameraNode, options)) {
  impl_->build();
}

TextureIntervalsBuilder::~TextureIntervalsBuilder() = default;

const PatchHierarchy& TextureIntervalsBuilder::hierarchy() const {
  return impl_->hierarchy();
}
int TextureIntervalsBuilder::nodeOfItem(uint32_t id) const {
  const SeenSubdivision& s = impl_->subdivision;
  if (id == kNoItem || !s.isLeafNumber(uint64_t(id) - 1)) return -1;
  return s.nodeOfLeafNumber(uint64_t(id) - 1);
}
uint64_t TextureIntervalsBuilder::numberOf(int node) const {
  return impl_->subdivision.numberOf(node);
}
uint64_t TextureIntervalsBuilder::fullNodeCount() const {
  return impl_->subdivision.fullNodeCount();
}
int TextureIntervalsBuilder::topsSeen() const {
  return impl_->subdivision.topsMade();
}
const TextureIntervalsOptions& TextureIntervalsBuilder::options() const {
  return impl_->options;
}
void TextureIntervalsBuilder::addFrame(int frame,
                                       const std::function<void(const IntervalFrame&)>& observer) {
  impl_->addFrame(frame, observer);
}
void TextureIntervalsBuilder::addVisibleSamples(
    int frame, const std::vector<uint32_t>& leaves, const std::vector<uint32_t>& counts,
    double itemBufferSeconds, const std::function<void(const IntervalFrame&)>& observer) {
  Impl& b = *impl_;
  b.setVisibleSamples(leaves, counts);
  b.addCounted(b.frameView(frame), nullptr, itemBufferSeconds, observer);
}
const std::vector<MovieExtent>& TextureIntervalsBuilder::movies() const {
  return impl_->movies;
}
double TextureIntervalsBuilder::itemBufferSeconds() const {
  return impl_->itemSeconds;
}
int TextureIntervalsBuilder::framesAdded() const {
  return impl_->frames;
}
long TextureIntervalsBuilder::moviesContinuedOverGaps() const {
  return impl_->continuedOverGaps;
}

std::vector<MovieExtent> TextureIntervalsBuilder::finish() {
  // Open movies keep end == kWindow and their last frame.
  std::vector<MovieExtent> out = impl_->movies;
  std::stable_sort(out.begin(), out.end(), [](const MovieExtent& a, const MovieExtent& b) {
    if (a.firstFrame != b.firstFrame) return a.firstFrame < b.firstFrame;
    return a.patch.packed() < b.patch.packed();
  });
  for (size_t i = 0; i < out.size(); ++i) out[i].movie = uint32_t(i);
  return out;
}

std::vector<MovieExtent> buildTextureIntervals(
    const Scene& scene, int cameraNode, const std::vector<int>& frames,
    const TextureIntervalsOptions& options,
    const std::function<void(const IntervalFrame&)>& observer) {
  TextureIntervalsBuilder b(scene, cameraNode, options);
  for (int f : frames) b.addFrame(f, observer);
  return b.finish();
}

}  // namespace rad
