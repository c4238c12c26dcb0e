// Frame composition (paper §3.1 last step). Contracts in frame_composer.h.
#include "libcommon/compose/frame_composer.h"
#include "libcommon/scene/emission_texture.h"
#include "libcommon/scene/gltf_item_label.h"
#include "libcommon/scene/texture_sampling.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "libcommon/compose/edge_cells.h"
#include "libcommon/compose/fallback_lamp_light.h"
#include "libcommon/compose/footprint_filter.h"
#include "libcommon/compose/smooth_surfaces.h"
#include "libcommon/compose/still_samples.h"
#include "libcommon/core/error.h"
#include "libcommon/radiosity/hierarchical_radiosity.h"
#include "libcommon/radiosity/scene_visibility.h"
#include "libcommon/scene/scene_emitters.h"

namespace rad {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Bilinear sample of a movie texture, whose texels hold the irradiance at their centres
// ((i+.5)/w, (j+.5)/h) (rad-movies bakes it there), carried linearly to the patch's border: in
// the outer half texel, beyond the last centres, each axis extrapolates its two outermost
// texels instead of holding the last one (GL's CLAMP_TO_EDGE). Irradiance is steepest at
// borders (concave corners, a floor by a lamp's foot: docs/design.md §6.4), and the held value
// was the largest error of the pixels along a polygon's edges. A side of one texel is constant;
// the result is never negative. With a second key `next`, each texel is first blended in float
// exactly as TextureMovie::textureAt blends the whole texture: (1 - weight) * rgb + weight * next.
glm::dvec3 sampleToBorder(const float* rgb, const float* next, float weight, int w, int h,
                          glm::dvec2 uv) {
  const double x = std::clamp(uv.x * w - 0.5, -0.5, w - 0.5);
  const double y = std::clamp(uv.y * h - 0.5, -0.5, h - 0.5);
  const int i0 = std::clamp(int(std::floor(x)), 0, std::max(w - 2, 0));
  const int j0 = std::clamp(int(std::floor(y)), 0, std::max(h - 2, 0));
  const int i1 = std::min(i0 + 1, w - 1), j1 = std::min(j0 + 1, h - 1);
  const double fx = w > 1 ? x - i0 : 0.0, fy = h > 1 ? y - j0 : 0.0;  // in [-.5, 1.5]
  const float keep = 1.0f - weight;
  auto at = [&](int i, int j) {
    const size_t o = (size_t(j) * w + i) * 3;
    const float* p = rgb + o;
    if (!next) return glm::dvec3(p[0], p[1], p[2]);
    const float* q = next + o;
    const float r = keep * p[0] + weight * q[0], g = keep * p[1] + weight * q[1],
                b = keep * p[2] + weight * q[2];
    return glm::dvec3(r, g, b);
  };
  return glm::max((1 - fy) * ((1 - fx) * at(i0, j0) + fx * at(i1, j0)) +
                      fy * ((1 - fx) * at(i0, j1) + fx * at(i1, j1)),
                  glm::dvec3(0.0));
}

// Active movie by packed patch id: open addressing with a multiplicative hash. Every covered
// pixel looks up each level of its descent; std::unordered_map's modulo by a prime was a
// visible share of rad-compose's per-pixel time.
class PatchIndex {
 public:
  explicit PatchIndex(size_t count) {
    size_t capacity = 16;
    while (capacity < 2 * count) capacity *= 2;
    shift_ = 64;
    for (size_t c = capacity; c > 1; c /= 2) --shift_;
    mask_ = capacity - 1;
    slots_.assign(capacity, Slot{kEmpty, 0});
  }
  void insert(uint64_t key, size_t value) {
    for (size_t i = slot(key);; i = (i + 1) & mask_) {
      if (slots_[i].key == kEmpty || slots_[i].key == key) {
        slots_[i] = Slot{key, value};  // a repeated patch: the last movie wins
        return;
      }
    }
  }
  long find(uint64_t key) const {
    for (size_t i = slot(key);; i = (i + 1) & mask_) {
      if (slots_[i].key == key) return long(slots_[i].value);
      if (slots_[i].key == kEmpty) return -1;
    }
  }

