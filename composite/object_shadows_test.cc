#include "composite/object_shadows.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include <glm/gtc/constants.hpp>

#include "bake/synthetic_recording.h"
#include "base/log.h"
#include "composite/object_light.h"
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

// A box standing on the open ground, seen from straight above (8 px per metre, pixel centres at
// x = (u − 31.5)/8, y = (23.5 − v)/8), under a sun of 100 from `sun` and no sky.
struct StandingBox {
  bake::testing::SyntheticRecording rec;
  scene::Scene scene;
  bake::SceneBake bake;
  std::unique_ptr<scene::RayCaster> real, objects;
  scene::SceneModel objects_model;
  std::unique_ptr<ObjectShadows> shadows;
  glm::vec3 sun;

  StandingBox(const std::string& name, const glm::vec3& centre, const glm::vec3& size, const glm::vec3& sun_dir,
              const ObjectShadowOptions& options)
      : rec(name), sun(glm::normalize(sun_dir)) {
    SetLogVerbosity(0);
    rec.scene["objects"] = {{{"mesh", "builtin:box"}, {"size", {size.x, size.y, size.z}},
                             {"position", {centre.x, centre.y, centre.z}}, {"albedo", {0.8, 0.8, 0.8}}}};
    scene = scene::LoadScene(rec.Write());
    bake = bake::RunBake(scene, bake::BakeOptions{});
    real = std::make_unique<scene::RayCaster>(scene.model);
    objects_model = scene::ObjectsModel(scene.objects);
    objects = std::make_unique<scene::RayCaster>(objects_model);
    shadows = std::make_unique<ObjectShadows>(scene, bake, *real, *objects, options);
    shadows->SetSun(sun);
  }
  // The share of its light each pixel keeps (> 1: it gains) under the sun alone.
  std::vector<float> Keep() const {
    const bake::CameraGBuffer& g = bake.camera;
    std::vector<float> frame(g.point.size() * 3, 0.0f);
    for (size_t p = 0; p < g.point.size(); ++p) {
      for (int c = 0; c < 3; ++c) frame[3 * p + c] = g.albedo[p][c] / glm::pi<float>() * 100.0f * std::max(0.0f, sun.z);
    }
    std::vector<float> out = frame;
    shadows->Apply({glm::dvec3(100.0), glm::dvec3(0.0)}, 0.0, out.data());
    std::vector<float> keep(g.point.size());
    for (size_t p = 0; p < keep.size(); ++p) keep[p] = out[3 * p + 1] / frame[3 * p + 1];
    return keep;
  }
};

// A pixel across a shadow's edge loses the share of its footprint that lies in the shadow, as a
// camera integrates it, not all or nothing by its centre. The box's shadow under a sun 45° up
// toward +x ends at x = −1.47 (1 m tall, its sunward... far side at x = −0.47), a line across
// the pixel whose centre is x = −1.4375.
TEST(ObjectShadowsTest, APixelAcrossAShadowsEdgeLosesTheShareOfItsFootprintInTheShadow) {
  StandingBox f("shadows_edge", glm::vec3(0.03f, 0.0f, 0.5f), glm::vec3(1.0f, 4.0f, 1.0f), glm::vec3(1.0f, 0.0f, 1.0f), {});
  const std::vector<float> keep = f.Keep();
  const int v = 20;  // y = 0.4375, well inside the box's 4 m
  int between = 0;
  for (int u = 14; u <= 23; ++u) {
    const float x0 = (static_cast<float>(u) - 32.0f) / 8.0f, x1 = x0 + 0.125f;  // the pixel's span
    const float in_shadow = std::clamp((std::min(x1, -0.47f) - std::max(x0, -1.47f)) / 0.125f, 0.0f, 1.0f);
    const float lost = 1.0f - keep[static_cast<size_t>(v) * 64 + static_cast<size_t>(u)];
    // 16 rays on a 4×4 grid over the pixel: within one column's share and the penumbra's.
    EXPECT_NEAR(lost, in_shadow, 0.13f) << "pixel " << u << " spans x " << x0 << " to " << x1;
    if (lost > 0.2f && lost < 0.8f) ++between;
  }
  EXPECT_GE(between, 1) << "no pixel across the edge: the shadow is a staircase";
}

