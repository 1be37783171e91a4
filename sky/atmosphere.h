// A clear sky from the physics of the atmosphere: single scattering of sunlight by air molecules
// (Rayleigh) and aerosols (Mie) in a spherical atmosphere whose density falls off exponentially
// with height, with the sunlight and the scattered light both attenuated along their paths. This
// is the model of Nishita, Sirai, Tadamura and Nakamae, "Display of the Earth taking into account
// atmospheric scattering" (SIGGRAPH 1993), with the constants of Bruneton and Neyret,
// "Precomputed atmospheric scattering" (EGSR 2008): Earth radius 6360 km, atmosphere 60 km thick,
// Rayleigh scattering 33.1e-6 /m at 440 nm falling as λ⁻⁴ with a scale height of 8 km, Mie
// scattering 21e-6 /m (extinction 1/0.9 of it) with a scale height of 1.2 km and the
// Cornette-Shanks phase function with g = 0.76.
//
// daylit does not take the sky's brightness from it, only how the shape of a clear sky changes
// with the sun's elevation (the captured sky re-aimed at another sun, sky/sky_distribution.h):
// a lower sun reddens the light along its longer path, brightens the horizon around itself and
// darkens the sky opposite it. Radiance is per unit of extraterrestrial solar irradiance, per
// channel at the dominant wavelengths of the Rec.709 primaries (612, 549 and 465 nm), which is
// what the recordings' linear RGB and a camera's are.
#pragma once

#include <vector>

#include <glm/glm.hpp>

namespace daylit::sky {

// How much the air and the aerosol scatter, per metre at sea level; the defaults are Bruneton and
// Neyret's (above). A hazier sky has more aerosol (Mie) scattering: SkyDistribution fits it to the
// captured sky.
struct Scattering {
  glm::dvec3 rayleigh = RayleighRec709();
  double mie = 21e-6;
  double mie_extinction_ratio = 1.0 / 0.9;  // extinction over scattering
  double mie_g = 0.76;                      // Cornette-Shanks asymmetry

  // Rayleigh scattering of air at sea level, 33.1e-6 /m at 440 nm (Bruneton and Neyret), scaled as
  // λ⁻⁴ to the dominant wavelengths of the Rec.709 primaries (612, 549, 465 nm).
  static glm::dvec3 RayleighRec709();
};

// The atmosphere's shape: the Earth, the top of the atmosphere and how the density of air and
// aerosol falls off with height.
struct AtmosphereShape {
  double earth_radius_m = 6360e3, top_radius_m = 6420e3;
  double rayleigh_height_m = 8000.0, mie_height_m = 1200.0;
};

class Atmosphere {
 public:
  explicit Atmosphere(const AtmosphereShape& shape = {});

  // Single-scattered radiance per unit solar irradiance toward the sky direction with zenith cosine
  // `view_mu` (> 0 above the horizon; taken at the horizon below it), the sun at zenith cosine
  // `sun_mu` and at `cos_gamma` from the view direction (clamped to what the two zenith angles
  // allow), through air and aerosol that scatter as `scattering` says. Zero with the sun far
  // enough below the horizon.
  glm::dvec3 Radiance(double view_mu, double sun_mu, double cos_gamma, const Scattering& scattering = {}) const;
  // The share of the sunlight that reaches the ground through the whole atmosphere with the sun
  // at zenith cosine `sun_mu`, per channel: what colours a low sun (0 below the horizon).
  glm::dvec3 Transmittance(double sun_mu, const Scattering& scattering = {}) const;

 private:
  // The air (x) and aerosol (y) along the path from altitude h toward zenith cosine mu to the top
  // of the atmosphere, in metres at sea-level density, from a table; infinite where the ray meets
  // the ground.
  glm::dvec2 DepthToTop(double h, double mu) const;
  static constexpr int kHeights = 64, kMus = 512;
  AtmosphereShape shape_;
  std::vector<glm::dvec2> depth_;  // [height · kMus + mu]
};

// The relative optical air mass toward a sun at `apparent_elevation_deg` (refraction included, as
// the sun is seen): the air along the path over the air toward the zenith, 1 at the zenith, about
// 2 at 30°, 26 at 1° and 38 at the horizon (where 1/sin elevation is 57 at 1° and infinite at 0°).
// Kasten and Young, "Revised optical air mass tables and approximation formula", Applied Optics 28
// (1989) 4735-4738, their equation 3: within 0.5% of their tables down to a 1.6° elevation and
// within 1.3% below. Elevations below the horizon are taken at it.
double RelativeAirMass(double apparent_elevation_deg);

}  // namespace daylit::sky
