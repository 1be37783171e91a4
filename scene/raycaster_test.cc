#include "scene/raycaster.h"

#include <gtest/gtest.h>

#include <random>

#include "scene/scene.h"

namespace daylit::scene {
namespace {

// A 20 x 20 m ground (counter-clockwise from above: normal +Z) and a 3 m wall at x = 2 facing −X,
// plus one degenerate triangle.
SceneModel GroundAndWall() {
  SceneModel m;
  m.surface_names = {"ground", "wall"};
  m.vertices = {{-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0},
                {2, -5, 0},    {2, 5, 0},    {2, 5, 3},   {2, -5, 3}, {0, 0, 5}};
  m.triangles = {{{0, 1, 2}, 0}, {{0, 2, 3}, 0}, {{4, 6, 5}, 1}, {{4, 7, 6}, 1}, {{8, 8, 8}, 1}};
  return m;
}

TEST(RayCasterTest, HitsNormalsAndFacing) {
  const SceneModel model = GroundAndWall();
  const RayCaster caster(model);
  EXPECT_EQ(caster.degenerate_triangles(), 1u);
  const RayHit down = caster.Intersect({0, 0, 1.5f}, {0, 0, -1});
  ASSERT_TRUE(down.IsHit());
  EXPECT_NEAR(down.t, 1.5f, 1e-5f);
  EXPECT_EQ(model.surface_names[down.surface], "ground");
  EXPECT_EQ(down.normal, glm::vec3(0, 0, 1));
  EXPECT_FALSE(down.back_face);
  const RayHit from_below = caster.Intersect({0, 0, -1}, {0, 0, 1});
  EXPECT_EQ(from_below.normal, glm::vec3(0, 0, -1));  // turned to face the origin
  EXPECT_TRUE(from_below.back_face);
  EXPECT_FALSE(caster.Intersect({0, 0, 1}, {0, 0, 1}).IsHit());  // sky
  const RayHit wall = caster.Intersect({0, 0, 1}, {1, 0, 0});
  EXPECT_EQ(model.surface_names[wall.surface], "wall");
  EXPECT_NEAR(wall.t, 2.0f, 1e-5f);
  EXPECT_NEAR(wall.normal.x, -1.0f, 1e-6f);
}

TEST(RayCasterTest, OcclusionRespectsTheSegment) {
  const SceneModel model = GroundAndWall();
  const RayCaster caster(model);
  EXPECT_TRUE(caster.Occluded({0, 0, 1}, {1, 0, 0}));
  EXPECT_FALSE(caster.Occluded({0, 0, 1}, {1, 0, 0}, 0.0f, 1.9f));  // stops before the wall
  EXPECT_FALSE(caster.Occluded({0, 0, 4}, {1, 0, 0}));              // passes over it
  // A point on the ground behind the wall, seen from the sun low in the west (−X) and the east.
  const glm::vec3 p(3, 0, 0.001f);
  EXPECT_TRUE(caster.Occluded(p, glm::normalize(glm::vec3(-1, 0, 0.3f)), 1e-3f));
  EXPECT_FALSE(caster.Occluded(p, glm::normalize(glm::vec3(1, 0, 0.3f)), 1e-3f));
}

TEST(RayCasterTest, BatchesAgreeWithSingleRays) {
  const SceneModel model = GroundAndWall();
  const RayCaster caster(model);
  std::mt19937 rng(9);
  std::normal_distribution<float> g;
  std::uniform_real_distribution<float> u(-4, 4);
  std::vector<glm::vec3> origins, dirs;
  for (int i = 0; i < 20000; ++i) {
    origins.emplace_back(u(rng), u(rng), std::abs(u(rng)) + 0.1f);
    dirs.push_back(glm::normalize(glm::vec3(g(rng), g(rng), g(rng))));
  }
  std::vector<RayHit> hits(origins.size());
  std::vector<uint8_t> occluded(origins.size());
  caster.IntersectMany(origins.data(), dirs.data(), origins.size(), 0.0f, hits.data());
  caster.OccludedMany(origins.data(), dirs.data(), origins.size(), 0.0f, 1e30f, occluded.data());
  size_t hit_count = 0;
  for (size_t i = 0; i < origins.size(); ++i) {
    const RayHit one = caster.Intersect(origins[i], dirs[i]);
    ASSERT_EQ(hits[i].IsHit(), one.IsHit());
    ASSERT_EQ(occluded[i] != 0, one.IsHit());
    if (one.IsHit()) {
      ASSERT_EQ(hits[i].t, one.t);
    }
    hit_count += one.IsHit();
  }
  EXPECT_GT(hit_count, 5000u);
  EXPECT_LT(hit_count, 15000u);
}

TEST(RayCasterTest, CourtyardCameraRayMeetsTheGroundPlane) {
  const Scene scene = LoadScene(DAYLIT_SOURCE_DIR "/recordings/courtyard-a");
  const RayCaster caster(scene.model);
  const CameraModel camera = scene.Camera();
  // The bottom-centre pixel looks down at the courtyard floor: compare with the analytic
  // intersection of its ray with z = 0.
  const glm::dvec3 c = camera.CenterInWorld();
  const glm::dvec3 d = camera.UnprojectToWorldRay({479.5, 530.0});
  const RayHit hit = caster.Intersect(glm::vec3(c), glm::vec3(d));
  ASSERT_TRUE(hit.IsHit());
  EXPECT_EQ(scene.model.surface_names[hit.surface], "ground");
  EXPECT_NEAR(hit.t, -c.z / d.z, 1e-4);
}

}  // namespace
}  // namespace daylit::scene