 private:
  static constexpr uint64_t kEmpty =
      ~uint64_t(0);  // no PatchId packs to this (path has a 1 marker)
  struct Slot {
    uint64_t key;
    size_t value;
  };
  size_t slot(uint64_t key) const { return size_t((key * 0x9E3779B97F4A7C15ull) >> shift_); }
  std::vector<Slot> slots_;
  size_t mask_ = 0;
  int shift_ = 60;
};

// The visible top-level patches' world polygons at the frame's time, with their normals and
// (u,v) maps, set up once per frame, not per pixel. Affine maps keep the (u,v)
// parameterisation, so the hit's (u,v) in the world polygon is its top-level (u,v).
struct VisibleTops {
  std::vector<Polygon> world;
  std::vector<glm::dvec3> normals;
  std::vector<PolygonUvMap> uvMaps;
};

// Active movies per top, by patch id; the deepest level per top bounds the descent.
struct ActiveMovies {
  PatchIndex movieOf;
  std::vector<int> deepest;
};

ActiveMovies indexMovies(const std::vector<MovieTexture>& movies, int topCount) {
  ActiveMovies a{PatchIndex(movies.size()), std::vector<int>(topCount, -1)};
  for (size_t k = 0; k < movies.size(); ++k) {
    const MovieTexture& mt = movies[k];
    if (mt.patch.top >= uint32_t(topCount) || !mt.irradiance || mt.width < 1 || mt.height < 1)
      throw Error(ExitCode::kInternal, "compose",
                  "movie of patch " + mt.patch.toString() + " is invalid for this scene");
    a.movieOf.insert(mt.patch.packed(), k);
    a.deepest[mt.patch.top] = std::max(a.deepest[mt.patch.top], mt.patch.level());
  }
  return a;
}

// The frame's movies with each one between two keys blended once, texel by texel, into `blended`
// (reused from frame to frame), with TextureMovie::textureAt's float arithmetic: a texel read by
// several samples (a texel covers about one pixel, nine samples) is blended once, not at each
// read, and a sample reads one texture instead of two. Bit-identical to blending as sampled.
std::vector<MovieTexture> blendKeys(const std::vector<MovieTexture>& movies,
                                    std::vector<float>& blended) {
  std::vector<size_t> offset(movies.size() + 1, 0);
  for (size_t k = 0; k < movies.size(); ++k) {
    const MovieTexture& mt = movies[k];
    const size_t floats = mt.nextIrradiance ? size_t(mt.width) * size_t(mt.height) * 3 : 0;
    offset[k + 1] = offset[k] + floats;
  }
  blended.resize(offset.back());
  std::vector<MovieTexture> out = movies;
  tbb::parallel_for(size_t(0), movies.size(), [&](size_t k) {
    const MovieTexture& mt = movies[k];
    if (!mt.nextIrradiance) return;
    const float weight = mt.weight, keep = 1.0f - weight;
    float* to = blended.data() + offset[k];
    for (size_t i = 0; i < offset[k + 1] - offset[k]; ++i)
      to[i] = keep * mt.irradiance[i] + weight * mt.nextIrradiance[i];
    out[k].irradiance = to;
    out[k].nextIrradiance = nullptr;
    out[k].weight = 0.0f;
  });
  return out;
}

// Per top, the packed patch ids of its active movies, sorted (StillSamples::beginFrame).
std::vector<std::vector<uint64_t>> moviePatchesByTop(const std::vector<MovieTexture>& movies,
                                                     size_t topCount) {
  std::vector<std::vector<uint64_t>> byTop(topCount);
  for (const MovieTexture& mt : movies) byTop[mt.patch.top].push_back(mt.patch.packed());
  for (std::vector<uint64_t>& ids : byTop) std::sort(ids.begin(), ids.end());
  return byTop;
}

// Top-level (u,v) of the hit point of the ray through image position `pixel` (a sample,
// sample_grid.h) with the patch's plane. (A ray parallel to the plane cannot hit it; its
// centroid stands in.)
glm::dvec2 topUvOfSample(const PrimaryRays& rays, glm::dvec2 pixel, const Polygon& poly,
                         const glm::dvec3& nrm, const PolygonUvMap& uvMap) {
  glm::dvec3 origin, direction;  // direction not unit length: its scale cancels in s
  rays.line(pixel, origin, direction);
  const double denom = glm::dot(nrm, direction);
  bool onPlane = false;
  glm::dvec3 hit;
  if (std::abs(denom) > 1e-300) {
    double s = glm::dot(nrm, poly.v[0] - origin) / denom;
    if (std::isfinite(s)) {
      hit = origin + s * direction;
      onPlane = true;
    }
  }
  if (!onPlane) hit = poly.centroid();
  return clampToParameterDomain(uvMap.uvAt(hit), poly.count == 3);
}

// Base colour texture factor tex(x) / mean(tex) (Material::reflectance already holds the
// mean) into `texFactor`; false (and 1) without a usable texture.
bool textureFactorAt(const Scene& scene, const Material& mat, const InputPolygon& top,
                     int cornerCount, glm::dvec2 topUv, glm::dvec3& texFactor) {
  texFactor = glm::dvec3(1.0);
  if (mat.baseColorTexture < 0 || mat.baseColorTexture >= int(scene.textures.size())) return false;
  const Texture& tex = scene.textures[mat.baseColorTexture];
  if (!hasPixels(tex)) return false;
  glm::dvec2 texUv = interpolateCorners(top.uv, cornerCount, topUv);
  glm::dvec3 c = sampleRepeat(tex, texUv);
  for (int a = 0; a < 3; ++a) texFactor[a] = tex.mean[a] > 0.0 ? c[a] / tex.mean[a] : 0.0;
  return true;
}

// The deepest active movie whose patch contains top-level (u,v) `topUv` of `top`, and the
// point's (u,v) in that movie's patch; -1 when none does.
int deepestMovieAt(const ActiveMovies& active, int top, glm::dvec2 topUv, bool triangle,
                   glm::dvec2& foundUv) {
  int found = -1;
  foundUv = glm::dvec2(0.0);
  if (active.deepest[top] < 0) return found;
  PatchId node{uint32_t(top), 1u};
  glm::dvec2 uv = topUv;
  for (int level = 0;; ++level) {
    const long k = active.movieOf.find(node.packed());
    if (k >= 0) {
      found = int(k);
      foundUv = uv;
    }
    if (level >= active.deepest[top]) break;
    node = node.child(descendToChild(uv, triangle));
  }
  return found;
}

}  // namespace

