#include "relight/new_light.h"

#include "relight/image_relight.h"

namespace daylit::relight {

estimation::SunSky NewLight(const RelightTarget& target, const estimation::SunSky& now, double now_elevation_deg) {
  estimation::SunSky light = target.light ? *target.light : now;
  if (target.clear_sky) {
    const glm::dvec2 f = ClearSkyFactors(now_elevation_deg, target.sun_elevation_deg, target.month);
    light.sun_rgb *= f.x, light.sky_rgb *= f.y;
  }
  if (target.e_sun) light.sun_rgb = *target.e_sun;
  if (target.e_sky) light.sky_rgb = *target.e_sky;
  if (target.sun_dir_in_scene.z <= 0.0f) light.sun_rgb = glm::dvec3(0.0);
  return light;
}

}  // namespace daylit::relight
