#include "sunmodel/geo_frame.h"

#include <gtest/gtest.h>

#include <random>

namespace daylit::sunmodel {
namespace {

constexpr double kEps = 1e-12;

TEST(SceneGeoFrameTest, NorthAzimuthRotatesTheHorizon) {
  // courtyard-a: scene +Y points to compass azimuth −20°.
  const SceneGeoFrame frame({57.0488, 9.9217, 10.0}, -20.0);
  const glm::dvec3 y = frame.DirectionInScene(-20.0 + 360.0, 90.0);
  EXPECT_NEAR(y.x, 0.0, kEps);
  EXPECT_NEAR(y.y, 1.0, kEps);
  EXPECT_NEAR(y.z, 0.0, kEps);
  // Scene +X is 90° clockwise of +Y seen from above: compass 70°.
  const glm::dvec3 x = frame.DirectionInScene(70.0, 90.0);
  EXPECT_NEAR(x.x, 1.0, kEps);
  EXPECT_NEAR(x.y, 0.0, kEps);
  EXPECT_NEAR(frame.DirectionInScene(123.0, 0.0).z, 1.0, kEps);  // zenith is +Z
}

TEST(SceneGeoFrameTest, DirectionRoundTripsAndIsUnit) {
  const SceneGeoFrame frame({-33.9, 18.4, 0.0}, 37.5);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> az(0, 360), zen(0.5, 179.5);
  for (int i = 0; i < 1000; ++i) {
    const double a = az(rng), z = zen(rng);
    const glm::dvec3 d = frame.DirectionInScene(a, z);
    ASSERT_NEAR(glm::length(d), 1.0, kEps);
    double a2 = 0, z2 = 0;
    frame.AzimuthZenithOf(d, &a2, &z2);
    ASSERT_NEAR(std::remainder(a2 - a, 360.0), 0.0, 1e-9);
    ASSERT_NEAR(z2, z, 1e-9);
  }
}

TEST(SceneGeoFrameTest, ScenePointsMapToWgs84) {
  const GeoSite origin{57.0488, 9.9217, 10.0};
  const SceneGeoFrame frame(origin, 0.0);  // +Y north
  // 1000 m north along the meridian is 1000 / 111,360 m per degree at 57° N (WGS84).
  const GeoSite north = frame.GeodeticOf({0.0, 1000.0, 0.0});
  EXPECT_NEAR(north.latitude_deg - origin.latitude_deg, 1000.0 / 111360.0, 2e-5);
  EXPECT_NEAR(north.longitude_deg, origin.longitude_deg, 1e-9);
  const glm::dvec3 back = frame.SceneOf(north);
  EXPECT_NEAR(back.y, 1000.0, 1e-6);
  EXPECT_NEAR(frame.SceneOf(origin).z, 0.0, 1e-6);
}

}  // namespace
}  // namespace daylit::sunmodel