struct FrameComposer::Impl {
  const Scene& scene;
  const GlobalSolution& solution;
  ImageSize size;
  int cameraNode;
  PixelSampling sampling;
  SampleGrid grid;                          // sampling.grid(size)
  std::unique_ptr<FootprintFilter> filter;  // null: the pixel centres, unfiltered
  bool edgeCells = true;                    // weigh the edge cells by coverage (edge_cells.h)
  double edgeContrast = 0.0;                // EdgeCellInputs::minContrast
  std::vector<InputPolygon> tops;
  std::vector<int> objectNodes;        // mesh node of each item object
  std::vector<size_t> topObject;       // per top, its item object (index into transforms)
  std::vector<glm::dmat4> transforms;  // per object, at the current time
  std::vector<Material> materials;     // per top (default material where -1)
  // Per item id: the top's material has a base colour or an emissive texture (its radiance is
  // not smooth over the footprint: the filter shades its samples).
  std::vector<char> texturedItem;
  std::vector<glm::dvec3> topEmission;  // per top: its mean L_e (meanEmissionOver)
  ItemBufferRenderer renderer;
  ItemBuffer items;                           // of the sample grid
  std::unique_ptr<SceneVisibility> rayScene;  // refineSilhouettes' rays, made on first use
  FallbackLampLight lampLight;                // the lamps at fallback samples
  std::vector<uint8_t> edgeMask;              // refineSilhouettes': samples with another neighbour
  std::vector<float> sampleRgb;               // filtered frames: radiance of the grid's samples
  std::vector<PixelSource> sampleSource;
  std::vector<uint8_t> edgeCandidates;  // weighEdgeCells': the edge samples
  std::vector<float> blendedKeys;       // blendKeys' textures of the frame
  // Filtered frames with edge cells: per grid sample, its smooth surface (smooth_surfaces.h).
  std::vector<uint32_t> surfaceIds;
  SmoothSurfaces surfaces;
  StillSamples still;  // the samples' geometry kept from frame to frame

  // The named steps of FrameComposer::compose, in order.
  CameraView renderItems(double t);
  // The shadow rays' scene at time t (made on first use), for silhouettes and lamps.
  SceneVisibility& raysAt(double t);
  // Returns the samples it looked at: those whose id differed from a 4-neighbour's.
  // `ids`: the buffer whose neighbours are compared (the items, or the smooth surfaces).
  std::vector<size_t> refineSilhouettes(double t, const PrimaryRays& rays,
                                        const std::vector<uint32_t>& ids);
  // The samples' smooth surfaces into surfaceIds.
  void markSurfaces(const VisibleTops& visible);
  void placeVisibleTops(VisibleTops& visible) const;
  glm::dvec3 fallbackRadiance(double t, const VisibleTops& visible, int top, glm::dvec2 topUv,
                              const glm::dvec3& emitted, const glm::dvec3& texFactor,
                              bool textured) const;
  // Sample `sample` (a grid index) at image position `pixel`, showing top-level patch `top`.
  PixelSource shadeSample(double t, const std::vector<MovieTexture>& movies,
                          const VisibleTops& visible, const ActiveMovies& active,
                          const PrimaryRays& rays, size_t sample, glm::dvec2 pixel, int top,
                          float* rgb);
  // The top-level (u,v) of a sample and its deepest movie, from `still` where they hold.
  glm::dvec2 sampleTopUv(const VisibleTops& visible, const PrimaryRays& rays, size_t sample,
                         glm::dvec2 pixel, int top, bool& kept);
  int sampleMovie(const std::vector<MovieTexture>& movies, const ActiveMovies& active,
                  size_t sample, bool keptTopUv, int top, glm::dvec2 topUv, glm::dvec2& foundUv);
  void composeFiltered(double t, const std::vector<MovieTexture>& movies,
                       const VisibleTops& visible, const ActiveMovies& active,
                       const CameraView& view, const PrimaryRays& rays,
                       const std::vector<size_t>& edges, ComposedFrame& out);
  // After the samples are shaded: the filter's edge cells (edge_cells.h), among the samples
  // whose id differs from a neighbour's.
  void weighEdgeCells(const VisibleTops& visible, const CameraView& view, const PrimaryRays& rays,
                      const std::vector<size_t>& edges);

