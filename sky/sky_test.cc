#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

#include <glm/gtc/constants.hpp>

#include "base/latlong.h"
#include "sky/atmosphere.h"
#include "sky/sky_distribution.h"

namespace daylit::sky {
namespace {

glm::vec3 SunAt(double elevation_deg, double azimuth_deg) {
  const double e = glm::radians(elevation_deg), a = glm::radians(azimuth_deg);
  return glm::vec3(glm::dvec3(std::cos(e) * std::sin(a), std::cos(e) * std::cos(a), std::sin(e)));
}

TEST(AtmosphereTest, AThinAirOnlyAtmosphereSeenAtTheZenithIsBetaTimesScaleHeightTimesPhase) {
  // Optically thin air and no aerosol: the zenith's single scattering is β·H·P_R(γ) (the density
  // integrates to its scale height, nothing is lost on the way), for the sun 60° from the zenith.
  Scattering thin;
  thin.rayleigh = glm::dvec3(1e-9, 2e-9, 4e-9);
  thin.mie = 0.0;
  const Atmosphere air;
  const double cos_gamma = std::cos(glm::radians(60.0));
  const glm::dvec3 l = air.Radiance(1.0, cos_gamma, cos_gamma, thin);
  const double phase = 3.0 / (16.0 * glm::pi<double>()) * (1.0 + cos_gamma * cos_gamma);
  // The atmosphere's top at 60 km cuts the exponential at e^-7.5: negligible.
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(l[c] / (thin.rayleigh[c] * 8000.0 * phase), 1.0, 0.01) << c;
}

TEST(AtmosphereTest, ALowSunReddensTheSkyAndTheEarthsShadowDarkensIt) {
  const Atmosphere air;
  const double zenith_high = 1.0, sun_high = std::sin(glm::radians(60.0)), sun_low = std::sin(glm::radians(5.0));
  const glm::dvec3 high = air.Radiance(zenith_high, sun_high, sun_high);
  const glm::dvec3 low = air.Radiance(zenith_high, sun_low, sun_low);
  EXPECT_GT(high.z, high.x);  // a blue sky
  EXPECT_GT(low.x / low.z, 1.1 * high.x / high.z);  // the low sun's light is redder (measured: 16%)
  const glm::dvec3 night = air.Radiance(1.0, std::sin(glm::radians(-20.0)), std::sin(glm::radians(-20.0)));
  EXPECT_LT(night.y, 1e-3 * high.y);
}

TEST(AtmosphereTest, RelativeAirMassIsKastenAndYoungsAndTheAtmospheresOwnPath) {
  // Kasten and Young's tabulated air masses (their Table 1): 1 at the zenith, 26.31 at 1° and
  // 38.09 at the horizon; their formula is within 0.5% above 1.6° and within 1.3% below.
  EXPECT_NEAR(RelativeAirMass(90.0), 1.0, 1e-3);
  EXPECT_NEAR(RelativeAirMass(1.0) / 26.31, 1.0, 0.013);
  EXPECT_NEAR(RelativeAirMass(0.0) / 38.09, 1.0, 0.013);
  EXPECT_DOUBLE_EQ(RelativeAirMass(-3.0), RelativeAirMass(0.0));
  // The same ratio from the physical atmosphere's own transmittance (Rayleigh only, a spherical
  // shell without refraction, one scale height): the optical depth toward the sun over the
  // zenith's. Refraction and the real air's profile part them only near the horizon (1.6% at 5°, 4% at 2°).
  Scattering air_only;
  air_only.mie = 0.0;
  const Atmosphere air;
  const double zenith_depth = -std::log(air.Transmittance(1.0, air_only).y);
  for (const double elevation : {60.0, 30.0, 15.0, 5.0, 2.0}) {
    const double path = -std::log(air.Transmittance(std::sin(glm::radians(elevation)), air_only).y) / zenith_depth;
    EXPECT_NEAR(RelativeAirMass(elevation) / path, 1.0, elevation >= 15.0 ? 0.005 : (elevation >= 5.0 ? 0.02 : 0.05)) << elevation << "°: " << path;
  }
}

// A lat-long map of `sky` under `sun`, with the texels below `hidden_below_deg` of elevation in
// the half of the sky beyond azimuth 0° hidden (buildings in front of the capture point).
HdrImage MapOf(const std::function<glm::vec3(const glm::vec3&)>& sky, std::vector<uint8_t>* is_sky,
               double hidden_below_deg) {
  const int w = 360, h = 180;
  HdrImage env{w, h, std::vector<float>(static_cast<size_t>(w) * h * 3)};
  is_sky->assign(static_cast<size_t>(w) * h, 0);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const glm::vec3 d(LatLongDirection(u, v, w, h));
      if (d.z <= 0.0f) continue;
      const float elevation = glm::degrees(std::asin(d.z));
      (*is_sky)[static_cast<size_t>(v) * w + u] = !(d.x > 0.0f && elevation < hidden_below_deg);
      const glm::vec3 l = sky(d);
      for (int c = 0; c < 3; ++c) env.Pixel(u, v)[c] = l[c];
    }
  }
  return env;
}

// The median over the upper hemisphere of |a/b − 1| per channel, and its largest.
double WorstMedianError(const SkyDistribution& a, const std::function<glm::vec3(const glm::vec3&)>& b) {
  std::vector<double> e[3];
  for (int t = 1; t < 89; t += 2) {
    for (int p = 0; p < 360; p += 3) {
      const glm::vec3 d = SunAt(90.0 - t, p);
      const glm::vec3 x = a.Radiance(d), y = b(d);
      for (int c = 0; c < 3; ++c) e[c].push_back(std::abs(x[c] / y[c] - 1.0));
    }
  }
  double worst = 0.0;
  for (auto& v : e) {
    std::nth_element(v.begin(), v.begin() + static_cast<ptrdiff_t>(v.size() / 2), v.end());
    worst = std::max(worst, v[v.size() / 2]);
  }
  return worst;
}

