#include "base/latlong.h"

#include <gtest/gtest.h>

#include <random>

#include <glm/gtc/constants.hpp>

namespace daylit {
namespace {

TEST(LatLongTest, ConventionOfTheDesignDoc) {
  EXPECT_GT(LatLongDirection(512, 0, 1024, 512).z, 0.9999);          // row 0: zenith
  EXPECT_NEAR(LatLongDirection(511.5, 255.5, 1024, 512).y, 1.0, 1e-12);  // centre: +Y
  EXPECT_NEAR(LatLongDirection(767.5, 255.5, 1024, 512).x, 1.0, 1e-12);  // right: +X
  EXPECT_NEAR(LatLongDirection(255.5, 255.5, 1024, 512).x, -1.0, 1e-12);
  double total = 0.0;
  for (int v = 0; v < 512; ++v) total += 1024 * LatLongTexelSolidAngle(v, 1024, 512);
  EXPECT_NEAR(total, 4.0 * glm::pi<double>(), 1e-9);
}

TEST(LatLongTest, CoordinatesInvertDirections) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-0.49, 1023.49), v(0.0, 511.0);
  for (int i = 0; i < 10000; ++i) {
    const double uu = u(rng), vv = v(rng);
    const glm::dvec2 back = LatLongCoordinates(LatLongDirection(uu, vv, 1024, 512), 1024, 512);
    ASSERT_NEAR(back.y, vv, 1e-7);
    ASSERT_NEAR(std::remainder(back.x - uu, 1024.0), 0.0, 1e-7);
  }
  for (int t = 0; t < 1024 * 512; t += 997) {
    ASSERT_EQ(LatLongTexel(LatLongDirection(t % 1024, t / 1024, 1024, 512), 1024, 512), t);
  }
}

}  // namespace
}  // namespace daylit