  Impl(const Scene& s, const GlobalSolution& g, ImageSize sz, int cam, const PixelSampling& ps,
       bool everySample, bool edgeCoverage, double minContrast)
      : scene(s),
        solution(g),
        size(sz),
        cameraNode(cam),
        sampling(ps),
        grid(ps.grid(sz)),
        filter(ps.filter.isNone() ? nullptr
                                  : std::make_unique<FootprintFilter>(ps, sz, everySample)),
        edgeCells(edgeCoverage),
        edgeContrast(minContrast),
        tops(s.inputPolygons()),
        renderer(grid, ItemBufferOptions{true, false}),  // ids only: compose reads no depth
        lampLight(s, g) {
    if (cam < 0 || cam >= int(s.nodes.size()) || s.nodes[cam].camera < 0)
      throw inputError(s.path, nodeLabel(s, cam) + " is not a camera");
    if (g.hierarchy.topCount() != int(tops.size()))
      throw inputError(s.path, "global solution has " + std::to_string(g.hierarchy.topCount()) +
                                   " top-level patches; the scene has " +
                                   std::to_string(tops.size()));
    // One item object per mesh node (rigid body), item id = top-level index + 1.
    std::unordered_map<int, size_t> objectOf;
    std::vector<ItemObject> objects;
    for (size_t i = 0; i < tops.size(); ++i) {
      int node = tops[i].node;
      auto it = objectOf.find(node);
      if (it == objectOf.end()) {
        it = objectOf.emplace(node, objects.size()).first;
        objects.emplace_back();
        objectNodes.push_back(node);
      }
      topObject.push_back(it->second);
      objects[it->second].addPolygon(tops[i].local, uint32_t(i + 1));
      int m = tops[i].material;
      materials.push_back(m >= 0 && m < int(s.materials.size()) ? s.materials[m] : Material{});
    }
    texturedItem.assign(tops.size() + 1, 0);
    topEmission.resize(tops.size());
    for (size_t i = 0; i < tops.size(); ++i) {
      const int tex = materials[i].baseColorTexture;
      texturedItem[i + 1] =
          (tex >= 0 && tex < int(s.textures.size())) || hasEmissiveTexture(s, materials[i]);
      topEmission[i] = meanEmissionOver(s, tops[i]);
    }
    renderer.setGeometry(objects);
    transforms.resize(objects.size());
  }
};

FrameComposer::FrameComposer(const Scene& scene, const GlobalSolution& solution, ImageSize size,
                             int cameraNode, const PixelSampling& sampling, bool everySample,
                             bool edgeCoverage, double edgeContrast)
    : impl_(std::make_unique<Impl>(scene, solution, size, cameraNode, sampling, everySample,
                                   edgeCoverage, edgeContrast)) {}

FrameComposer::~FrameComposer() = default;

ImageSize FrameComposer::size() const {
  return impl_->size;
}

ComposedFrame FrameComposer::compose(double t, const std::vector<MovieTexture>& movies) {
  ComposedFrame out;
  compose(t, movies, out);
  return out;
}

// Visibility: the item buffer at time t, the object transforms left in `transforms`.
CameraView FrameComposer::Impl::renderItems(double t) {
  CameraView view = scene.cameraAt(cameraNode, t);
  for (size_t k = 0; k < objectNodes.size(); ++k)
    transforms[k] = scene.worldTransform(objectNodes[k], t);
  renderer.render(view, transforms, items);
  return view;
}

SceneVisibility& FrameComposer::Impl::raysAt(double t) {
  if (!rayScene) {
    const std::vector<double>& k = solution.keyTimes;
    rayScene = std::make_unique<SceneVisibility>(scene, solution.hierarchy, k.front(), k.back());
  }
  rayScene->setTime(t);
  return *rayScene;
}

