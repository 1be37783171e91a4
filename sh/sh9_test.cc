#include "sh/sh9.h"

#include "base/latlong.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include <glm/gtc/constants.hpp>

namespace daylit::sh {
namespace {


constexpr double kPi = glm::pi<double>();

std::vector<float> LatLongOf(int w, int h, const std::function<glm::dvec3(const glm::dvec3&)>& radiance) {
  std::vector<float> rgb(static_cast<size_t>(w) * h * 3);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const glm::dvec3 l = radiance(LatLongDirection(u, v, w, h));
      for (int c = 0; c < 3; ++c) rgb[(static_cast<size_t>(v) * w + u) * 3 + c] = static_cast<float>(l[c]);
    }
  }
  return rgb;
}

glm::dvec3 RandomUnit(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
}

TEST(Sh9Test, BasisIsOrthonormalOverTheSphere) {
  // ∫ Y_i Y_j dω = δ_ij, summed over a fine lat-long grid.
  constexpr int kW = 512, kH = 256;
  std::array<std::array<double, 9>, 9> gram{};
  for (int v = 0; v < kH; ++v) {
    const double dw = LatLongTexelSolidAngle(v, kW, kH);
    for (int u = 0; u < kW; ++u) {
      const Sh9Basis y = EvalSh9(LatLongDirection(u, v, kW, kH));
      for (size_t i = 0; i < 9; ++i) {
        for (size_t j = 0; j < 9; ++j) gram[i][j] += y[i] * y[j] * dw;
      }
    }
  }
  for (size_t i = 0; i < 9; ++i) {
    for (size_t j = 0; j < 9; ++j) EXPECT_NEAR(gram[i][j], i == j ? 1.0 : 0.0, 2e-4) << i << "," << j;
  }
}

TEST(Sh9Test, UniformSkyGivesPiTimesRadianceEverywhere) {
  const std::vector<float> map = LatLongOf(256, 128, [](const glm::dvec3&) { return glm::dvec3(1.0, 2.0, 0.5); });
  const ShRgb9 sh = ProjectLatLong(map.data(), 256, 128);
  std::mt19937 rng(1);
  for (int i = 0; i < 100; ++i) {
    const glm::dvec3 e = sh.Irradiance(RandomUnit(rng));
    EXPECT_NEAR(e.x, kPi * 1.0, 2e-4);
    EXPECT_NEAR(e.y, kPi * 2.0, 4e-4);
    EXPECT_NEAR(e.z, kPi * 0.5, 1e-4);
  }
}

TEST(Sh9Test, UpperHemisphereSkyIsExactForUpAndHorizontalNormals) {
  // Radiance 1 above the horizon: exact E is π facing up, π/2 facing the horizon, 0 facing
  // down. Its band-2 coefficient L20 is 0, and bands 0 and 1 give exactly these three values.
  const std::vector<float> map = LatLongOf(512, 256, [](const glm::dvec3& d) { return glm::dvec3(d.z > 0 ? 1.0 : 0.0); });
  const ShRgb9 sh = ProjectLatLong(map.data(), 512, 256);
  EXPECT_NEAR(sh.Irradiance({0, 0, 1}).x, kPi, 1e-3);
  EXPECT_NEAR(sh.Irradiance({1, 0, 0}).x, kPi / 2, 1e-3);
  EXPECT_NEAR(sh.Irradiance({0, 0, -1}).x, 0.0, 1e-3);
}

TEST(Sh9Test, LinearRadianceHasExactCosineConvolution) {
  // L(ω) = ω·a is band 1 only: E(n) = (2π/3) a·n exactly, for any n.
  const glm::dvec3 a(0.3, -0.7, 0.5);
  std::mt19937 rng(2);
  const std::vector<float> map = LatLongOf(512, 256, [&](const glm::dvec3& d) { return glm::dvec3(glm::dot(d, a)); });
  const ShRgb9 sh = ProjectLatLong(map.data(), 512, 256);
  for (int i = 0; i < 100; ++i) {
    const glm::dvec3 n = RandomUnit(rng);
    EXPECT_NEAR(sh.Irradiance(n).x, 2.0 * kPi / 3.0 * glm::dot(a, n), 1e-3);
  }
}

}  // namespace
}  // namespace daylit::sh
