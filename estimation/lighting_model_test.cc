#include "estimation/lighting_model.h"

#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/constants.hpp>

namespace daylit::estimation {
namespace {

TEST(LightingModelTest, RecordingFormatDefinitionOfUnits) {
  // recording-format.md: a Lambertian surface of albedo ρ, horizontal, unshadowed, under an open
  // sky with the sun at the zenith has L = ρ/π · (E_sun + E_sky), whatever the sky's split.
  const SunSky light{{86.0, 63.0, 37.0}, {9.8, 9.7, 10.0}};
  const Transfer open{glm::vec3(1.0f), glm::vec3(1.0f), glm::vec3(1.0f)};
  for (const double share : {0.0, 0.3, 1.0}) {
    const glm::vec3 l = 0.5f * glm::one_over_pi<float>() * Irradiance(SplitLight(light, share), open);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(l[c], 0.5 / glm::pi<double>() * (light.sun_rgb[c] + light.sky_rgb[c]), 1e-5) << share;
    }
  }
}

TEST(LightingModelTest, TheSkySplitsIntoAGreyOvercastAndAClearRestAndTheShareIsClamped) {
  const SunSky light{{100, 100, 100}, {10, 20, 30}};
  // Grey: a quarter of E_sky's mean (20) in every channel; the clear part keeps the colour.
  const LightParts parts = SplitLight(light, 0.25);
  for (int c = 0; c < 3; ++c) {
    EXPECT_FLOAT_EQ(parts.overcast[c], 5.0f) << c;
    EXPECT_FLOAT_EQ(parts.clear[c] + parts.overcast[c], static_cast<float>(light.sky_rgb[c])) << c;
  }
  // At most E_sky in a channel: a share of 1 leaves red no clear part, blue some.
  const LightParts full = SplitLight(light, 1.0);
  EXPECT_FLOAT_EQ(full.overcast.x, 10.0f);
  EXPECT_FLOAT_EQ(full.clear.x, 0.0f);
  EXPECT_FLOAT_EQ(full.overcast.z, 20.0f);
  EXPECT_FLOAT_EQ(full.clear.z, 10.0f);
  EXPECT_FLOAT_EQ(SplitLight(light, 1.7).clear.x, 0.0f);
  EXPECT_FLOAT_EQ(SplitLight(light, -0.2).overcast.x, 0.0f);
}

TEST(LightingModelTest, SeedOnesModelIsTheUniformSkyWithoutBounces) {
  // 45° sun on a horizontal point, sky visibility 0.8: E = E_sun·cos 45° + E_sky·V when lit,
  // E_sky·V in shadow, for any split (a uniform sky without interreflection: T_clear = T_overcast).
  const SunSky light{{100, 100, 100}, {10, 20, 30}};
  const float cosine = static_cast<float>(std::sqrt(0.5));
  const Transfer lit{glm::vec3(cosine), glm::vec3(0.8f), glm::vec3(0.8f)};
  const Transfer shadowed{glm::vec3(0.0f), glm::vec3(0.8f), glm::vec3(0.8f)};
  EXPECT_NEAR(Irradiance(SplitLight(light, 0.4), lit).x, 100 * std::sqrt(0.5) + 8, 1e-4);
  EXPECT_NEAR(Irradiance(SplitLight(light, 0.9), shadowed).z, 24, 1e-5);
}

}  // namespace
}  // namespace daylit::estimation