TEST(SkyDistributionTest, TheCapturedSkyStaysAsItWasUnderItsOwnSun) {
  const Atmosphere air;
  const glm::vec3 sun = SunAt(35.0, 90.0);
  const auto clear = [&](const glm::vec3& d) { return glm::vec3(air.Radiance(d.z, sun.z, glm::dot(d, sun))); };
  std::vector<uint8_t> is_sky;
  const HdrImage env = MapOf(clear, &is_sky, 20.0);
  const SkyDistribution captured(env, is_sky, sun);
  const SkyDistribution same = captured.Under(sun);
  for (int t = 0; t < 90; t += 7) {
    for (int p = 0; p < 360; p += 11) {
      const glm::vec3 d = SunAt(90.0 - t - 0.5, p);
      for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(captured.Radiance(d)[c], same.Radiance(d)[c]);
    }
  }
}

TEST(SkyDistributionTest, AHazySkyCapturedUnderAHighSunIsRightUnderALowOne) {
  // A hand-built sky: the atmosphere's clear sky with a wider aureole and a greyer horizon than it
  // has (R = (1 + 3 e^(−γ/15°)) · (1 − 0.2 cos θ) per channel, stronger in red, and a term that is
  // not a product of the two, 1 + 0.1 sin θ cos γ), captured under a
  // sun 55° up with the low sky beyond azimuth 0° hidden, used for a sun 15° up on the other
  // side. The (θ, γ) table re-aimed as it stood misses the low sun's sky by the change of the
  // atmosphere itself; re-aimed with the atmosphere it keeps only the binning's error.
  const Atmosphere air;
  const auto hazy = [&](const glm::vec3& sun) {
    return [&air, sun](const glm::vec3& d) {
      const float gamma = glm::degrees(std::acos(std::clamp(glm::dot(d, sun), -1.0f, 1.0f)));
      const float haze = 1.0f + 3.0f * std::exp(-gamma / 15.0f);
      const float mixed = 1.0f + 0.1f * std::sqrt(1.0f - d.z * d.z) * glm::dot(d, sun);
      const glm::vec3 r = glm::vec3(haze, 0.5f + 0.5f * haze, 1.0f) * (1.0f - 0.2f * d.z) * mixed;
      return glm::vec3(air.Radiance(d.z, sun.z, glm::dot(d, sun))) * r;
    };
  };
  const glm::vec3 capture_sun = SunAt(55.0, 120.0), low_sun = SunAt(15.0, 250.0);
  std::vector<uint8_t> is_sky;
  const HdrImage env = MapOf(hazy(capture_sun), &is_sky, 25.0);
  const SkyDistribution captured(env, is_sky, capture_sun);
  const SkyDistribution reaimed = captured.Under(low_sun);
  const auto truth = hazy(low_sun);
  const double error = WorstMedianError(reaimed, truth);
  EXPECT_LT(error, 0.03);
  // The table as it stood, only read about the low sun (the direction at the same θ and γ from
  // the capture's sun): what daylit did before.
  const SkyDistribution as_captured = captured.Under(capture_sun);
  const auto same_table = [&](const glm::vec3& d) {
    const double theta = std::acos(std::clamp(static_cast<double>(d.z), -1.0, 1.0));
    const double cos_gamma = glm::dot(d, low_sun), ct = std::cos(theta), st = std::sin(theta);
    const double cs = capture_sun.z, ss = std::sqrt(1.0 - cs * cs);
    const double cos_phi = std::clamp((cos_gamma - ct * cs) / std::max(st * ss, 1e-9), -1.0, 1.0);
    const glm::dvec3 east(capture_sun.x / ss, capture_sun.y / ss, 0.0), north(-east.y, east.x, 0.0);
    const glm::dvec3 dir = st * (cos_phi * east + std::sqrt(1.0 - cos_phi * cos_phi) * north) + glm::dvec3(0.0, 0.0, ct);
    return as_captured.Radiance(glm::vec3(dir));
  };
  double old_error = 0.0;
  {
    std::vector<double> e;
    for (int t = 1; t < 89; t += 2) {
      for (int p = 0; p < 360; p += 3) {
        const glm::vec3 d = SunAt(90.0 - t, p);
        e.push_back(std::abs(same_table(d).x / truth(d).x - 1.0));
      }
    }
    std::nth_element(e.begin(), e.begin() + static_cast<ptrdiff_t>(e.size() / 2), e.end());
    old_error = e[e.size() / 2];
  }
  EXPECT_GT(old_error, 2.0 * error);  // the case tells the two apart
  std::printf("median error under the low sun: %.3f re-aimed with the atmosphere, %.3f as captured\n", error, old_error);
}

TEST(SkyDistributionTest, HorizontalIrradianceOfAUniformSkyIsPi) {
  const int w = 256, h = 128;
  HdrImage env{w, h, std::vector<float>(static_cast<size_t>(w) * h * 3, 1.0f)};
  std::vector<uint8_t> is_sky(static_cast<size_t>(w) * h, 1);
  const SkyDistribution uniform(env, is_sky, glm::vec3(0.0f, 0.0f, -1.0f));  // the sun down: no re-aiming
  EXPECT_NEAR(uniform.HorizontalIrradiance().x, glm::pi<double>(), 1e-3);
  EXPECT_NEAR(uniform.Under(SunAt(30.0, 0.0)).HorizontalIrradiance().y, glm::pi<double>(), 1e-3);
}

}  // namespace
}  // namespace daylit::sky
