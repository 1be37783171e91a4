#include "sh/exact_irradiance.h"

#include <gtest/gtest.h>

#include <random>

#include <glm/gtc/constants.hpp>

#include "bake/sampling.h"
#include "base/latlong.h"

namespace daylit::sh {
namespace {

// Texel by texel, the definition itself.
glm::dvec3 BruteForce(const HdrImage& map, const glm::vec3& n) {
  glm::dvec3 e(0.0);
  for (int v = 0; v < map.height; ++v) {
    const double solid_angle = LatLongTexelSolidAngle(v, map.width, map.height);
    for (int u = 0; u < map.width; ++u) {
      const double c = glm::dot(glm::dvec3(n), LatLongDirection(u, v, map.width, map.height));
      if (c <= 0.0) continue;
      const float* p = map.Pixel(u, v);
      e += c * solid_angle * glm::dvec3(p[0], p[1], p[2]);
    }
  }
  return e;
}

TEST(ExactIrradianceTest, RowArcsGiveTheTexelByTexelSum) {
  // A rough random map (every texel independent: the worst case for the arc ends).
  HdrImage map{256, 128, std::vector<float>(256 * 128 * 3)};
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> radiance(0.0f, 10.0f);
  for (float& x : map.rgb) x = radiance(rng);
  std::vector<glm::vec3> normals = bake::SphericalFibonacci(200);
  normals.push_back(glm::vec3(0, 0, 1)), normals.push_back(glm::vec3(0, 0, -1)), normals.push_back(glm::vec3(1, 0, 0));
  const std::vector<glm::dvec3> fast = ExactIrradiance(map, normals);
  for (size_t i = 0; i < normals.size(); ++i) {
    const glm::dvec3 want = BruteForce(map, normals[i]);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(fast[i][c], want[c], 1e-7 * want[c]) << i;  // the same sum, in another order
  }
}

TEST(ExactIrradianceTest, UniformSkyAndHalfSky) {
  HdrImage map{512, 256, std::vector<float>(512 * 256 * 3, 1.0f)};
  const std::vector<glm::dvec3> e = ExactIrradiance(map, {glm::vec3(0, 0, 1), glm::normalize(glm::vec3(1, 2, 3))});
  EXPECT_NEAR(e[0].x, glm::pi<double>(), 1e-4);  // uniform radiance 1: π for every normal
  EXPECT_NEAR(e[1].y, glm::pi<double>(), 1e-4);
}

TEST(ExactIrradianceTest, SubdividedIcosahedronHasSeed002sNormals) {
  const std::vector<glm::vec3> normals = IcosahedronNormals(5);
  ASSERT_EQ(normals.size(), 20480u);
  glm::dvec3 mean(0.0);
  for (const glm::vec3& n : normals) {
    EXPECT_NEAR(glm::length(n), 1.0f, 1e-5f);
    mean += glm::dvec3(n);
  }
  EXPECT_LT(glm::length(mean / 20480.0), 1e-6);  // spread over the whole sphere
}

}  // namespace
}  // namespace daylit::sh
