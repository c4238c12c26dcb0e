// rad-compose's still samples (libcommon/compose/still_samples.h): under a still camera a sample
// keeps its top-level (u,v) and its deepest movie from frame to frame, and a frame composed so must
// be bit-identical to one composed from scratch, also when a top's movies change level, when the
// textures change, and when the camera or an object moves between frames.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "libcommon/compose/frame_composer.h"
#include "libcommon/compose/still_samples.h"
#include "tests/unit/compose_fixture.h"

namespace rad {
namespace {

constexpr ImageSize kSize{40, 26};

// Two walls at z = -5 facing the camera at the origin (two mesh nodes, so two objects), the
// left one a quad, the right one a triangle, with the camera node last.
Scene twoWalls() {
  Scene s;
  s.path = "still";
  Material m;
  m.reflectance = glm::dvec3(0.5, 0.4, 0.3);
  s.materials = {m};
  const std::vector<std::vector<glm::dvec3>> walls = {
      {{-4, -3, -5}, {0.3, -3, -5}, {0.3, 3, -5}, {-4, 3, -5}},
      {{0.3, -3, -5}, {4, -3, -5}, {0.3, 3, -5}}};
  for (const std::vector<glm::dvec3>& w : walls) {
    Mesh mesh;
    for (size_t k = 1; k + 1 < w.size(); ++k) {
      MeshTriangle t;
      t.p = {w[0], w[k], w[k + 1]};
      t.material = 0;
      mesh.triangles.push_back(t);
    }
    Node node;
    node.mesh = int(s.meshes.size());
    s.meshes.push_back(mesh);
    s.nodes.push_back(node);
  }
  Camera lens;
  lens.name = "cam";
  lens.yfov = 0.8;
  lens.znear = 0.01;
  s.cameras.push_back(lens);
  Node cam;
  cam.name = "cam";
  cam.camera = 0;
  s.nodes.push_back(cam);
  return s;
}

// A w x h texture whose texels differ (so a wrong texel or (u,v) shows), scaled by `scale`.
std::vector<float> texture(int w, int h, float scale) {
  std::vector<float> t;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i)
      for (int c = 0; c < 3; ++c) t.push_back(scale * float(1 + i + 7 * j + 3 * c));
  return t;
}

TEST(StillSamples, FramesAreThoseComposedFromScratch) {
  const Scene scene = twoWalls();
  const GlobalSolution solution =
      test::makeSolution(scene, {0.0}, false, [](int, int) { return glm::dvec3(0.25); });
  const int tops = int(scene.inputPolygons().size());
  ASSERT_GE(tops, 2);
  const std::vector<float> a0 = texture(5, 4, 1.0f), a1 = texture(5, 4, 1.5f),
                           b0 = texture(3, 3, 2.0f), child = texture(2, 3, 0.5f);
  // The last top (the triangle) is shown by its level-0 movie, then by two of its children with
  // the rest falling back, then by its level-0 movie again; the quads' movie blends its keys.
  const PatchId quad{0, 1}, tri{uint32_t(tops - 1), 1};
  const std::vector<std::vector<MovieTexture>> frames = {
      {{quad, 5, 4, a0.data()}, {tri, 3, 3, b0.data()}},
      {{quad, 5, 4, a0.data(), a1.data(), 0.25f},
       {tri.child(0), 2, 3, child.data()},
       {tri.child(3), 2, 3, child.data()}},
      {{quad, 5, 4, a0.data(), a1.data(), 0.75f},
       {tri.child(0), 2, 3, child.data()},
       {tri.child(3), 2, 3, child.data()}},
      {{quad, 5, 4, a1.data()}, {tri, 3, 3, b0.data()}},
      {{quad, 5, 4, a1.data()}, {tri, 3, 3, b0.data()}}};
  for (const PixelSampling& sampling :
       {PixelSampling{PixelFilter{}, 3}, PixelSampling::pixelCentres()}) {
    FrameComposer kept(scene, solution, kSize, scene.cameraNode(""), sampling);
    for (size_t f = 0; f < frames.size(); ++f) {
      const ComposedFrame frame = kept.compose(0.0, frames[f]);
      FrameComposer fresh(scene, solution, kSize, scene.cameraNode(""), sampling);
      const ComposedFrame scratch = fresh.compose(0.0, frames[f]);
      EXPECT_EQ(frame.rgb, scratch.rgb) << sampling.toString() << ", frame " << f;
      EXPECT_EQ(frame.fallbackPixels, scratch.fallbackPixels);
      EXPECT_GT(frame.moviePixels, 0);
    }
  }
}

TEST(StillSamples, KeepsOnlyWhatHasNotMoved) {
  CameraView view;
  std::vector<glm::dmat4> objects(2, glm::dmat4(1.0));
  const std::vector<std::vector<uint64_t>> movies = {{PatchId{0, 1}.packed()},
                                                     {PatchId{1, 1}.packed()}};
  StillSamples still;
  glm::dvec2 uv;
  uint64_t patch;
  still.beginFrame(view, objects, movies, 4);
  EXPECT_FALSE(still.enabled());  // no last frame
  still.beginFrame(view, objects, movies, 4);
  ASSERT_TRUE(still.enabled());
  EXPECT_FALSE(still.topUv(0, 1, 0, uv));  // nothing recorded yet
  still.setTopUv(0, 1, glm::dvec2(0.25, 0.5));
  still.setMovie(0, movies[0][0], glm::dvec2(0.5, 1.0));
  still.setTopUv(1, 2, glm::dvec2(0.75, 0.5));
  still.setMovie(1, movies[1][0], glm::dvec2(0.5, 0.5));

  still.beginFrame(view, objects, movies, 4);  // nothing moved
  ASSERT_TRUE(still.topUv(0, 1, 0, uv));
  EXPECT_EQ(uv, glm::dvec2(0.25, 0.5));
  ASSERT_TRUE(still.movie(0, 0, patch, uv));
  EXPECT_EQ(patch, movies[0][0]);
  EXPECT_EQ(uv, glm::dvec2(0.5, 1.0));
  EXPECT_FALSE(still.topUv(0, 2, 1, uv));  // another item at the sample

  std::vector<std::vector<uint64_t>> changed = movies;
  changed[1] = {PatchId{1, 1}.child(0).packed()};
  objects[0][3][0] = 1e-9;                      // object 0 moved
  still.beginFrame(view, objects, changed, 4);  // sample 1's top changed its movies
  EXPECT_FALSE(still.topUv(0, 1, 0, uv));
  ASSERT_TRUE(still.topUv(1, 2, 1, uv));
  EXPECT_FALSE(still.movie(1, 1, patch, uv));

  still.beginFrame(view, objects, changed, 4);  // still again: sample 0 was not recorded since
  EXPECT_FALSE(still.topUv(0, 1, 0, uv));
  ASSERT_TRUE(still.topUv(1, 2, 1, uv));
  EXPECT_FALSE(still.movie(1, 1, patch, uv));  // recorded before its movies changed

  CameraView moved = view;
  moved.worldFromCamera[3][2] = 1e-12;
  still.beginFrame(moved, objects, changed, 4);
  EXPECT_FALSE(still.enabled());
  still.beginFrame(moved, objects, changed, 4);
  ASSERT_TRUE(still.enabled());
  EXPECT_FALSE(still.topUv(1, 2, 1, uv));  // recorded before the camera moved
}

}  // namespace
}  // namespace rad
