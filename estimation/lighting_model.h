// The one radiometric model of daylit (docs/design.md), per colour channel, for a Lambertian
// point x with albedo ρ:
//
//   L(x) = ρ/π · E(x),   E(x) = E_sun·T_sun(x) + E_clear·T_clear(x) + E_overcast·T_overcast(x)
//
// E_sun: direct normal irradiance of the sun (DNI); E_clear + E_overcast = E_sky, the diffuse
// horizontal irradiance of the sky (DHI), split into a part shaped like the captured clear sky
// and a uniform overcast part. T: the point's transfer, its irradiance per unit of each part
// (direct and reflected; estimation/transfer.h computes it). Without interreflection and with a
// uniform sky, T_sun = s·max(0, n·l) (s the sun's visibility) and T_clear = T_overcast = V (the
// cosine-weighted visible-sky fraction), which is seed 001's model. Radiance is in the units of
// E over steradians. For a fixed sun E is linear in the parts: the per-frame fit is a small
// linear problem, and every stage (the relit env map, the relit image, the objects' shadows)
// combines per-part terms with these weights.
#pragma once

#include <glm/glm.hpp>

namespace daylit::estimation {

// What is estimated per frame: RGB irradiances, ≥ 0.
struct SunSky {
  glm::dvec3 sun_rgb{0.0};  // E_sun, DNI
  glm::dvec3 sky_rgb{0.0};  // E_sky, DHI
};

// The three parts of the light, RGB, ≥ 0: E_sun, E_clear and E_overcast, E_clear + E_overcast =
// E_sky.
struct LightParts {
  glm::vec3 sun{0.0f}, clear{0.0f}, overcast{0.0f};
};
// The parts of `light` with the overcast share o (clamped to [0, 1]). Clouds are grey: the
// overcast part is the same in every channel, o times E_sky's mean over the channels (at most
// E_sky in each), and the clear part, the rest, carries the sky's colour. An overcast part with
// the sky's own colour (o·E_sky per channel) made the clear sky's blue, mixed into a passing
// cloud, into overcast blue: under a cloud the fit then took 2% of E_sky's blue for sun, E_sun's
// blue 6-10% high (courtyard-a's overcast burst, courtyard-c's cloud in burst 1). "Grey" is the
// camera's white: equal linear RGB.
LightParts SplitLight(const SunSky& light, double overcast_share);

// Irradiance at a point per unit of each part, RGB (reflected light takes the colour of the
// surfaces it comes from).
struct Transfer {
  glm::vec3 sun{0.0f};       // per unit DNI
  glm::vec3 clear{0.0f};     // per unit DHI of the captured sky's distribution (= overcast without one)
  glm::vec3 overcast{0.0f};  // per unit DHI of a uniform sky
};

// E = E_sun·T_sun + E_clear·T_clear + E_overcast·T_overcast, per channel.
inline glm::vec3 Irradiance(const LightParts& light, const glm::vec3& t_sun, const glm::vec3& t_clear,
                            const glm::vec3& t_overcast) {
  return light.sun * t_sun + light.clear * t_clear + light.overcast * t_overcast;
}
inline glm::vec3 Irradiance(const LightParts& light, const Transfer& t) {
  return Irradiance(light, t.sun, t.clear, t.overcast);
}

}  // namespace daylit::estimation
