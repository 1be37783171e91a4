#include "scene/sun_tracker.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "base/check.h"

namespace daylit::scene {

std::string SunTrackerOptions::Check() const {
  if (!(move_threshold_deg > 0.0 && move_threshold_deg <= 5.0)) {
    return fmt::format("sun.move_threshold_deg: {} is outside (0, 5] degrees", move_threshold_deg);
  }
  return {};
}

bool SunMoved(const glm::vec3& from, const glm::vec3& to, double threshold_deg) {
  return glm::degrees(std::acos(std::clamp(glm::dot(from, to), -1.0f, 1.0f))) > threshold_deg;
}

SunTracker::SunTracker(const Scene& scene, const SunTrackerOptions& options)
    : site_(scene.location),
      atmosphere_(sunmodel::Atmosphere::Standard(scene.location.elevation_m)),
      geo_(scene.GeoFrame()),
      options_(options) {
  const std::string why = options.Check();
  DAYLIT_CHECK(why.empty(), "{}", why);
}

const TrackedSun& SunTracker::Update(const UtcTime& utc) {
  sun_.position = sunmodel::ComputeSunPosition(utc, site_, atmosphere_, {});
  const glm::vec3 own(geo_.DirectionInScene(sun_.position.azimuth_deg, sun_.position.apparent_zenith_deg));
  sun_.moved = sun_.generation == 0 || SunMoved(sun_.dir_in_scene, own, options_.move_threshold_deg);
  if (sun_.moved) {
    sun_.dir_in_scene = own;
    ++sun_.generation;
  }
  return sun_;
}

}  // namespace daylit::scene
