// scene::SunTracker: the frame's own sun as scene::SunAt computes it, and the one sun-moved
// rule: a move counts once the direction is more than the threshold from the last that counted.
#include <gtest/gtest.h>

#include <cmath>

#include "base/check.h"
#include "scene/scene.h"
#include "scene/sun_tracker.h"

namespace daylit::scene {
namespace {

glm::vec3 Rotated(const glm::vec3& v, double degrees) {  // about the z axis
  const float a = static_cast<float>(glm::radians(degrees));
  return {std::cos(a) * v.x - std::sin(a) * v.y, std::sin(a) * v.x + std::cos(a) * v.y, v.z};
}

TEST(SunTrackerTest, SunMovedIsTheAngleAgainstTheThreshold) {
  const glm::vec3 sun = glm::normalize(glm::vec3(0.3f, 0.5f, 0.8f));
  // At 58° from the pole a rotation by φ about z turns the vector by about φ·sin(58°).
  const double per_degree = std::sqrt(1.0 - 0.8 * 0.8 / (0.3 * 0.3 + 0.5 * 0.5 + 0.8 * 0.8));
  EXPECT_FALSE(SunMoved(sun, sun, 0.05));
  EXPECT_FALSE(SunMoved(sun, Rotated(sun, 0.03 / per_degree), 0.05));
  EXPECT_TRUE(SunMoved(sun, Rotated(sun, 0.08 / per_degree), 0.05));
  EXPECT_TRUE(SunMoved(sun, -sun, 0.05));
}

TEST(SunTrackerTest, FollowsTheEphemerisAndCountsMovesPastTheThreshold) {
  const Scene scene = LoadScene(DAYLIT_SOURCE_DIR "/recordings/courtyard-a");
  SunTracker tracker(scene);
  const UtcTime start = ParseUtcTime("2026-06-21T10:00:00Z", "test");
  int moves = 0;
  glm::vec3 last_counted{0.0f};
  // Ten minutes at 1 s steps: the sun moves about 0.004° a second at this site, so a move past
  // 0.05° counts every 12-13 s, each from the last counted direction.
  for (int s = 0; s <= 600; ++s) {
    const UtcTime utc = UtcFromUnixSeconds(UnixSeconds(start) + s);
    const TrackedSun& sun = tracker.Update(utc);
    const SceneSun exact = SunAt(scene, utc);
    EXPECT_DOUBLE_EQ(sun.position.azimuth_deg, exact.position.azimuth_deg);
    EXPECT_EQ(sun.moved, s == 0 || SunMoved(last_counted, glm::vec3(exact.dir), 0.05)) << s;
    if (sun.moved) {
      EXPECT_NEAR(glm::length(sun.dir_in_scene - glm::vec3(exact.dir)), 0.0f, 1e-6f) << s;
      last_counted = sun.dir_in_scene, ++moves;
    } else {
      EXPECT_EQ(sun.dir_in_scene, last_counted) << s;  // the stages keep their work
      EXPECT_FALSE(SunMoved(sun.dir_in_scene, glm::vec3(exact.dir), 0.05)) << s;
    }
    EXPECT_EQ(sun.generation, moves);
  }
  EXPECT_GE(moves, 600 / 14);
  EXPECT_LE(moves, 600 / 11 + 1);
}

TEST(SunTrackerTest, OptionsOutOfRangeAreNamedAndRefused) {
  SunTrackerOptions options;
  options.move_threshold_deg = 0.0;
  EXPECT_NE(options.Check().find("sun.move_threshold_deg"), std::string::npos);
  const Scene scene = LoadScene(DAYLIT_SOURCE_DIR "/recordings/courtyard-a");
  EXPECT_THROW(SunTracker(scene, options), InvariantError);
}

}  // namespace
}  // namespace daylit::scene
