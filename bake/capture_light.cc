#include "bake/capture_light.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <glm/gtx/component_wise.hpp>

#include "base/log.h"
#include "scene/hdr_image.h"
#include "base/latlong.h"

namespace daylit::bake {
namespace {

// Entries without data take the value of the nearest entry with data (linear between two).
void FillFromNearest(std::vector<glm::dvec3>* values, const std::vector<uint8_t>& known) {
  const int n = static_cast<int>(values->size());
  for (int i = 0; i < n; ++i) {
    if (known[static_cast<size_t>(i)]) continue;
    int lo = i - 1, hi = i + 1;
    while (lo >= 0 && !known[static_cast<size_t>(lo)]) --lo;
    while (hi < n && !known[static_cast<size_t>(hi)]) ++hi;
    if (lo < 0 && hi >= n) return;
    if (lo < 0) {
      (*values)[static_cast<size_t>(i)] = (*values)[static_cast<size_t>(hi)];
    } else if (hi >= n) {
      (*values)[static_cast<size_t>(i)] = (*values)[static_cast<size_t>(lo)];
    } else {
      const double f = static_cast<double>(i - lo) / (hi - lo);
      (*values)[static_cast<size_t>(i)] = (1.0 - f) * (*values)[static_cast<size_t>(lo)] + f * (*values)[static_cast<size_t>(hi)];
    }
  }
}


}  // namespace

glm::vec3 TexelRadiance(const HdrImage& env, int texel) {
  const float* p = &env.rgb[static_cast<size_t>(texel) * 3];
  return {p[0], p[1], p[2]};
}

glm::vec3 Lookup(const HdrImage& env, const glm::vec3& dir) {
  return TexelRadiance(env, LatLongTexel(glm::dvec3(dir), env.width, env.height));
}

CaptureSun ExtractSun(HdrImage* env, const glm::dvec3& sun_dir, const std::optional<glm::dvec3>& given_dni,
                      const std::string& name) {
  CaptureSun sun;
  sun.dir = glm::vec3(glm::normalize(sun_dir));
  sun.above_horizon = sun_dir.z > 0.0;
  const double cos_disc = std::cos(glm::radians(kSunDiscRadiusDeg));
  const double cos_annulus = std::cos(glm::radians(kSunAnnulusOuterDeg));
  std::vector<size_t> disc;
  std::array<std::vector<float>, 3> annulus;
  float brightest = -1.0f;
  glm::dvec3 brightest_dir(0.0);
  for (int v = 0; v < env->height; ++v) {
    for (int u = 0; u < env->width; ++u) {
      const glm::dvec3 d = LatLongDirection(u, v, env->width, env->height);
      const float* p = env->Pixel(u, v);
      if (scene::Luminance(p) > brightest) brightest = scene::Luminance(p), brightest_dir = d;
      const double c = glm::dot(d, glm::dvec3(sun.dir));
      if (c >= cos_disc) {
        disc.push_back(static_cast<size_t>(v) * env->width + u);
      } else if (c >= cos_annulus) {
        for (size_t k = 0; k < 3; ++k) annulus[k].push_back(p[k]);
      }
    }
  }
  sun.brightest_offset_deg = glm::degrees(std::acos(std::clamp(glm::dot(brightest_dir, glm::dvec3(sun.dir)), -1.0, 1.0)));
  if (sun.above_horizon && sun.brightest_offset_deg > 2.0) {
    Log().warn("{}: the map's brightest texel is {:.1f} deg from the ephemeris sun: check north_azimuth_deg, "
               "envmap.time_utc and the map's orientation",
               name, sun.brightest_offset_deg);
  }
  glm::vec3 background(0.0f);
  for (size_t k = 0; k < 3; ++k) {
    if (annulus[k].empty()) continue;
    auto mid = annulus[k].begin() + static_cast<ptrdiff_t>(annulus[k].size() / 2);
    std::nth_element(annulus[k].begin(), mid, annulus[k].end());
    background[static_cast<int>(k)] = *mid;
  }
  glm::dvec3 dni(0.0);
  for (const size_t texel : disc) {
    float* p = &env->rgb[texel * 3];
    const double solid_angle = LatLongTexelSolidAngle(static_cast<int>(texel / static_cast<size_t>(env->width)), env->width, env->height);
    for (int k = 0; k < 3; ++k) {
      dni[k] += std::max(0.0, static_cast<double>(p[k]) - background[k]) * solid_angle;
      p[k] = background[k];
    }
  }
  sun.disc_texels = disc.size();
  sun.dni_from_map_rgb = glm::vec3(dni);
  sun.dni_rgb = !sun.above_horizon ? glm::vec3(0.0f) : given_dni ? glm::vec3(*given_dni) : sun.dni_from_map_rgb;
  return sun;
}

size_t SkyDistribution::BinOf(const glm::vec3& dir, const glm::vec3& sun_dir) {
  const glm::dvec3 d(dir);
  const double theta = glm::degrees(std::acos(std::clamp(d.z, -1.0, 1.0)));
  const double gamma = glm::degrees(std::acos(std::clamp(glm::dot(d, glm::dvec3(sun_dir)), -1.0, 1.0)));
  const int ti = std::min(kThetaBins - 1, static_cast<int>(theta));
  const int gi = std::min(kGammaBins - 1, static_cast<int>(gamma / 2.0));
  return static_cast<size_t>(ti) * kGammaBins + static_cast<size_t>(gi);
}

SkyDistribution::SkyDistribution(const HdrImage& env, const std::vector<uint8_t>& is_sky,
                                 const glm::vec3& sun_dir) {
  std::vector<glm::dvec3> sum(kThetaBins * kGammaBins, glm::dvec3(0.0));
  std::vector<double> weight(sum.size(), 0.0);
  for (int v = 0; v < env.height; ++v) {
    const double solid_angle = LatLongTexelSolidAngle(v, env.width, env.height);
    for (int u = 0; u < env.width; ++u) {
      if (!is_sky[static_cast<size_t>(v) * env.width + u]) continue;
      const float* p = env.Pixel(u, v);
      const size_t b = BinOf(glm::vec3(LatLongDirection(u, v, env.width, env.height)), sun_dir);
      sum[b] += solid_angle * glm::dvec3(p[0], p[1], p[2]);
      weight[b] += solid_angle;
    }
  }
  // Bins the capture never saw as sky (the low sky behind the buildings; for another sun, the
  // (θ, γ) pairs that sun makes and the capture's did not) come from a separable fit
  // L ≈ g(θ)·h(γ), the form of the Perez and CIE standard skies (gradation × indicatrix), fitted
  // to the seen bins in log radiance. Copying the nearest seen bin instead carried the bright
  // aureole 40° away into the dim sky at 90° from the sun and made shaded walls too warm; a
  // harmonic fill across the (θ, γ) plane underestimated the zenith for a sun far from the
  // capture's.
  std::vector<glm::vec3> log_mean(sum.size(), glm::vec3(0.0f));
  std::vector<uint8_t> known(sum.size(), 0);
  bool any = false;
  for (size_t b = 0; b < sum.size(); ++b) {
    if (weight[b] <= 0.0) continue;
    log_mean[b] = glm::log(glm::max(glm::vec3(sum[b] / weight[b]), glm::vec3(1e-6f)));
    known[b] = 1;
    any = true;
  }
  if (!any) return;  // no sky at all: nothing to fit
  std::vector<glm::dvec3> log_g(kThetaBins, glm::dvec3(0.0)), log_h(kGammaBins, glm::dvec3(0.0));
  std::vector<uint8_t> g_known(kThetaBins, 0), h_known(kGammaBins, 0);
  const auto index = [](int t, int g) { return static_cast<size_t>(t) * kGammaBins + static_cast<size_t>(g); };
  constexpr int kHorizon = 90;  // the indicatrix h is fitted on the upper hemisphere only
  // One half-step: each entry i of `fitted` becomes the weighted mean, over the seen bins of its
  // row (θ: i = t) or column (γ: i = g) among the first `others` of the other axis, of log L less
  // the other factor.
  const auto half_step = [&](bool theta, int others, const std::vector<glm::dvec3>& other,
                             std::vector<glm::dvec3>* fitted, std::vector<uint8_t>* fitted_known) {
    for (size_t i = 0; i < fitted->size(); ++i) {
      glm::dvec3 num(0.0);
      double den = 0.0;
      for (int j = 0; j < others; ++j) {
        const size_t b = theta ? index(static_cast<int>(i), j) : index(j, static_cast<int>(i));
        if (known[b]) num += weight[b] * (glm::dvec3(log_mean[b]) - other[static_cast<size_t>(j)]), den += weight[b];
      }
      if (den > 0.0) (*fitted)[i] = num / den, (*fitted_known)[i] = 1;
    }
  };
  for (int iteration = 0; iteration < 30; ++iteration) {
    half_step(true, kGammaBins, log_h, &log_g, &g_known);
    half_step(false, kHorizon, log_g, &log_h, &h_known);
  }
  FillFromNearest(&log_g, g_known);
  FillFromNearest(&log_h, h_known);
  mean_.resize(sum.size());
  for (int t = 0; t < kThetaBins; ++t) {
    for (int g = 0; g < kGammaBins; ++g) {
      const size_t b = index(t, g);
      mean_[b] = known[b] ? glm::vec3(sum[b] / weight[b])
                          : glm::vec3(glm::exp(log_g[static_cast<size_t>(t)] + log_h[static_cast<size_t>(g)]));
    }
  }
}

glm::vec3 SkyDistribution::Radiance(const glm::vec3& dir, const glm::vec3& sun_dir) const {
  if (mean_.empty()) return glm::vec3(0.0f);
  // Bilinear between bin centres (θ at i + 0.5°, γ at 2j + 1°): nearest bins drew rings.
  const float theta = glm::degrees(std::acos(std::clamp(dir.z, -1.0f, 1.0f)));
  const float gamma = glm::degrees(std::acos(std::clamp(glm::dot(dir, sun_dir), -1.0f, 1.0f)));
  const float t = std::clamp(theta - 0.5f, 0.0f, static_cast<float>(kThetaBins - 1));
  const float g = std::clamp(0.5f * gamma - 0.5f, 0.0f, static_cast<float>(kGammaBins - 1));
  const int t0 = std::min(static_cast<int>(t), kThetaBins - 2), g0 = std::min(static_cast<int>(g), kGammaBins - 2);
  const float ft = t - static_cast<float>(t0), fg = g - static_cast<float>(g0);
  const auto at = [&](int ti, int gi) { return mean_[static_cast<size_t>(ti) * kGammaBins + static_cast<size_t>(gi)]; };
  return (1.0f - ft) * ((1.0f - fg) * at(t0, g0) + fg * at(t0, g0 + 1)) + ft * ((1.0f - fg) * at(t0 + 1, g0) + fg * at(t0 + 1, g0 + 1));
}

glm::dvec3 SkyDistribution::HorizontalIrradiance(const glm::vec3& sun_dir) const {
  // Midpoint rule on a 0.5° × 1° grid of the upper hemisphere: finer than the bins.
  constexpr int kRows = 180, kColumns = 360;
  glm::dvec3 sum(0.0);
  for (int r = 0; r < kRows; ++r) {
    const double theta = 0.5 * glm::pi<double>() * (r + 0.5) / kRows;
    const double weight = std::cos(theta) * std::sin(theta) * (0.5 * glm::pi<double>() / kRows) *
                          (2.0 * glm::pi<double>() / kColumns);
    for (int c = 0; c < kColumns; ++c) {
      const double phi = 2.0 * glm::pi<double>() * (c + 0.5) / kColumns;
      const glm::vec3 dir(glm::dvec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)));
      sum += weight * glm::dvec3(Radiance(dir, sun_dir));
    }
  }
  return sum;
}

HdrImage SkyOnly(const HdrImage& env, const std::vector<uint8_t>& is_sky, const glm::vec3& sun_dir) {
  const SkyDistribution distribution(env, is_sky, sun_dir);
  if (distribution.empty()) return env;
  HdrImage sky = env;
  for (int v = 0; v < env.height; ++v) {
    for (int u = 0; u < env.width; ++u) {
      if (is_sky[static_cast<size_t>(v) * env.width + u]) continue;
      const glm::vec3 m = distribution.Radiance(glm::vec3(LatLongDirection(u, v, env.width, env.height)), sun_dir);
      float* p = sky.Pixel(u, v);
      p[0] = m.x, p[1] = m.y, p[2] = m.z;
    }
  }
  return sky;
}

}  // namespace daylit::bake
