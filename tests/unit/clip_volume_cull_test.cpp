#include "libcommon/gl/clip_volume_cull.h"

#include <cmath>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include "libcommon/gl/item_buffer.h"
#include "libcommon/scene/camera_projection.h"

namespace rad {
namespace {

constexpr ImageSize kSize{64, 48};

CameraView axisCamera() {
  CameraView v;
  v.lens.yfov = 0.8;
  v.lens.znear = 0.1;
  return v;  // at the origin, looking down -Z
}

glm::mat4 clipAt(const glm::dvec3& translation) {
  return rasterClipFromLocal(axisCamera(), kSize, glm::translate(glm::dmat4(1.0), translation));
}

// The image's left edge at depth 5 lies at x = -5 tan(yfov / 2) * aspect.
double leftEdgeAtDepth5() {
  return -5.0 * std::tan(0.4) * double(kSize.width) / double(kSize.height);
}

const LocalBounds kUnitBox{glm::vec3(0.0f), glm::vec3(1.0f)};

TEST(ClipVolumeCull, BoxBesideTheViewIsOutside) {
  EXPECT_TRUE(outsideClipVolume(clipAt({leftEdgeAtDepth5() - 1.5, 0.0, -5.0}), kUnitBox));
  EXPECT_TRUE(outsideClipVolume(clipAt({0.0, 4.0, -5.0}), kUnitBox));  // above
}

TEST(ClipVolumeCull, BoxInOrAcrossTheViewIsKept) {
  EXPECT_FALSE(outsideClipVolume(clipAt({-0.5, -0.5, -5.0}), kUnitBox));
  // Across the left edge, and with corners on it (at depth 5, x = the edge; the rest outside):
  // either may draw samples.
  EXPECT_FALSE(outsideClipVolume(clipAt({leftEdgeAtDepth5() - 0.5, 0.0, -5.0}), kUnitBox));
  EXPECT_FALSE(outsideClipVolume(clipAt({leftEdgeAtDepth5() - 1.0, 0.0, -5.0}), kUnitBox));
  EXPECT_TRUE(outsideClipVolume(clipAt({leftEdgeAtDepth5() - 1.001, 0.0, -5.0}), kUnitBox));
  // Around the eye (corners behind and in front of it).
  EXPECT_FALSE(outsideClipVolume(clipAt({-0.5, -0.5, -0.5}), kUnitBox));
}

TEST(ClipVolumeCull, BoxBehindTheEyeIsOutside) {
  EXPECT_TRUE(outsideClipVolume(clipAt({-0.5, -0.5, 3.0}), kUnitBox));
}

TEST(ClipVolumeCull, EmptyBoundsAreOutside) {
  const LocalBounds empty{glm::vec3(INFINITY), glm::vec3(-INFINITY)};
  EXPECT_TRUE(outsideClipVolume(clipAt({0.0, 0.0, -5.0}), empty));
}

// The renderer skips objects outside the view: the ids of the ones inside are as drawn alone.
TEST(ClipVolumeCull, ItemBufferUnchangedByObjectsOutside) {
  ItemObject inside, outside;
  Polygon quad;
  quad.count = 4;
  quad.v = {glm::dvec3(-1, -1, -5), glm::dvec3(1, -1, -5), glm::dvec3(1, 1, -5),
            glm::dvec3(-1, 1, -5)};
  inside.addPolygon(quad, 7);
  outside.addPolygon(quad, 9);
  ItemBufferRenderer renderer(kSize);
  renderer.setGeometry({inside});
  const ItemBuffer alone = renderer.render(axisCamera(), {glm::dmat4(1.0)});
  renderer.setGeometry({outside, inside, outside});
  const glm::dmat4 away = glm::translate(glm::dmat4(1.0), glm::dvec3(40.0, 0.0, 0.0));
  const ItemBuffer both = renderer.render(axisCamera(), {away, glm::dmat4(1.0), away});
  EXPECT_EQ(both.id, alone.id);
  EXPECT_EQ(both.depth, alone.depth);
  // Moved into the view, the culled object is drawn again.
  const ItemBuffer back = renderer.render(
      axisCamera(), {glm::translate(glm::dmat4(1.0), glm::dvec3(0, 0, 1)), glm::dmat4(1.0), away});
  EXPECT_NE(back.id, alone.id);
}

}  // namespace
}  // namespace rad
