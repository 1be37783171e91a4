#include "composite/object_shadows.h"

#include <gtest/gtest.h>

#include <glm/gtc/constants.hpp>

#include "bake/synthetic_recording.h"
#include "base/log.h"
#include "scene/object_mesh.h"

namespace daylit::composite {
namespace {

// A sphere of radius 0.5 floating 1 m above an open ground, seen from straight above (8 px per
// metre), the sun 45° up toward +x; with `wall`, a 3 m wall on the sun's side between x = 1 and
// 1.2 whose real shadow covers the ground from x = −2 to 1, the sphere's shadow included.
struct FloatingSphere {
  bake::testing::SyntheticRecording rec;
  scene::Scene scene;
  bake::SceneBake bake;
  std::unique_ptr<scene::RayCaster> real, objects;
  scene::SceneModel objects_model;
  std::unique_ptr<ObjectShadows> shadows;
  const glm::vec3 sun = glm::normalize(glm::vec3(1.0f, 0.0f, 1.0f));

  FloatingSphere(const std::string& name, bool wall) : rec(name) {
    SetLogVerbosity(0);
    if (wall) {
      rec.obj += "o wall\nv 1 -9 0\nv 1.2 -9 0\nv 1.2 9 0\nv 1 9 0\nv 1 -9 3\nv 1.2 -9 3\nv 1.2 9 3\nv 1 9 3\n"
                 "f 5 8 7 6\nf 9 10 11 12\nf 5 6 10 9\nf 6 7 11 10\nf 7 8 12 11\nf 8 5 9 12\n";
    }
    rec.scene["objects"] = {{{"mesh", "builtin:sphere"}, {"radius", 0.5}, {"position", {0.0, 0.0, 1.0}}}};
    scene = scene::LoadScene(rec.Write());
    bake = bake::RunBake(scene, bake::BakeOptions{});
    real = std::make_unique<scene::RayCaster>(scene.model);
    objects_model = scene::ObjectsModel(scene.objects);
    objects = std::make_unique<scene::RayCaster>(objects_model);
    shadows = std::make_unique<ObjectShadows>(scene, bake, *real, *objects);
    shadows->SetSun(sun);
  }

  // The frame the model predicts under `light` (L = ρ/π·(E_sun·s·cos + E_sky·V)), then with the
  // objects' share taken out.
  std::vector<float> Frame(const estimation::SunSky& light) const {
    const bake::CameraGBuffer& g = bake.camera;
    std::vector<float> rgb(g.point.size() * 3, 0.0f);
    for (size_t p = 0; p < g.point.size(); ++p) {
      if (g.surface[p] == bake::kNoSurface) continue;
      const glm::vec3 origin = g.point[p] + 2e-3f * g.normal[p];
      const float direct = real->Occluded(origin, sun) ? 0.0f : std::max(0.0f, glm::dot(g.normal[p], sun));
      for (int c = 0; c < 3; ++c) {
        rgb[3 * p + c] = g.albedo[p][c] / glm::pi<float>() *
                         static_cast<float>(light.sun_rgb[c] * direct + light.sky_rgb[c] * g.sky_visibility[p]);
      }
    }
    return rgb;
  }
  std::vector<float> Shaded(const estimation::SunSky& light, const std::vector<float>& frame) {
    std::vector<float> out = frame;
    shadows->Apply(light, 0.0, out.data());
    return out;
  }
  // Whether the ground pixel's sun ray passes through the sphere (Embree against the mesh), and
  // how far from the sphere's centre it passes.
  bool SunRayHitsSphere(size_t p, float* miss_distance) const {
    const glm::vec3 origin = bake.camera.point[p] + 2e-3f * bake.camera.normal[p];
    const glm::vec3 to = glm::vec3(0.0f, 0.0f, 1.0f) - origin;
    *miss_distance = glm::length(to - glm::dot(to, sun) * sun);
    return objects->Occluded(origin, sun);
  }
};

const estimation::SunSky kSunny{glm::dvec3(100.0), glm::dvec3(20.0)};

TEST(ObjectShadowsTest, TheShadowLandsWhereTheSunRaysMeetTheObject) {
  FloatingSphere f("shadows_open", false);
  const std::vector<float> frame = f.Frame(kSunny);
  const std::vector<float> out = f.Shaded(kSunny, frame);
  const bake::CameraGBuffer& g = f.bake.camera;
  int shadowed = 0, clear = 0;
  for (size_t p = 0; p < g.point.size(); ++p) {
    if (g.surface[p] == bake::kNoSurface || frame[3 * p + 1] <= 0.0f) continue;
    float miss = 0.0f;
    const float keep = out[3 * p + 1] / frame[3 * p + 1];
    if (f.SunRayHitsSphere(p, &miss) && miss < 0.4f) {
      // The sun's whole disc is behind the sphere: the sun's share goes, the sky's stays.
      EXPECT_LT(keep, 0.35f) << "ground point " << g.point[p].x << ", " << g.point[p].y;
      ++shadowed;
    } else if (miss > 0.6f) {
      EXPECT_GT(keep, 0.85f) << "ground point " << g.point[p].x << ", " << g.point[p].y;  // sky loss only
      ++clear;
    }
  }
  // Falls away from the sun: around (−1, 0), 1 m from the point under the sphere, not at (+1, 0).
  EXPECT_GT(shadowed, 20);
  EXPECT_GT(clear, 1000);
  const auto pixel = [&](float x, float y) {
    return static_cast<size_t>(std::lround(-40.0f * y / 5.0f + 23.5f)) * 64 + static_cast<size_t>(std::lround(40.0f * x / 5.0f + 31.5f));
  };
  EXPECT_LT(out[3 * pixel(-1.0f, 0.0f) + 1] / frame[3 * pixel(-1.0f, 0.0f) + 1], 0.35f);
  EXPECT_GT(out[3 * pixel(1.0f, 0.0f) + 1] / frame[3 * pixel(1.0f, 0.0f) + 1], 0.85f);
}

TEST(ObjectShadowsTest, AVirtualShadowInsideARealShadowDoesNotDarkenIt) {
  FloatingSphere f("shadows_wall", true);
  const std::vector<float> frame = f.Frame(kSunny);
  // The same frame under a sun of 100 and of 0: where the real scene already shades the ground,
  // the sun's strength must not matter (only the sky the sphere covers is taken).
  const std::vector<float> sunny = f.Shaded(kSunny, frame);
  const std::vector<float> sunless = f.Shaded({glm::dvec3(0.0), kSunny.sky_rgb}, frame);
  const bake::CameraGBuffer& g = f.bake.camera;
  int inside = 0;
  for (size_t p = 0; p < g.point.size(); ++p) {
    if (g.surface[p] == bake::kNoSurface || g.point[p].x > 0.9f) continue;
    const glm::vec3 origin = g.point[p] + 2e-3f * g.normal[p];
    if (!f.real->Occluded(origin, f.sun)) continue;
    float miss = 0.0f;
    if (f.SunRayHitsSphere(p, &miss)) ++inside;
    for (int c = 0; c < 3; ++c) ASSERT_EQ(sunny[3 * p + c], sunless[3 * p + c]) << "pixel " << p;
  }
  EXPECT_GT(inside, 20) << "the sphere's shadow is not inside the wall's";
}

}  // namespace
}  // namespace daylit::composite
