// The lights that stand in for the relit env map (--lighting lights:N): they match the map's exact
// irradiance under the light they were fitted at and, recombined per part, under another; light
// from below (the courtyard's ground) is marked as reflected by the model.
#include "lightfit/env_lights.h"

#include <gtest/gtest.h>

#include <cmath>

#include "base/check.h"
#include "base/error.h"
#include "sh/exact_irradiance.h"
#include "base/latlong.h"
#include "scene/scene.h"

namespace daylit::lightfit {
namespace {

constexpr int kWidth = 256, kHeight = 128;

// Three parts like the relit map's: sunlight reflected by a patch of ground, a clear sky
// brighter toward the sun, a uniform overcast sky.
relight::EnvBasis SyntheticBasis() {
  relight::EnvBasis basis;
  const glm::dvec3 sun = glm::normalize(glm::dvec3(0.3, 0.8, 0.5));
  const glm::dvec3 patch = glm::normalize(glm::dvec3(-0.6, -0.3, -0.5));
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      const glm::dvec3 w = LatLongDirection(u, v, kWidth, kHeight);
      const bool sky = w.z > 0.0;
      basis.sun.push_back(glm::dot(w, patch) > std::cos(glm::radians(35.0)) ? glm::vec3(0.030f, 0.026f, 0.022f) : glm::vec3(0.0f));
      const float glow = sky ? static_cast<float>(1.0 + 4.0 * std::pow(std::max(0.0, glm::dot(w, sun)), 8.0)) : 0.0f;
      basis.clear.push_back(glow * glm::vec3(0.06f, 0.08f, 0.11f));
      basis.overcast.push_back(sky ? glm::vec3(1.0f / 3.14159265f) : glm::vec3(0.0f));
    }
  }
  return basis;
}

// The mean relative error of `lights` against the exact irradiance of the basis under `parts`.
double MeanError(const relight::EnvBasis& basis, const estimation::LightParts& parts, const LightSet& lights) {
  HdrImage map{kWidth, kHeight, {}};
  for (size_t t = 0; t < basis.sun.size(); ++t) {
    const glm::vec3 l = parts.sun * basis.sun[t] + parts.clear * basis.clear[t] + parts.overcast * basis.overcast[t];
    map.rgb.insert(map.rgb.end(), {l.x, l.y, l.z});
  }
  const std::vector<glm::vec3> normals = sh::IcosahedronNormals(4);
  return RelativeError(sh::ExactIrradiance(map, normals), lights.Irradiance(normals)).mean;
}

TEST(EnvLightsTest, MatchTheMapAndRecombineUnderAnotherLight) {
  const scene::Scene scene = scene::LoadScene(DAYLIT_SOURCE_DIR "/recordings/courtyard-a");
  const scene::RayCaster model(scene.model);
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const scene::VirtualObject& o : scene.objects) lo = glm::min(lo, glm::vec3(o.position)), hi = glm::max(hi, glm::vec3(o.position));
  // Captured at the objects' centre: the reprojection changes nothing but the sampling.
  EnvLights lights(8, model, 0.5f * (lo + hi), 0.5f * (lo + hi), kWidth, kHeight);
  const relight::EnvBasis basis = SyntheticBasis();
  estimation::LightParts clear_day;
  clear_day.sun = glm::vec3(900.0f, 850.0f, 800.0f);
  clear_day.clear = glm::vec3(1.0f);
  clear_day.overcast = glm::vec3(20.0f);
  lights.SetBasis(basis);
  const LightSet fitted = lights.Update(clear_day);
  EXPECT_EQ(lights.generation(), 1);
  const double error = MeanError(basis, clear_day, fitted);
  std::printf("8 lights: %.2f%% at the light they were fitted at (its own check: %.2f%%)\n", 100 * error, 100 * lights.error());
  EXPECT_LT(error, 0.05);
  EXPECT_NEAR(lights.error(), error, 0.01);  // the fit's normals against the 20 480 of the measure
  // Light from below the horizon is the ground's (the sunlit patch): the model reflects it, so it
  // must not shadow it.
  int below = 0;
  for (size_t i = 0; i < fitted.lights.size(); ++i) {
    if (fitted.lights[i].direction.z < -0.05f) {
      ++below;
      EXPECT_EQ(lights.reflected()[i], 1) << "light " << i;
    }
  }
  EXPECT_GE(below, 1) << "no light for the ground's reflected sunlight";
  // Somewhat more overcast: the same directions, each part's irradiances recombined.
  estimation::LightParts hazier = clear_day;
  hazier.overcast *= 1.5f;
  const double recombined = MeanError(basis, hazier, lights.Update(hazier));
  std::printf("8 lights: %.2f%% with the overcast part 1.5 times stronger\n", 100 * recombined);
  EXPECT_EQ(lights.generation(), 1);
  EXPECT_LT(recombined, 0.05);
  // Linear in the light: twice the light, twice every irradiance.
  estimation::LightParts twice = hazier;
  twice.sun *= 2.0f, twice.clear *= 2.0f, twice.overcast *= 2.0f;
  const LightSet a = lights.Update(hazier), b = lights.Update(twice);
  EXPECT_EQ(lights.generation(), 1);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(b.ambient[c], 2.0f * a.ambient[c], 1e-5f * b.ambient[c] + 1e-9f);
  for (size_t i = 0; i < a.lights.size(); ++i) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(b.lights[i].irradiance[c], 2.0f * a.lights[i].irradiance[c], 1e-4f * b.lights[i].irradiance[c] + 1e-9f);
  }
  // A cloud (the sun a tenth, the sky mostly overcast): recombining would be far off, so the
  // directions are fitted again.
  estimation::LightParts cloudy;
  cloudy.sun = 0.1f * clear_day.sun;
  cloudy.clear = glm::vec3(0.3f);
  cloudy.overcast = glm::vec3(60.0f);
  const LightSet under_cloud = lights.Update(cloudy);
  const double refitted = MeanError(basis, cloudy, under_cloud);
  std::printf("8 lights: %.2f%% under a cloud, fitted again\n", 100 * refitted);
  EXPECT_EQ(lights.generation(), 2);
  EXPECT_LT(refitted, 0.07);
}

TEST(EnvLightsTest, CountsOutsideOneToSixteenAreRefused) {
  const scene::Scene scene = scene::LoadScene(DAYLIT_SOURCE_DIR "/recordings/courtyard-a");
  const scene::RayCaster model(scene.model);
  EXPECT_THROW(EnvLights(0, model, glm::vec3(0.0f), glm::vec3(0.0f), 64, 32), InvariantError);
  EXPECT_THROW(EnvLights(17, model, glm::vec3(0.0f), glm::vec3(0.0f), 64, 32), InvariantError);
}

}  // namespace
}  // namespace daylit::lightfit
