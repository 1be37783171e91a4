#include "lightfit/lights.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "sh/exact_irradiance.h"
#include "base/latlong.h"

namespace daylit::lightfit {
namespace {


TEST(MedianCutTest, LightsCarryTheMapsPowerAndSplitItEvenly) {
  const HdrImage map = scene::ReadHdrImage(DAYLIT_SOURCE_DIR "/probes/galileo_latlong_1024x512.hdr");
  const LightSet set = MedianCut(map, 4);
  ASSERT_EQ(set.lights.size(), 16u);
  glm::dvec3 total(0.0), lights(0.0);
  for (int v = 0; v < map.height; ++v) {
    const double solid_angle = LatLongTexelSolidAngle(v, map.width, map.height);
    for (int u = 0; u < map.width; ++u) {
      const float* p = map.Pixel(u, v);
      total += solid_angle * glm::dvec3(p[0], p[1], p[2]);
    }
  }
  for (const DirectionalLight& l : set.lights) {
    lights += glm::dvec3(l.irradiance);
    EXPECT_NEAR(glm::length(l.direction), 1.0f, 1e-5f);
  }
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(lights[c], total[c], 1e-6 * total[c]);
  // Equal luminance per region, to within one row or column of texels.
  const auto luminance = [](const glm::vec3& x) { return 0.2126 * x.x + 0.7152 * x.y + 0.0722 * x.z; };
  const double share = luminance(glm::vec3(total)) / 16.0;
  for (const DirectionalLight& l : set.lights) EXPECT_NEAR(luminance(l.irradiance), share, 0.2 * share);
}

TEST(MedianCutTest, AnyNumberOfLightsKeepsThePowerAndExtendsTheLevels) {
  const HdrImage map = scene::ReadHdrImage(DAYLIT_SOURCE_DIR "/probes/stpeters_latlong_1024x512.hdr");
  const LightSet eight = MedianCut(map, 3), five = MedianCutLights(map, 5), also_eight = MedianCutLights(map, 8);
  ASSERT_EQ(five.lights.size(), 5u);
  ASSERT_EQ(also_eight.lights.size(), 8u);
  glm::dvec3 power5(0.0), power8(0.0);
  for (const DirectionalLight& l : five.lights) power5 += glm::dvec3(l.irradiance);
  for (size_t i = 0; i < 8; ++i) {
    power8 += glm::dvec3(eight.lights[i].irradiance);
    EXPECT_EQ(eight.lights[i].direction, also_eight.lights[i].direction);  // MedianCut is the 2^k case
  }
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(power5[c], power8[c], 1e-6 * power8[c]);
}

TEST(MedianCutTest, Seed002sMaxErrorOnGalileoAndOurMean) {
  // Seed 002, Fig. 2 caption: median cut with 8 lights on Galileo's tomb, about 25% mean and over
  // 75% max per-normal relative error; more lights, less error. The max is reproduced; the mean
  // is half the seed's (docs/lightfit.md says why), so it is held to what we measure.
  const HdrImage map = scene::ReadHdrImage(DAYLIT_SOURCE_DIR "/probes/galileo_latlong_1024x512.hdr");
  const std::vector<glm::vec3> normals = sh::IcosahedronNormals(5);
  const std::vector<glm::dvec3> truth = sh::ExactIrradiance(map, normals);
  double previous = 1e9;
  for (const int levels : {3, 5, 7}) {
    const ApproximationError e = RelativeError(truth, MedianCut(map, levels).Irradiance(normals));
    std::printf("median cut, %d lights: mean %.1f%%, max %.1f%% over %zu normals\n", 1 << levels, 100 * e.mean,
                100 * e.max, e.normals);
    if (levels == 3) {
      // Measured 12.3% mean, 86.8% max.
      EXPECT_NEAR(e.mean, 0.123, 0.01);
      EXPECT_GT(e.max, 0.75);
    }
    EXPECT_LT(e.mean, previous);
    previous = e.mean;
  }
}

}  // namespace
}  // namespace daylit::lightfit
