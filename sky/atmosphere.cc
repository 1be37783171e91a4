#include "sky/atmosphere.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/gtc/constants.hpp>

namespace daylit::sky {
namespace {

constexpr double kNoPath = std::numeric_limits<double>::infinity();

}  // namespace

glm::dvec3 Scattering::RayleighRec709() {
  // ITU-R BT.709's primaries have dominant wavelengths of about 612, 549 and 465 nm.
  const glm::dvec3 wavelength_nm(612.0, 549.0, 465.0);
  glm::dvec3 beta;
  for (int c = 0; c < 3; ++c) beta[c] = 33.1e-6 * std::pow(440.0 / wavelength_nm[c], 4.0);
  return beta;
}

Atmosphere::Atmosphere(const AtmosphereShape& shape) : shape_(shape), depth_(static_cast<size_t>(kHeights) * kMus) {
  constexpr int kSteps = 256;
  const double thickness = shape_.top_radius_m - shape_.earth_radius_m;
  for (int i = 0; i < kHeights; ++i) {
    const double f = static_cast<double>(i) / (kHeights - 1);
    const double r = shape_.earth_radius_m + thickness * f * f;  // denser near the ground, where the air is
    for (int j = 0; j < kMus; ++j) {
      const double mu = -1.0 + 2.0 * j / (kMus - 1);
      glm::dvec2& d = depth_[static_cast<size_t>(i) * kMus + static_cast<size_t>(j)];
      if (mu < 0.0 && r * r * (mu * mu - 1.0) + shape_.earth_radius_m * shape_.earth_radius_m >= 0.0) {
        d = glm::dvec2(kNoPath);  // the ray meets the ground
        continue;
      }
      const double length = -r * mu + std::sqrt(std::max(0.0, r * r * (mu * mu - 1.0) + shape_.top_radius_m * shape_.top_radius_m));
      d = glm::dvec2(0.0);
      for (int k = 0; k < kSteps; ++k) {
        // Quadratic spacing: most of the air is near the start of an upward path.
        const double t0 = static_cast<double>(k) / kSteps, t1 = static_cast<double>(k + 1) / kSteps, t = 0.5 * (t0 + t1);
        const double s = length * t * t, ds = length * (t1 * t1 - t0 * t0);
        const double h = std::sqrt(r * r + s * s + 2.0 * r * s * mu) - shape_.earth_radius_m;
        d += ds * glm::dvec2(std::exp(-h / shape_.rayleigh_height_m), std::exp(-h / shape_.mie_height_m));
      }
    }
  }
}

glm::dvec2 Atmosphere::DepthToTop(double h, double mu) const {
  const double thickness = shape_.top_radius_m - shape_.earth_radius_m;
  const double fi = std::sqrt(std::clamp(h / thickness, 0.0, 1.0)) * (kHeights - 1);
  const double fj = std::clamp((mu + 1.0) * 0.5, 0.0, 1.0) * (kMus - 1);
  const int i0 = std::min(static_cast<int>(fi), kHeights - 2), j0 = std::min(static_cast<int>(fj), kMus - 2);
  const double a = fi - i0, b = fj - j0;
  const auto at = [&](int i, int j) { return depth_[static_cast<size_t>(i) * kMus + static_cast<size_t>(j)]; };
  return (1.0 - a) * ((1.0 - b) * at(i0, j0) + b * at(i0, j0 + 1)) + a * ((1.0 - b) * at(i0 + 1, j0) + b * at(i0 + 1, j0 + 1));
}

glm::dvec3 Atmosphere::Transmittance(double sun_mu, const Scattering& scattering) const {
  const glm::dvec2 depth = DepthToTop(0.0, sun_mu);
  if (!std::isfinite(depth.x)) return glm::dvec3(0.0);
  glm::dvec3 out;
  for (int c = 0; c < 3; ++c) {
    out[c] = std::exp(-(scattering.rayleigh[c] * depth.x + scattering.mie * scattering.mie_extinction_ratio * depth.y));
  }
  return out;
}

glm::dvec3 Atmosphere::Radiance(double view_mu, double sun_mu, double cos_gamma, const Scattering& scattering) const {
  const double mu = std::clamp(view_mu, 0.0, 1.0), mu_s = std::clamp(sun_mu, -1.0, 1.0);
  const double sin_v = std::sqrt(1.0 - mu * mu), sin_s = std::sqrt(1.0 - mu_s * mu_s);
  // The azimuth between view and sun that gives cos γ (the nearest possible one where the two
  // zenith angles do not allow it).
  const double cos_phi = sin_v * sin_s > 1e-9 ? std::clamp((cos_gamma - mu * mu_s) / (sin_v * sin_s), -1.0, 1.0) : 1.0;
  const double sin_phi = std::sqrt(1.0 - cos_phi * cos_phi);
  const glm::dvec3 view(sin_v, 0.0, mu), sun(sin_s * cos_phi, sin_s * sin_phi, mu_s);
  const double c = glm::dot(view, sun);
  const double phase_rayleigh = 3.0 / (16.0 * glm::pi<double>()) * (1.0 + c * c);
  const double g = scattering.mie_g, g2 = g * g;
  const double phase_mie =
      3.0 / (8.0 * glm::pi<double>()) * (1.0 - g2) * (1.0 + c * c) / ((2.0 + g2) * std::pow(1.0 + g2 - 2.0 * g * c, 1.5));
  const double r0 = shape_.earth_radius_m;
  const double length = -r0 * mu + std::sqrt(std::max(0.0, r0 * r0 * (mu * mu - 1.0) + shape_.top_radius_m * shape_.top_radius_m));
  const double mie_extinction = scattering.mie * scattering.mie_extinction_ratio;
  constexpr int kSteps = 64;
  glm::dvec2 to_observer(0.0);
  glm::dvec3 sum(0.0);
  for (int k = 0; k < kSteps; ++k) {
    const double t0 = static_cast<double>(k) / kSteps, t1 = static_cast<double>(k + 1) / kSteps, t = 0.5 * (t0 + t1);
    const double s = length * t * t, ds = length * (t1 * t1 - t0 * t0);
    const glm::dvec3 p = glm::dvec3(0.0, 0.0, r0) + s * view;
    const double r = glm::length(p), h = r - r0;
    const glm::dvec2 density(std::exp(-h / shape_.rayleigh_height_m), std::exp(-h / shape_.mie_height_m));
    const glm::dvec2 here = to_observer + 0.5 * ds * density;
    to_observer += ds * density;
    const glm::dvec2 to_sun = DepthToTop(h, glm::dot(p, sun) / r);
    if (!std::isfinite(to_sun.x)) continue;  // in the Earth's shadow
    const glm::dvec2 depth = here + to_sun;
    for (int ch = 0; ch < 3; ++ch) {
      const double beta = scattering.rayleigh[ch];
      const double transmittance = std::exp(-(beta * depth.x + mie_extinction * depth.y));
      sum[ch] += ds * transmittance * (beta * density.x * phase_rayleigh + scattering.mie * density.y * phase_mie);
    }
  }
  return sum;
}

double RelativeAirMass(double apparent_elevation_deg) {
  const double h = std::clamp(apparent_elevation_deg, 0.0, 90.0);
  return 1.0 / (std::sin(glm::radians(h)) + 0.50572 * std::pow(h + 6.07995, -1.6364));
}

}  // namespace daylit::sky