// A sunlit box gives light back to the ground beside it: a pixel in front of its sunlit face
// gains what that face sends it, ρ/π·E_sun·cos 30° times the face's configuration factor from
// the pixel, checked against a quadrature of that factor over the face (cos θ cos θ' / r² dA).
// The sun is 30° up toward +x, so the face in front (x = 0.5) casts no shadow there.
TEST(ObjectShadowsTest, ASunlitObjectGivesTheGroundInFrontOfItThePartOfItsLightItSees) {
  ObjectShadowOptions options;
  options.sky_rays = 2048;  // the covered rays, here the few that meet the face: enough of them
  const glm::vec3 sun(std::cos(glm::radians(30.0f)), 0.0f, std::sin(glm::radians(30.0f)));
  StandingBox f("shadows_bounce", glm::vec3(0.0f, 0.0f, 0.5f), glm::vec3(1.0f, 2.0f, 1.0f), sun, options);
  ObjectLight light(f.scene, f.bake, *f.real, *f.objects, f.shadows->ReflectingSides());
  light.SetSun(f.sun);
  const std::array<std::vector<glm::vec3>, 3> none = {std::vector<glm::vec3>(light.points().size(), glm::vec3(0.0f)),
                                                      std::vector<glm::vec3>(light.points().size(), glm::vec3(0.0f)),
                                                      std::vector<glm::vec3>(light.points().size(), glm::vec3(0.0f))};
  std::array<std::vector<glm::vec3>, 3> radiance;
  light.Radiance(none, &radiance);
  const std::vector<float> before = f.Keep();
  for (const float k : before) EXPECT_LE(k, 1.0f);
  f.shadows->SetObjectRadiance(radiance);
  const std::vector<float> keep = f.Keep();
  const float face_radiance = 0.8f / glm::pi<float>() * 100.0f * sun.x;  // per the face's albedo and cos
  const float b = 100.0f * sun.z;                                        // the pixel's own irradiance
  double got = 0.0, want = 0.0;
  int pixels = 0;
  for (int v = 20; v <= 27; ++v) {    // y from 0.4375 to −0.4375
    for (int u = 37; u <= 41; ++u) {  // x from 0.6875 to 1.1875: 0.19 to 0.69 m in front of the face
      const glm::vec3 p((static_cast<float>(u) - 31.5f) / 8.0f, (23.5f - static_cast<float>(v)) / 8.0f, 0.0f);
      double e = 0.0;
      constexpr int kY = 200, kZ = 100;
      for (int i = 0; i < kY; ++i) {
        for (int j = 0; j < kZ; ++j) {
          const glm::dvec3 q(0.5, -1.0 + 2.0 * (i + 0.5) / kY, (j + 0.5) / kZ);
          const glm::dvec3 r = q - glm::dvec3(p);
          const double d2 = glm::dot(r, r), d = std::sqrt(d2);
          e += (r.z / d) * (-r.x / d) / d2 * (2.0 / kY) * (1.0 / kZ);  // receiver up, face toward +x
        }
      }
      want += face_radiance * e;
      got += (keep[static_cast<size_t>(v) * 64 + static_cast<size_t>(u)] - 1.0f) * b;
      ++pixels;
    }
  }
  std::printf("the ground in front of the sunlit face gains %.2f (quadrature %.2f) on average over %d pixels, of %.0f\n",
              got / pixels, want / pixels, pixels, b);
  EXPECT_NEAR(got, want, 0.06 * want);
}

}  // namespace
}  // namespace daylit::composite
