#include "scene/camera.h"

#include <gtest/gtest.h>

#include <random>

namespace daylit::scene {
namespace {

CameraIntrinsics Distorted() {
  CameraIntrinsics k;
  k.width = 1280;
  k.height = 720;
  k.fx = 1100;
  k.fy = 1090;
  k.cx = 640.3;
  k.cy = 359.2;
  k.distortion = {-0.28, 0.09, 0.0008, -0.0005, -0.012};
  return k;
}

RigidPose SomePose() {
  RigidPose pose;
  const double a = 0.3;
  pose.rotation = glm::dmat3(glm::dvec3(std::cos(a), 0, -std::sin(a)), glm::dvec3(0, 1, 0),
                             glm::dvec3(std::sin(a), 0, std::cos(a)));
  pose.translation = {0.4, -0.2, 5.0};
  return pose;
}

TEST(CameraTest, ProjectUnprojectRoundTripWithDistortion) {
  const CameraModel camera(Distorted(), SomePose());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(20, 1260), v(20, 700), depth(1, 50);
  for (int i = 0; i < 2000; ++i) {
    const glm::dvec2 px(u(rng), v(rng));
    const glm::dvec3 ray = camera.UnprojectToWorldRay(px);
    ASSERT_NEAR(glm::length(ray), 1.0, 1e-12);
    const glm::dvec3 point = camera.CenterInWorld() + depth(rng) * ray;
    const glm::dvec2 back = camera.Project(point);
    ASSERT_NEAR(back.x, px.x, 1e-6) << i;
    ASSERT_NEAR(back.y, px.y, 1e-6) << i;
  }
}

TEST(CameraTest, PinholeProjectionIsTheTextbookFormula) {
  CameraIntrinsics k = Distorted();
  k.distortion.clear();
  const CameraModel camera(k, RigidPose{});
  const glm::dvec2 px = camera.Project(glm::dvec3(1.0, -0.5, 4.0));
  EXPECT_NEAR(px.x, 640.3 + 1100 * 0.25, 1e-9);
  EXPECT_NEAR(px.y, 359.2 - 1090 * 0.125, 1e-9);
  EXPECT_TRUE(std::isnan(camera.Project(glm::dvec3(0, 0, -1)).x));  // behind the camera
}

TEST(CameraTest, PoseFromNoisyCorrespondences) {
  const CameraModel truth(Distorted(), SomePose());
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> xy(-3, 3), z(-1, 2);
  std::normal_distribution<double> noise(0.0, 0.3);  // pixels
  std::vector<glm::dvec3> world;
  std::vector<glm::dvec2> pixels;
  for (int i = 0; i < 40; ++i) {
    world.emplace_back(xy(rng), xy(rng), z(rng));
    pixels.push_back(truth.Project(world.back()) + glm::dvec2(noise(rng), noise(rng)));
  }
  PoseFit fit;
  std::string why;
  ASSERT_TRUE(SolvePoseFromCorrespondences(truth.intrinsics(), world, pixels, &fit, &why)) << why;
  EXPECT_NEAR(fit.rms_reprojection_px, 0.3 * std::sqrt(2.0), 0.15);  // the noise level, no worse
  EXPECT_LT(glm::length(fit.cam_from_world.CenterInWorld() - truth.CenterInWorld()), 0.02);
  // Too few points is refused with a reason.
  EXPECT_FALSE(SolvePoseFromCorrespondences(truth.intrinsics(), {world[0], world[1], world[2]},
                                            {pixels[0], pixels[1], pixels[2]}, &fit, &why));
  EXPECT_EQ(why, "at least 4 correspondences are needed, got 3");
}

TEST(CameraTest, RotationChecks) {
  EXPECT_TRUE(IsRotation(SomePose().rotation, 1e-12));
  glm::dmat3 reflected = SomePose().rotation;
  reflected[2] = -reflected[2];
  EXPECT_FALSE(IsRotation(reflected, 1e-6));
  glm::dmat3 noisy = SomePose().rotation;
  noisy[0][0] += 1e-7;
  EXPECT_TRUE(IsRotation(noisy, 1e-5));
  EXPECT_LT(OrthonormalityError(NearestRotation(noisy)), 1e-14);
}

}  // namespace
}  // namespace daylit::scene
