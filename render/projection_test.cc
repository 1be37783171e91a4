#include "render/projection.h"

#include <gtest/gtest.h>

#include "scene/scene.h"

namespace daylit::render {
namespace {

TEST(ProjectionTest, GlMatricesLandOnOpenCvsPixels) {
  const scene::Scene scene = scene::LoadScene(DAYLIT_SOURCE_DIR "/recordings/courtyard-a");
  const scene::CameraModel camera = scene.Camera();
  const glm::mat4 clip = ClipFromCamera(scene.intrinsics, 0.05f, 500.0f) * CameraFromWorld(scene.cam_from_world);
  for (const glm::dvec3& p : {glm::dvec3(-0.8, -2.2, 0.5), glm::dvec3(1.6, -0.6, 0.5), glm::dvec3(0.0, 0.0, 0.0)}) {
    const glm::dvec2 uv = camera.Project(p);
    const glm::vec4 c = clip * glm::vec4(glm::vec3(p), 1.0f);
    const double wx = (c.x / c.w + 1.0) * 0.5 * scene.intrinsics.width, wy = (c.y / c.w + 1.0) * 0.5 * scene.intrinsics.height;
    EXPECT_NEAR(wx, uv.x + 0.5, 1e-2);
    EXPECT_NEAR(wy, scene.intrinsics.height - (uv.y + 0.5), 1e-2);
    EXPECT_GT(c.z / c.w, -1.0f);
    EXPECT_LT(c.z / c.w, 1.0f);
  }
}

}  // namespace
}  // namespace daylit::scene
