// The clear sky's radiance over the whole sphere of directions, for any sun, from one captured
// env map: a table over the zenith angle θ and the angle γ from the sun (1° × 2° bins), the form
// of the Perez and CIE sky models, which carries what matters to a wall: the bright sky near the
// horizon (up to ten times the zenith's) and the aureole around the sun.
//
// The table is the captured sky relative to a physical clear sky (sky/atmosphere.h) under the
// capture's sun: R(θ, γ) = L_captured / L_atmosphere. Under another sun the sky is
// L_atmosphere(θ, γ; that sun) · R(θ, γ). The atmosphere carries how a clear sky changes with the
// sun's elevation (a lower sun reddens the light, brightens the horizon around itself and darkens
// the sky opposite it); R carries what this sky has that the model does not (its haze, its
// aureole's width, the captured colour). Using the captured (θ, γ) table as it stood for a sun
// 9-17° from the capture's left a tenth of a shadowed wall's light wrong (docs/sky.md).
//
// Bins the capture point never saw as sky (the low sky behind the buildings, and for another sun
// the (θ, γ) pairs that sun makes and the capture's did not) take R from a separable fit
// log R ≈ g(θ) + h(γ) to the seen bins.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "base/hdr_image.h"
#include "sky/atmosphere.h"

namespace daylit::sky {

class SkyDistribution {
 public:
  SkyDistribution() = default;
  // From `env` (lat-long, sun disc removed) where `is_sky[texel]`, with the sun at unit `sun_dir`.
  SkyDistribution(const HdrImage& env, const std::vector<uint8_t>& is_sky, const glm::vec3& sun_dir);

  bool empty() const { return mean_.empty(); }
  // The unit sun this distribution is for.
  const glm::vec3& sun() const { return sun_; }
  // The aerosol scattering (Mie, per metre at sea level) that makes the atmosphere's sky most like
  // the captured one in shape.
  double MieScattering() const { return scattering_.mie; }
  // The direct sun's colour under the unit sun `sun_dir` given its irradiance `capture_dni` under
  // this distribution's sun: capture_dni times the atmosphere's transmittance there over here (a
  // lower sun's beam crosses more air and reddens). `capture_dni` itself without a physical sky.
  glm::dvec3 SunUnder(const glm::vec3& sun_dir, const glm::dvec3& capture_dni) const;
  // The same sky under the unit sun `sun_dir` (the captured sky re-aimed, above). Empty stays
  // empty. About 10 ms: call it once per sun, not per direction. `reaim` false: the table as
  // captured, only read about the new sun, its unseen bins a separable fit of log L (what daylit
  // did before the atmosphere; for comparisons).
  SkyDistribution Under(const glm::vec3& sun_dir, bool reaim = true) const;

  // Radiance toward unit `dir` (bilinear between bins).
  glm::vec3 Radiance(const glm::vec3& dir) const;
  // The diffuse horizontal irradiance ∫ L cos θ dω over the upper hemisphere, the number to
  // divide by for a distribution per unit DHI.
  glm::dvec3 HorizontalIrradiance() const;

  static constexpr int kThetaBins = 181;  // 1° from the zenith to the nadir
  static constexpr int kGammaBins = 90;   // 2° from the sun to its opposite

 private:
  static size_t BinOf(const glm::vec3& dir, const glm::vec3& sun_dir);
  // The aerosol that makes the atmosphere's sky under `sun_dir` most like the binned sky
  // (`sum` / `weight` per bin) in shape.
  static Scattering FitAerosol(const std::vector<glm::dvec3>& sum, const std::vector<double>& weight, const glm::vec3& sun_dir);
  // The atmosphere's radiance per bin under `sun_dir` (rows below the horizon take the horizon's).
  static std::vector<glm::vec3> AtmosphereTable(const glm::vec3& sun_dir, const Scattering& scattering);

  glm::vec3 sun_{0.0f, 0.0f, 1.0f};
  Scattering scattering_;  // the aerosol fitted to the captured sky
  std::shared_ptr<const std::vector<glm::vec3>> ratio_;  // R per bin: the captured sky over the atmosphere's
  std::shared_ptr<const std::vector<glm::vec3>> plain_;  // the sky per bin, unseen bins fitted as log L
  std::vector<glm::vec3> mean_;                          // the radiance per bin under sun_
};

// The sky as seen from anywhere: `env` where the capture point sees sky (`is_sky[texel]`); where
// it sees the model instead, the SkyDistribution of the visible sky at the same (θ, γ).
HdrImage SkyOnly(const HdrImage& env, const std::vector<uint8_t>& is_sky, const glm::vec3& sun_dir);

}  // namespace daylit::sky
