// The compositor on real GL (llvmpipe here): pixel values checked against geometry computed with
// Embree and the camera model, never against stored images.
#include "render/compositor.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <optional>

#include <glm/gtc/constants.hpp>

#include "render/gl_context.h"
#include "scene/object_mesh.h"
#include "scene/raycaster.h"
#include "sunmodel/solar_position.h"

namespace daylit::render {
namespace {

struct Fixture {
  std::unique_ptr<HeadlessGlContext> gl;
  scene::Scene scene;
  glm::vec3 sun;
  std::vector<float> background;

  explicit Fixture(size_t frame = 300) {
    std::string why;
    gl = HeadlessGlContext::Create(&why);
    EXPECT_NE(gl, nullptr) << why;
    scene = scene::LoadScene(DAYLIT_SOURCE_DIR "/recordings/courtyard-a");
    const UtcTime t = scene.frame_times->frames[frame].utc;
    const sunmodel::SunPosition s = sunmodel::ComputeSunPosition(t, scene.location, sunmodel::Atmosphere::Standard(10.0), {});
    sun = glm::vec3(scene.GeoFrame().DirectionInScene(s.azimuth_deg, s.apparent_zenith_deg));
    // A background with a different value in every pixel: any resampling would show.
    background.resize(static_cast<size_t>(scene.intrinsics.width) * scene.intrinsics.height * 3);
    for (size_t i = 0; i < background.size(); ++i) background[i] = 0.01f * static_cast<float>(i % 997) + 0.5f;
  }

  std::vector<float> Render(const std::vector<scene::VirtualObject>& objects) {
    scene::Scene s = scene;
    s.objects = objects;
    Compositor compositor(s);
    CompositeInput in;
    in.light.sun_rgb = glm::dvec3(10.0, 20.0, 30.0);
    in.sun_dir = sun;
    std::vector<float> out;
    out = background;
    compositor.Render(in, out.data());
    return out;
  }

