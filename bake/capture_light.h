// The light of the scene at env-map capture time, as the bake needs it: the sun (direction from
// the ephemeris, DNI from `sun_irradiance_rgb` or from the map's disc), the map with the sun disc
// removed, and a sky map in which every direction holds sky radiance.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/hdr_image.h"
#include "sky/sky_distribution.h"

namespace daylit::bake {

// Angular radius within which texels count as the sun disc (the disc is 0.27°; a rendered or
// photographed one is blurred by the optics and resampling), and the annulus outside it that
// gives the sky behind the disc.
inline constexpr double kSunDiscRadiusDeg = 1.5;
inline constexpr double kSunAnnulusOuterDeg = 3.0;

struct CaptureSun {
  glm::vec3 dir{0.0f, 0.0f, 1.0f};   // unit vector to the sun, scene coordinates (apparent)
  bool above_horizon = false;
  glm::vec3 dni_rgb{0.0f};           // the DNI used: sun_irradiance_rgb if given, else dni_from_map
  glm::vec3 dni_from_map_rgb{0.0f};  // what the map's disc integrates to above its surroundings
  size_t disc_texels = 0;            // texels replaced by the surrounding sky
  double brightest_offset_deg = 0.0; // angle from the ephemeris sun to the map's brightest texel
};

// Removes the sun disc from `env` (texels within kSunDiscRadiusDeg of `sun_dir` get the median of
// the annulus around it) and measures its DNI: Σ (L − L_annulus) dΩ over the disc. Warns when the
// map's brightest texel lies more than 2° from the ephemeris sun (a wrong north, time or map
// orientation). `given_dni` (sun_irradiance_rgb) wins over the map's own disc.
CaptureSun ExtractSun(HdrImage* env, const glm::dvec3& sun_dir, const std::optional<glm::dvec3>& given_dni,
                      const std::string& name);

// Nearest-texel radiance of a lat-long map in direction `dir`, and of texel index `texel`.
glm::vec3 Lookup(const HdrImage& env, const glm::vec3& dir);
glm::vec3 TexelRadiance(const HdrImage& env, int texel);

}  // namespace daylit::bake