// The item buffer's silhouettes decided by the pixel centre's ray. GL rasterizes with a few bits of
// sub-pixel precision (llvmpipe: 8), so a silhouette edge that passes within ~1/256 pixel of a
// centre can give the pixel either surface, while rad-reference --pixel-filter none (and a
// renderer's first hit) takes the surface the centre's ray meets first. Such pixels are few but far
// off (the Cornell box: the wall behind a box's top edge, much brighter than the box). A pixel
// whose item differs from a 4-neighbour's casts that ray (Embree, the scene's patches at t) and
// takes the patch it meets when that patch faces the camera, as the rasterizer's back-face rule
// would; a pixel whose ray meets nothing, or a back face, keeps its item. A filtered frame whose
// edge cells are weighed by coverage casts no ray: a cell whose sample is that close to an edge
// takes each side's share of it from the polygons' outlines (edge_cells.h), whichever item the
// sample shows, and the item buffer's ids are then rad-intervals' own, so no sample falls back.
std::vector<size_t> FrameComposer::Impl::refineSilhouettes(double t, const PrimaryRays& rays,
                                                           const std::vector<uint32_t>& ids) {
  const int w = items.width, h = items.height;  // the sample grid's (sample_grid.h)
  // Each pair of neighbours compared once (right, below), both marked when they differ; then
  // the marked samples in row-major order.
  edgeMask.assign(ids.size(), 0);
  const uint32_t* id = ids.data();
  for (int row = 0; row < h; ++row) {
    const size_t r = size_t(row) * w;
    for (int col = 0; col + 1 < w; ++col)
      if (id[r + col] != id[r + col + 1]) edgeMask[r + col] = edgeMask[r + col + 1] = 1;
    if (row + 1 < h)
      for (int col = 0; col < w; ++col)
        if (id[r + col] != id[r + w + col]) edgeMask[r + col] = edgeMask[r + w + col] = 1;
  }
  std::vector<size_t> edge;
  for (size_t p = 0; p < edgeMask.size(); ++p)
    if (edgeMask[p]) edge.push_back(p);
  if (edge.empty() || (filter && edgeCells)) return edge;
  raysAt(t);
  std::vector<uint32_t> decided(edge.size());
  tbb::parallel_for(size_t(0), edge.size(), [&](size_t e) {
    const size_t p = edge[e];
    decided[e] = items.id[p];
    const Ray ray = rays.at(grid.position(int(p % size_t(w)), int(p / size_t(w))));
    const uint32_t hit = rayScene->visibility().firstHit(ray.origin, ray.direction);
    if (hit == VisibilityScene::kNoSurface || hit >= uint32_t(tops.size())) return;
    const Polygon world = tops[hit].local.transformed(transforms[topObject[hit]]);
    // A double-sided material is two one-sided patches at the same place (the reversed copy):
    // only the one facing the camera is what the rasterizer shows.
    if (glm::dot(world.normal(), ray.direction) < 0.0) decided[e] = hit + 1;
  });
  for (size_t e = 0; e < edge.size(); ++e) items.id[edge[e]] = decided[e];
  return edge;
}

void FrameComposer::Impl::markSurfaces(const VisibleTops& visible) {
  std::vector<int> material(tops.size());
  for (size_t i = 0; i < tops.size(); ++i) material[i] = tops[i].material;
  surfaces = smoothSurfaces(visible.world, visible.normals, material, topObject, texturedItem);
  surfaceIds.resize(items.id.size());
  const uint32_t* of = surfaces.surfaceOf.data();
  for (size_t p = 0; p < items.id.size(); ++p) surfaceIds[p] = of[items.id[p]];
}

void FrameComposer::Impl::placeVisibleTops(VisibleTops& v) const {
  const int topCount = int(tops.size());
  v.world.assign(topCount, Polygon{});
  v.normals.assign(topCount, glm::dvec3(0.0));
  v.uvMaps.assign(topCount, PolygonUvMap{});
  std::vector<char> seen(topCount, 0);
  for (uint32_t id : items.id)
    if (id != kNoItem) seen[id - 1] = 1;
  for (int i = 0; i < topCount; ++i)
    if (seen[i]) {
      v.world[i] = tops[i].local.transformed(transforms[topObject[size_t(i)]]);
      v.normals[i] = v.world[i].normal();
      v.uvMaps[i] = PolygonUvMap(v.world[i]);
    }
}

