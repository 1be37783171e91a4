// The sun of each frame for the whole pipeline: its position from the ephemeris at the frame's
// time, its direction in scene coordinates, and the one rule that says when it has moved enough
// for the sun-dependent work (shadow rays, transfer terms, shadow maps) to be redone.
#pragma once

#include <string>

#include <glm/glm.hpp>

#include "base/utc_time.h"
#include "scene/scene.h"
#include "sunmodel/geo_frame.h"
#include "sunmodel/solar_position.h"

namespace daylit::scene {

struct SunTrackerOptions {
  // Degrees, (0, 5]: the sun counts as moved once its direction is more than this from the last
  // direction that counted. 0.05° is 12 s of the sun's motion; a 10 m wall's shadow tip moves by
  // under 1 cm per 0.05° at 45° elevation, far below a pixel of the bundled cameras.
  double move_threshold_deg = 0.05;

  // Empty when every field is in range, else the first problem ("sun.move_threshold_deg: ...").
  std::string Check() const;
};

// True when `to` is more than `threshold_deg` from `from` (both unit vectors, any frame). The one
// sun-moved rule: every stage that caches sun-dependent work asks this, through SunTracker.
bool SunMoved(const glm::vec3& from, const glm::vec3& to, double threshold_deg);

struct TrackedSun {
  sunmodel::SunPosition position;   // at the frame's own time (apparent zenith, azimuth east of north)
  // Unit vector toward the sun as every stage uses it: the frame's own direction when `moved`,
  // else that of the last frame that moved (within move_threshold_deg of the frame's own).
  // Stages redo their sun-dependent work when it changes, and only then.
  glm::vec3 dir_in_scene{0.0f, 0.0f, 1.0f};
  bool moved = true;                // the first update, or SunMoved since the last update that moved
  int generation = 0;               // counts the updates that moved, from 1
};

// Not thread-safe; one per stream of frames.
class SunTracker {
 public:
  // `options` must Check() empty (a broken caller otherwise: CHECK).
  explicit SunTracker(const Scene& scene, const SunTrackerOptions& options = {});

  // The sun at `utc`; `moved` says whether the stages must redo their sun-dependent work.
  const TrackedSun& Update(const UtcTime& utc);
  const TrackedSun& current() const { return sun_; }

 private:
  sunmodel::GeoSite site_;
  sunmodel::Atmosphere atmosphere_;
  sunmodel::SceneGeoFrame geo_;
  SunTrackerOptions options_;
  TrackedSun sun_;
};

}  // namespace daylit::scene
