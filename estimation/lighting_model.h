// The one radiometric model of daylit (docs/design.md), per colour channel, for a Lambertian
// point x with albedo ρ and normal n:
//
//   L(x) = ρ/π · ( E_sun · s(x) · max(0, n·l) + E_sky · V(x) )
//
// E_sun: direct normal irradiance of the sun (DNI); E_sky: diffuse horizontal irradiance of the
// sky (DHI); l: unit vector to the sun; s ∈ [0, 1]: sun visibility; V ∈ [0, 1]: cosine-weighted
// visible-sky fraction. Radiance in the units of E over steradians. For a fixed sun direction
// L is linear in (E_sun, E_sky), which is what makes the per-frame fit a small linear problem.
#pragma once

#include <glm/glm.hpp>

namespace daylit::estimation {

// What is estimated per frame: RGB irradiances, ≥ 0.
struct SunSky {
  glm::dvec3 sun_rgb{0.0};  // E_sun, DNI
  glm::dvec3 sky_rgb{0.0};  // E_sky, DHI
};

// The geometric factors of a point under a sun direction.
struct ShadingTerms {
  double sun = 0.0;  // s · max(0, n·l): fraction of DNI that reaches the point, per unit
  double sky = 0.0;  // V: fraction of DHI that reaches the point
};

// s · max(0, n·l) and V for a point with unit normal `n`, unit sun vector `l`.
ShadingTerms TermsOf(const glm::dvec3& n, const glm::dvec3& l, double sun_visibility,
                     double sky_visibility);

// Irradiance E(x) = E_sun·s·max(0,n·l) + E_sky·V, per channel.
glm::dvec3 Irradiance(const ShadingTerms& terms, const SunSky& light);

// Radiance L(x) = ρ/π · E(x), per channel.
glm::dvec3 Radiance(const glm::dvec3& albedo, const ShadingTerms& terms, const SunSky& light);

// Albedo by inverse rendering, ρ = π·L / E; 0 where E is 0.
glm::dvec3 AlbedoOf(const glm::dvec3& radiance, const glm::dvec3& irradiance);

}  // namespace daylit::estimation