void FrameComposer::compose(double t, const std::vector<MovieTexture>& movies, ComposedFrame& out) {
  Impl& m = *impl_;
  const ImageSize size = m.size;
  const CameraView view = m.renderItems(t);
  // The frame's primary rays (the lens is validated here, once).
  const PrimaryRays rays(view, size);
  // Where edge cells are weighed no id changes and the filter sees the smooth surfaces
  // (smooth_surfaces.h); otherwise the silhouettes are re-decided first.
  const bool bySurface = m.filter && m.edgeCells;
  VisibleTops visible;
  if (bySurface) {
    m.placeVisibleTops(visible);
    m.markSurfaces(visible);
  }
  const std::vector<size_t> edges =
      m.refineSilhouettes(t, rays, bySurface ? m.surfaceIds : m.items.id);
  if (!bySurface) m.placeVisibleTops(visible);
  const ActiveMovies active = indexMovies(movies, int(m.tops.size()));
  const std::vector<MovieTexture> keyed = blendKeys(movies, m.blendedKeys);
  m.still.beginFrame(view, m.transforms, moviePatchesByTop(movies, m.tops.size()),
                     m.items.id.size());
  if (!m.lampLight.empty()) m.lampLight.setTime(t, m.raysAt(t).visibility());

  out.size = size;
  out.time = t;
  const size_t n = size_t(size.pixelCount());
  out.rgb.assign(n * 3, 0.0f);
  out.source.assign(n, PixelSource::kBackground);
  if (m.filter) {
    if (bySurface)
      m.filter->plan(m.surfaceIds, edges, m.surfaces.fullSurface);
    else
      m.filter->plan(m.items.id, edges, m.texturedItem);
    m.composeFiltered(t, keyed, visible, active, view, rays, edges, out);
    return;
  }
  std::vector<long long> rowMovie(size.height, 0), rowFallback(size.height, 0),
      rowCovered(size.height, 0);

  tbb::parallel_for(tbb::blocked_range<int>(0, size.height), [&](const tbb::blocked_range<int>& r) {
    for (int row = r.begin(); row < r.end(); ++row) {
      for (int col = 0; col < size.width; ++col) {
        size_t p = size_t(row) * size.width + col;
        uint32_t id = m.items.id[p];
        if (id == kNoItem) continue;
        ++rowCovered[row];
        const PixelSource source =
            m.shadeSample(t, keyed, visible, active, rays, p, m.grid.position(col, row),
                          int(id - 1), &out.rgb[p * 3]);
        out.source[p] = source;
        ++(source == PixelSource::kMovie ? rowMovie : rowFallback)[row];
      }
    }
  });
  out.coveredPixels = out.moviePixels = out.fallbackPixels = 0;
  for (int row = 0; row < size.height; ++row) {
    out.coveredPixels += rowCovered[row];
    out.moviePixels += rowMovie[row];
    out.fallbackPixels += rowFallback[row];
  }
}

// The filtered frame (footprint_filter.h): the samples the filter reads are shaded, then each
// pixel is filtered from them. A pixel counts as covered when a sample it reads shows a
// surface, as fallen back when one of them fell back, as a movie pixel otherwise. The filter
// has planned this item buffer (compose).
void FrameComposer::Impl::composeFiltered(double t, const std::vector<MovieTexture>& movies,
                                          const VisibleTops& visible, const ActiveMovies& active,
                                          const CameraView& view, const PrimaryRays& rays,
                                          const std::vector<size_t>& edges, ComposedFrame& out) {
  const std::vector<uint8_t>& needed = filter->needed();
  const int gw = items.width, gh = items.height;
  // Only the needed samples are written and read: no fill of the whole grid.
  sampleRgb.resize(needed.size() * 3);
  sampleSource.resize(needed.size());
  // A sample shaded, or the background's 0.
  auto shade = [&](int i, int j, size_t p) {
    const uint32_t id = items.id[p];
    if (id == kNoItem) {
      std::fill_n(&sampleRgb[3 * p], 3, 0.0f);
      sampleSource[p] = PixelSource::kBackground;
    } else {
      sampleSource[p] = shadeSample(t, movies, visible, active, rays, p, grid.position(i, j),
                                    int(id - 1), &sampleRgb[3 * p]);
    }
  };
  // Two passes over the grid's pixels: the centres and the samples that cannot be interpolated
  // are shaded, then the others are interpolated from the centres (footprint_filter.h).
  const int s = grid.perAxis, mid = (s - 1) / 2;
  const int pw = gw / s, ph = gh / s;
  // The ids plan() saw: the smooth surfaces where edge cells are weighed.
  const std::vector<uint32_t>& planned = edgeCells ? surfaceIds : items.id;
  auto sameSurface = [&](size_t p, size_t q) { return planned[p] == planned[q]; };
  for (const bool second : {false, true})
    tbb::parallel_for(tbb::blocked_range<int>(0, ph), [&](const tbb::blocked_range<int>& r) {
      for (int py = r.begin(); py < r.end(); ++py)
        for (int px = 0; px < pw; ++px) {
          const int ci = px * s + mid, cj = py * s + mid;
          const size_t centre = size_t(cj) * gw + size_t(ci);
          if (!filter->offCentreNeeded(px, py)) {  // the centre alone
            if (!second && needed[centre]) shade(ci, cj, centre);
            continue;
          }
          const bool smooth = filter->smooth(px, py);
          if (second && !smooth) continue;
          for (int j = py * s; j < (py + 1) * s; ++j)
            for (int i = px * s; i < (px + 1) * s; ++i) {
              const size_t p = size_t(j) * gw + i;
              if (!needed[p]) continue;
              const bool interpolated = smooth && p != centre && sameSurface(p, centre);
              if (interpolated != second) continue;
              if (interpolated) {
                filter->interpolate(i, j, sampleRgb.data(), &sampleRgb[3 * p]);
                sampleSource[p] = sampleSource[centre];
              } else {
                shade(i, j, p);
              }
            }
        }
    });
  if (edgeCells) weighEdgeCells(visible, view, rays, edges);
  static_assert(sizeof(PixelSource) == 1, "sample sources are read as bytes");
  const auto* tags = reinterpret_cast<const uint8_t*>(sampleSource.data());
  std::vector<long long> rowMovie(size.height, 0), rowFallback(size.height, 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, size.height), [&](const tbb::blocked_range<int>& r) {
    for (int row = r.begin(); row < r.end(); ++row)
      for (int col = 0; col < size.width; ++col) {
        const size_t p = size_t(row) * size.width + col;
        // The largest source read: fallback > movie > background.
        const auto source =
            PixelSource(filter->filterPixel(sampleRgb.data(), tags, col, row, &out.rgb[3 * p]));
        out.source[p] = source;
        if (source != PixelSource::kBackground)
          ++(source == PixelSource::kMovie ? rowMovie : rowFallback)[row];
      }
  });
  out.moviePixels = out.fallbackPixels = 0;
  for (int row = 0; row < size.height; ++row) {
    out.moviePixels += rowMovie[row];
    out.fallbackPixels += rowFallback[row];
  }
  out.coveredPixels = out.moviePixels + out.fallbackPixels;
}

