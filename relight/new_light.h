// The light a frame is relit to (daylit relight, seed 004): a new sun, and the new E_sun, E_sky
// either those of another frame (--like-frame), or the frame's own estimate scaled by a clear-sky
// model (--clear-sky), or given outright (--e-sun, --e-sky). A sun below the horizon gives a
// sky-only light.
#pragma once

#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "estimation/sun_sky_fit.h"

namespace daylit::relight {

struct RelightTarget {
  glm::vec3 sun_dir_in_scene{0.0f, 0.0f, 1.0f};  // unit, toward the new sun
  double sun_elevation_deg = 90.0;               // apparent
  int month = 6;                                 // 1..12, for the clear-sky model
  std::optional<estimation::SunSky> light;       // a fixed new light (--like-frame's fit)
  double overcast_share = 0.0;                   // its E_overcast / E_sky
  bool clear_sky = false;                        // scale the frame's light by ClearSkyFactors
  std::optional<glm::dvec3> e_sun, e_sky;        // radiance units, replace the above
  std::string what;                              // for the log: "the sun at ..."
};

// The light a frame whose own estimate is `now` (its sun `now_elevation_deg` up) is relit to.
estimation::SunSky NewLight(const RelightTarget& target, const estimation::SunSky& now, double now_elevation_deg);

// E_overcast / E_sky of the new light: the fixed light's, else the frame's own.
inline double NewOvercastShare(const RelightTarget& target, double now_overcast_share) {
  return target.light ? target.overcast_share : now_overcast_share;
}

}  // namespace daylit::relight
