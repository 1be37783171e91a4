#include "estimation/lighting_model.h"

#include <gtest/gtest.h>

#include <glm/gtc/constants.hpp>

namespace daylit::estimation {
namespace {

TEST(LightingModelTest, RecordingFormatDefinitionOfUnits) {
  // recording-format.md: a Lambertian surface of albedo ρ facing the sun, unshadowed, open sky,
  // horizontal with the sun at the zenith has L = ρ/π · (E_sun + E_sky).
  const SunSky light{{86.0, 63.0, 37.0}, {9.8, 9.7, 10.0}};
  const glm::dvec3 up(0, 0, 1);
  const glm::dvec3 l = Radiance(glm::dvec3(0.5), TermsOf(up, up, 1.0, 1.0), light);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(l[c], 0.5 / glm::pi<double>() * (light.sun_rgb[c] + light.sky_rgb[c]), 1e-12);
  }
}

TEST(LightingModelTest, ShadowBackfaceAndObliqueSun) {
  const SunSky light{{100, 100, 100}, {10, 20, 30}};
  const glm::dvec3 n(0, 0, 1);
  const glm::dvec3 l = glm::normalize(glm::dvec3(1, 0, 1));  // 45° elevation
  EXPECT_NEAR(Irradiance(TermsOf(n, l, 1.0, 0.8), light).x, 100 * std::sqrt(0.5) + 8, 1e-12);
  EXPECT_NEAR(Irradiance(TermsOf(n, l, 0.0, 0.8), light).z, 24, 1e-12);  // in shadow: sky only
  EXPECT_NEAR(Irradiance(TermsOf(-n, l, 1.0, 0.5), light).y, 10, 1e-12);  // facing away
}

TEST(LightingModelTest, AlbedoInvertsRadiance) {
  const SunSky light{{50, 40, 30}, {5, 6, 7}};
  const ShadingTerms t = TermsOf(glm::normalize(glm::dvec3(0.2, -0.3, 1)), glm::normalize(glm::dvec3(-1, 2, 3)), 0.7, 0.6);
  const glm::dvec3 albedo(0.31, 0.42, 0.53);
  const glm::dvec3 back = AlbedoOf(Radiance(albedo, t, light), Irradiance(t, light));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(back[c], albedo[c], 1e-12);
  EXPECT_EQ(AlbedoOf(glm::dvec3(1.0), glm::dvec3(0.0)), glm::dvec3(0.0));
}

}  // namespace
}  // namespace daylit::estimation