void FrameComposer::Impl::weighEdgeCells(const VisibleTops& visible, const CameraView& view,
                                         const PrimaryRays& rays,
                                         const std::vector<size_t>& edges) {
  // refineSilhouettes cast no ray (edge cells are weighed): `edges` are the samples whose id
  // differs from a 4-neighbour's, the edge cells' candidates.
  edgeCandidates.assign(items.id.size(), 0);
  for (size_t p : edges) edgeCandidates[p] = 1;
  const EdgeCellInputs in{
      grid, items.id, filter->needed(), sampleRgb.data(), visible.world, visible.normals,
      view, rays,     edgeContrast};
  filter->setEdgeCells(findEdgeCells(in, edgeCandidates));
}

// A sample no movie textures: the union leaf's radiosity, $L = B / \pi$; with a texture, the
// reflected part modulated (B holds the patch's mean emission, emission_texture.h); with lamps,
// their leaf average replaced by the point's direct light (fallback_lamp_light.h).
glm::dvec3 FrameComposer::Impl::fallbackRadiance(double t, const VisibleTops& visible, int top,
                                                 glm::dvec2 topUv, const glm::dvec3& emitted,
                                                 const glm::dvec3& texFactor, bool textured) const {
  const int leaf = leafAtTopUv(solution.hierarchy, top, topUv);
  const glm::dvec3 B = solution.radiosity(leaf, t);
  if (lampLight.empty()) {
    if (textured)
      return emitted + texFactor * glm::max(B / kPi - topEmission[size_t(top)], glm::dvec3(0.0));
    return B / kPi;
  }
  const glm::dmat4& toWorld = transforms[topObject[size_t(top)]];
  const glm::dvec3 x =
      glm::dvec3(toWorld * glm::dvec4(solution.hierarchy.pointAt(top, topUv), 1.0));
  const Polygon leafWorld = solution.hierarchy.node(leaf).local.transformed(toWorld);
  const FallbackLampLight::Terms lamps =
      lampLight.at(leaf, leafWorld, x, visible.normals[size_t(top)], top);
  const glm::dvec3 rhoOverPi = materials[size_t(top)].reflectance / kPi;
  const glm::dvec3 indirect =
      glm::max(B / kPi - topEmission[size_t(top)] - rhoOverPi * lamps.leafAverage, glm::dvec3(0.0));
  return emitted + texFactor * (indirect + rhoOverPi * lamps.atPoint);
}

