// The sun of every burst of the bundled recording, in scene coordinates, against the values
// the recording's renderer used (astropy, topocentric apparent; groundtruth/info.json). This
// checks the ephemeris, refraction and the scene's north convention together.
#include <gtest/gtest.h>

#include <cmath>

#include <nlohmann/json.hpp>

#include "base/csv.h"
#include "scene/scene.h"
#include "sunmodel/solar_position.h"

namespace daylit {
namespace {

TEST(RecordingSunTest, EveryBurstMatchesTheRenderersSun) {
  const scene::Scene scene = scene::LoadScene(DAYLIT_SOURCE_DIR "/recordings/courtyard-a");
  const nlohmann::json info = nlohmann::json::parse(
      ReadTextFile(DAYLIT_SOURCE_DIR "/recordings/courtyard-a/groundtruth/info.json"));
  const sunmodel::Atmosphere atmosphere = sunmodel::Atmosphere::Standard(scene.location.elevation_m);
  ASSERT_EQ(info["bursts"].size(), 6u);
  for (const auto& burst : info["bursts"]) {
    // "All frames of a burst use the sun at the burst's middle": halfway between its first and
    // last frame.
    const int first = burst["first_frame"].get<int>();
    const int last = first + burst["frames"].get<int>() - 1;
    const UtcTime t0 = scene.frame_times->frames[static_cast<size_t>(first)].utc;
    UtcTime middle = t0;
    middle.second += 0.5 * scene.frame_times->frames[static_cast<size_t>(last)].utc.SecondsSince(t0);
    const sunmodel::SunPosition sun =
        sunmodel::ComputeSunPosition(middle, scene.location, atmosphere, {});
    const glm::dvec3 ours = scene.GeoFrame().DirectionInScene(sun.azimuth_deg, sun.apparent_zenith_deg);
    const auto& d = burst["sun_direction_scene"];
    const glm::dvec3 theirs(d[0].get<double>(), d[1].get<double>(), d[2].get<double>());
    const double angle_deg = std::acos(std::min(1.0, glm::dot(ours, theirs))) * 180.0 / M_PI;
    // 0.01°: refraction models and the unknown pressure of the renderer differ by a few
    // thousandths at these elevations; a wrong north or time zone would be off by degrees.
    EXPECT_LT(angle_deg, 0.01) << "burst " << burst["burst"];
    EXPECT_NEAR(sun.azimuth_deg, burst["sun_azimuth_compass_deg"].get<double>(), 0.01);
    EXPECT_NEAR(sun.ApparentElevationDeg(), burst["sun_elevation_apparent_deg"].get<double>(), 0.01);
  }
}

}  // namespace
}  // namespace daylit