  glm::vec3 At(const std::vector<float>& image, glm::dvec2 uv) const {
    const size_t p = static_cast<size_t>(std::lround(uv.y)) * static_cast<size_t>(scene.intrinsics.width) +
                     static_cast<size_t>(std::lround(uv.x));
    return {image[3 * p], image[3 * p + 1], image[3 * p + 2]};
  }
};

scene::VirtualObject Sphere(const glm::dvec3& centre, double radius) {
  scene::VirtualObject o;
  o.kind = scene::MeshKind::kSphere;
  o.radius = radius;
  o.position = centre;
  o.albedo = glm::dvec3(0.5);
  return o;
}

// Two spots for a 0.15 m sphere on the ground the camera sees, under fixture `f`'s sun: one wholly
// in a wall's shadow and one wholly in the sun (Embree decides: all or none of 27 points of the
// sphere's bounding cube see the sun), apart across the sun's direction so neither shadows the
// other.
struct ShadowAndSun {
  std::optional<glm::dvec3> shadowed, sunlit;
};

ShadowAndSun FindShadowAndSun(const Fixture& f) {
  const scene::CameraModel camera = f.scene.Camera();
  const scene::RayCaster real(f.scene.model);
  ShadowAndSun found;
  for (int y = f.scene.intrinsics.height / 2; y < f.scene.intrinsics.height && !(found.shadowed && found.sunlit); y += 9) {
    for (int x = 20; x < f.scene.intrinsics.width - 20 && !(found.shadowed && found.sunlit); x += 23) {
      const glm::dvec3 dir = camera.UnprojectToWorldRay(glm::dvec2(x, y));
      const scene::RayHit hit = real.Intersect(glm::vec3(camera.CenterInWorld()), glm::vec3(dir));
      if (!hit.IsHit() || hit.normal.z < 0.9f || hit.t > 20.0f) continue;  // ground only
      const glm::dvec3 centre = camera.CenterInWorld() + static_cast<double>(hit.t) * dir + glm::dvec3(0, 0, 0.16);
      int blocked = 0;
      for (int k = 0; k < 27; ++k) {  // the sphere's bounding cube, corners and centres
        const glm::dvec3 q = centre + 0.15 * glm::dvec3(k % 3 - 1, (k / 3) % 3 - 1, k / 9 - 1);
        blocked += real.Occluded(glm::vec3(q), f.sun) ? 1 : 0;
      }
      const auto apart = [&](const std::optional<glm::dvec3>& other) {
        return !other || glm::length(glm::cross(*other - centre, glm::dvec3(f.sun))) > 1.0;
      };
      if (blocked == 27 && !found.shadowed && apart(found.sunlit)) found.shadowed = centre;
      if (blocked == 0 && !found.sunlit && apart(found.shadowed)) found.sunlit = centre;
    }
  }
  return found;
}

TEST(CompositorTest, ObjectsAppearWhereTheCameraProjectsThemLitByTheSunAndNothingElseChanges) {
  Fixture f;
  const std::vector<float> image = f.Render(f.scene.objects);
  const scene::CameraModel camera = f.scene.Camera();
  const scene::SceneModel objects_model = scene::ObjectsModel(f.scene.objects);
  const scene::RayCaster real(f.scene.model), objects(objects_model);
  // The sphere's point halfway between the camera's and the sun's direction: seen and lit.
  const scene::VirtualObject& sphere = f.scene.objects[0];
  ASSERT_EQ(sphere.kind, scene::MeshKind::kSphere);
  const glm::dvec3 to_camera = glm::normalize(camera.CenterInWorld() - sphere.position);
  const glm::dvec3 normal = glm::normalize(to_camera + glm::dvec3(f.sun));
  const glm::dvec3 point = sphere.position + sphere.radius * normal;
  const glm::vec3 n(normal);
  const float cos_l = std::max(0.0f, glm::dot(n, f.sun));
  ASSERT_GT(cos_l, 0.3f);
  const glm::vec3 origin = glm::vec3(point) + 1e-3f * n;
  const bool lit = !real.Occluded(origin, f.sun) && !objects.Occluded(origin, f.sun);
  ASSERT_TRUE(lit) << "pick a frame where the sphere is in the sun";
  const glm::vec3 expected = glm::vec3(0.5f / glm::pi<float>()) * glm::vec3(10, 20, 30) * cos_l;
  const glm::vec3 got = f.At(image, camera.Project(point));
  std::printf("sphere: expected (%.3f %.3f %.3f), rendered (%.3f %.3f %.3f)\n", expected.x, expected.y, expected.z, got.x,
              got.y, got.z);
  // A pixel covers a patch of the sphere: n·l varies by about 1% across it.
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], expected[c], 0.02f * expected[c]);
  // Far from the objects the frame passes through bit for bit.
  size_t same = 0, far = 0;
  const glm::dvec2 a = camera.Project(f.scene.objects[0].position), b = camera.Project(f.scene.objects[1].position);
  for (int y = 0; y < f.scene.intrinsics.height; y += 7) {
    for (int x = 0; x < f.scene.intrinsics.width; x += 7) {
      if (glm::distance(glm::dvec2(x, y), a) < 200 || glm::distance(glm::dvec2(x, y), b) < 200) continue;
      const size_t p = static_cast<size_t>(y * f.scene.intrinsics.width + x);
      ++far;
      same += image[3 * p] == f.background[3 * p] && image[3 * p + 1] == f.background[3 * p + 1] &&
              image[3 * p + 2] == f.background[3 * p + 2];
    }
  }
  EXPECT_EQ(same, far);
}

TEST(CompositorTest, ARealWallHidesAnObjectBehindIt) {
  Fixture f;
  const scene::CameraModel camera = f.scene.Camera();
  const scene::RayCaster real(f.scene.model);
  // A pixel whose ray meets the model 4-40 m away.
  for (int y = f.scene.intrinsics.height / 3; y < f.scene.intrinsics.height; y += 20) {
    const glm::dvec2 uv(f.scene.intrinsics.width / 2.0, y);
    const glm::dvec3 dir = camera.UnprojectToWorldRay(uv);
    const scene::RayHit hit = real.Intersect(glm::vec3(camera.CenterInWorld()), glm::vec3(dir));
    if (!hit.IsHit() || hit.t < 4.0f || hit.t > 40.0f) continue;
    const glm::dvec3 behind = camera.CenterInWorld() + (hit.t + 1.0) * dir;
    const glm::dvec3 before = camera.CenterInWorld() + (hit.t - 1.0) * dir;
    const glm::vec3 bg = f.At(f.background, uv);
    EXPECT_EQ(f.At(f.Render({Sphere(behind, 0.3)}), uv), bg) << "the object behind the wall shows";
    EXPECT_NE(f.At(f.Render({Sphere(before, 0.3)}), uv), bg) << "the object in front of the wall does not show";
    return;
  }
  FAIL() << "no pixel sees a wall";
}