// One covered sample at image position `pixel` on top-level patch `top`: its radiance into
// rgb[0..2], from the deepest active movie containing the point, else from the global solution.
glm::dvec2 FrameComposer::Impl::sampleTopUv(const VisibleTops& visible, const PrimaryRays& rays,
                                            size_t sample, glm::dvec2 pixel, int top, bool& kept) {
  glm::dvec2 topUv;
  const uint32_t id = uint32_t(top) + 1;
  kept = still.topUv(sample, id, topObject[size_t(top)], topUv);
  if (kept) return topUv;
  topUv = topUvOfSample(rays, pixel, visible.world[size_t(top)], visible.normals[size_t(top)],
                        visible.uvMaps[size_t(top)]);
  if (still.enabled()) still.setTopUv(sample, id, topUv);
  return topUv;
}

int FrameComposer::Impl::sampleMovie(const std::vector<MovieTexture>& movies,
                                     const ActiveMovies& active, size_t sample, bool keptTopUv,
                                     int top, glm::dvec2 topUv, glm::dvec2& foundUv) {
  uint64_t patch;
  // The same set of movies on the top: the descent ends at the same patch (the index's find is
  // the descent's own).
  if (keptTopUv && still.movie(sample, uint32_t(top), patch, foundUv))
    return int(active.movieOf.find(patch));
  const int found = deepestMovieAt(active, top, topUv, tops[size_t(top)].local.count == 3, foundUv);
  if (found >= 0 && still.enabled())
    still.setMovie(sample, movies[size_t(found)].patch.packed(), foundUv);
  return found;
}

PixelSource FrameComposer::Impl::shadeSample(double t, const std::vector<MovieTexture>& movies,
                                             const VisibleTops& visible, const ActiveMovies& active,
                                             const PrimaryRays& rays, size_t sample,
                                             glm::dvec2 pixel, int top, float* rgb) {
  const Polygon& poly = visible.world[top];
  const Material& mat = materials[top];
  bool keptTopUv;
  const glm::dvec2 topUv = sampleTopUv(visible, rays, sample, pixel, top, keptTopUv);
  glm::dvec3 texFactor;
  const bool textured = textureFactorAt(scene, mat, tops[top], poly.count, topUv, texFactor);
  // $L_e(x)$: the emissive texture per sample (emission_texture.h), else the material's.
  const bool emissiveTextured = hasEmissiveTexture(scene, mat);
  const glm::dvec3 emitted =
      emissiveTextured ? emissionAt(scene, mat, interpolateCorners(tops[top].uv, poly.count, topUv))
                       : mat.emission;
  glm::dvec2 foundUv;
  const int found = sampleMovie(movies, active, sample, keptTopUv, top, topUv, foundUv);

  glm::dvec3 L;
  PixelSource source;
  if (found >= 0) {
    // $L = L_e + \frac{\rho(x)}{\pi} H(x)$
    const MovieTexture& mt = movies[size_t(found)];
    glm::dvec3 H =
        sampleToBorder(mt.irradiance, mt.nextIrradiance, mt.weight, mt.width, mt.height, foundUv);
    L = emitted + (mat.reflectance * texFactor / kPi) * H;
    source = PixelSource::kMovie;
  } else {
    L = fallbackRadiance(t, visible, top, topUv, emitted, texFactor, textured || emissiveTextured);
    source = PixelSource::kFallback;
  }
  for (int a = 0; a < 3; ++a) rgb[a] = std::isfinite(L[a]) ? float(std::max(L[a], 0.0)) : 0.0f;
  return source;
}

double autoExposureEV(const Scene& scene, const GlobalSolution& solution, double percentile) {
  const PatchHierarchy& h = solution.hierarchy;
  const SceneEmitters emitters(scene, h.tops());   // the lights are left out of the exposure
  std::vector<std::pair<double, double>> lumArea;  // (luminance of B/pi, area)
  for (int i = 0; i < h.size(); ++i) {
    if (!h.isLeaf(i)) continue;
    if (emitters.topEmits(int(h.node(i).id.top))) continue;
    double area = h.node(i).local.area();
    if (!(area > 0.0)) continue;
    for (int k = 0; k < solution.keyCount(); ++k) {
      double y = luminance(solution.radiosityAtKey(i, k) / kPi);
      if (std::isfinite(y) && y > 0.0) lumArea.push_back({y, area});
    }
  }
  if (lumArea.empty()) return 0.0;
  std::sort(lumArea.begin(), lumArea.end());
  double total = 0.0;
  for (const auto& la : lumArea) total += la.second;
  double target = std::clamp(percentile, 0.0, 1.0) * total, acc = 0.0;
  double y = lumArea.back().first;
  for (const auto& la : lumArea) {
    acc += la.second;
    if (acc >= target) {
      y = la.first;
      break;
    }
  }
  return -std::log2(y);
}

}  // namespace rad
