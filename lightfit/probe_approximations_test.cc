// lightfit::ProbeApproximations (seed 002's benchmark as a library): the automatic N is the
// smallest N under the threshold, checked against every N fitted one by one; fits are cached;
// SH9 is exact for a map it can represent; out-of-range calls are broken invariants.
#include <gtest/gtest.h>

#include <cmath>

#include "base/check.h"
#include "lightfit/probe_approximations.h"
#include "base/latlong.h"

namespace daylit::lightfit {
namespace {

// A sky of radiance 1 over a ground of 0.3, with two bright patches: lights are needed for them.
HdrImage TwoSunSky(int width) {
  HdrImage map{width, width / 2, std::vector<float>(static_cast<size_t>(width) * width / 2 * 3)};
  const glm::dvec3 a = glm::normalize(glm::dvec3(0.5, 0.2, 0.8)), b = glm::normalize(glm::dvec3(-0.6, -0.3, 0.4));
  for (int v = 0; v < map.height; ++v) {
    for (int u = 0; u < map.width; ++u) {
      const glm::dvec3 d = LatLongDirection(u, v, map.width, map.height);
      float l = d.z > 0.0 ? 1.0f : 0.3f;
      if (glm::dot(d, a) > std::cos(glm::radians(6.0))) l += 200.0f;
      if (glm::dot(d, b) > std::cos(glm::radians(8.0))) l += 60.0f;
      float* p = map.Pixel(u, v);
      p[0] = l, p[1] = 0.9f * l, p[2] = 0.8f * l;
    }
  }
  return map;
}

TEST(ProbeApproximationsTest, AutomaticNIsTheSmallestNUnderTheThreshold) {
  const HdrImage map = TwoSunSky(128);
  for (const Method method : {Method::kMedianCut, Method::kIrradianceOptimization}) {
    ProbeApproximations table(map, {});
    const double threshold = 0.05;
    const std::optional<int> automatic = table.AutomaticN(method, threshold);
    ASSERT_TRUE(automatic.has_value()) << MethodKey(method);
    // An independent search: every N from 1 until the first under the threshold.
    ProbeApproximations one_by_one(map, {});
    int first = 0;
    for (int n = 1; n <= *automatic && first == 0; ++n) {
      if (one_by_one.Lights(method, n).error.mean < threshold) first = n;
    }
    EXPECT_EQ(first, *automatic) << MethodKey(method);
    EXPECT_LT(table.Lights(method, *automatic).error.mean, threshold);
    EXPECT_GT(*automatic, 1) << "the two patches need more than one light";
  }
}

TEST(ProbeApproximationsTest, FitsAreCachedAndListedInOrder) {
  const HdrImage map = TwoSunSky(64);
  ProbeApproximations table(map, {});
  const LightsApproximation& four = table.Lights(Method::kMedianCut, 4);
  table.Lights(Method::kMedianCut, 1);
  EXPECT_EQ(&table.Lights(Method::kMedianCut, 4), &four);
  const std::vector<const LightsApproximation*> fitted = table.Fitted(Method::kMedianCut);
  ASSERT_EQ(fitted.size(), 2u);
  EXPECT_EQ(fitted[0]->n, 1);
  EXPECT_EQ(fitted[1]->n, 4);
  EXPECT_EQ(four.lights.lights.size(), 4u);
  EXPECT_TRUE(table.Fitted(Method::kIrradianceOptimization).empty());
}

TEST(ProbeApproximationsTest, Sh9IsExactForAnSh9MapAndOutOfRangeIsABrokenInvariant) {
  // Radiance 1 + 0.5·z is in SH's first two bands: its irradiance is represented exactly, up to
  // the map's quadrature.
  HdrImage map{128, 64, std::vector<float>(128 * 64 * 3)};
  for (int v = 0; v < map.height; ++v) {
    for (int u = 0; u < map.width; ++u) {
      const float l = static_cast<float>(1.0 + 0.5 * LatLongDirection(u, v, map.width, map.height).z);
      float* p = map.Pixel(u, v);
      p[0] = p[1] = p[2] = l;
    }
  }
  ProbeApproximations table(map, {});
  EXPECT_LT(table.Sh9().error.max, 2e-3);
  EXPECT_THROW(table.Lights(Method::kMedianCut, 0), InvariantError);
  EXPECT_THROW(table.Lights(Method::kIrradianceOptimization, 129), InvariantError);
  EXPECT_THROW(table.Lights(Method::kSh9, 9), InvariantError);
}

}  // namespace
}  // namespace daylit::lightfit