TEST(CompositorTest, AnObjectInARealShadowGetsNoSun) {
  Fixture f(0);  // 05:00, the sun 17° high: long wall shadows on the ground
  const scene::CameraModel camera = f.scene.Camera();
  // Two small spheres on the ground, one in a wall's shadow and one in the sun, rendered together.
  const auto [shadowed, sunlit] = FindShadowAndSun(f);
  ASSERT_TRUE(shadowed.has_value()) << "no ground in a wall's shadow";
  ASSERT_TRUE(sunlit.has_value()) << "no ground in the sun";
  const std::vector<float> image = f.Render({Sphere(*shadowed, 0.15), Sphere(*sunlit, 0.15)});
  const auto facing = [&](const glm::dvec3& c) {  // the point seen and facing the sun most
    return c + 0.15 * glm::normalize(glm::normalize(camera.CenterInWorld() - c) + glm::dvec3(f.sun));
  };
  EXPECT_EQ(f.At(image, camera.Project(facing(*shadowed))), glm::vec3(0.0f)) << "the sphere in the shadow is lit";
  EXPECT_GT(f.At(image, camera.Project(facing(*sunlit))).x, 0.3f) << "the sphere in the sun is dark";
}

// --lighting lights:N: the lights and ambient instead of the volume, each object with its own
// set (lightfit::EnvLights: the light as seen from where it stands), each light with a shadow map
// of the objects only. One light along the sun (the sun itself dark): the sphere in a wall's shadow
// gets the ambient alone when its set says the wall hides that light, ambient + light·cos when it
// does not (the wall does not shadow it then); the one in the sun ambient + light·cos.
TEST(CompositorTest, EachObjectTakesItsOwnLightsAndOnlyObjectsShadowThem) {
  Fixture f(0);
  const scene::CameraModel camera = f.scene.Camera();
  const auto [shadowed, sunlit] = FindShadowAndSun(f);
  ASSERT_TRUE(shadowed && sunlit);
  scene::Scene s = f.scene;
  s.objects = {Sphere(*shadowed, 0.15), Sphere(*sunlit, 0.15)};
  CompositorOptions one_light;
  one_light.lights = 1;
  Compositor compositor(s, one_light);
  lightfit::LightSet lights;
  lights.ambient = glm::vec3(0.1f, 0.2f, 0.3f);
  lights.lights = {{f.sun, glm::vec3(10.0f, 20.0f, 30.0f)}};
  lightfit::LightSet hidden = lights;  // as seen from behind the wall
  hidden.lights[0].irradiance = glm::vec3(0.0f);
  std::vector<lightfit::LightSet> sets = {hidden, lights};  // the scene's order: shadowed, sunlit
  CompositeInput in;
  in.sun_dir = f.sun;  // E_sun = 0
  in.lights = &sets;
  in.lights_generation = 1;
  const auto facing = [&](const glm::dvec3& c) {
    return c + 0.15 * glm::normalize(glm::normalize(camera.CenterInWorld() - c) + glm::dvec3(f.sun));
  };
  // The normal where the pixel's own ray meets the (ideal) sphere: a 0.15 m sphere spans few
  // pixels, so the normal turns by degrees from one pixel to the next.
  const auto pixel = [&](const glm::dvec3& c) { return glm::round(camera.Project(facing(c))); };
  const auto expected = [&](const glm::dvec3& c, bool lit) {
    const glm::dvec3 o = camera.CenterInWorld(), d = camera.UnprojectToWorldRay(pixel(c));
    const double b = glm::dot(o - c, d), disc = b * b - (glm::dot(o - c, o - c) - 0.15 * 0.15);
    EXPECT_GT(disc, 0.0);
    const glm::dvec3 n = glm::normalize(o + (-b - std::sqrt(std::max(disc, 0.0))) * d - c);
    const float cos_l = std::max(0.0f, glm::dot(glm::vec3(n), f.sun));
    return glm::vec3(0.5f / glm::pi<float>()) * (lights.ambient + (lit ? cos_l : 0.0f) * lights.lights[0].irradiance);
  };
  const auto check = [&](const glm::vec3& got, const glm::vec3& want, const char* what) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 0.02f * want[c]) << what << " channel " << c;
  };
  std::vector<float> image = f.background;
  compositor.Render(in, image.data());
  check(f.At(image, pixel(*shadowed)), expected(*shadowed, false), "behind the wall");
  check(f.At(image, pixel(*sunlit)), expected(*sunlit, true), "in the open");
  // The same light for both: the wall does not shadow it (each object's set holds what the model
  // hides from it).
  sets = {lights, lights};
  image = f.background;
  compositor.Render(in, image.data());
  check(f.At(image, pixel(*shadowed)), expected(*shadowed, true), "behind the wall, its set lit");
}

}  // namespace
}  // namespace daylit::render
