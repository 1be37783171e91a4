#include "bake/capture_light.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>

#include "base/log.h"
#include "scene/latlong.h"

namespace daylit::bake {
namespace {

float Luminance(const float* rgb) { return 0.2126f * rgb[0] + 0.7152f * rgb[1] + 0.0722f * rgb[2]; }

}  // namespace

glm::vec3 Lookup(const scene::HdrImage& env, const glm::vec3& dir) {
  const int texel = scene::LatLongTexel(glm::dvec3(dir), env.width, env.height);
  const float* p = &env.rgb[static_cast<size_t>(texel) * 3];
  return {p[0], p[1], p[2]};
}

CaptureSun ExtractSun(scene::HdrImage* env, const glm::dvec3& sun_dir, const std::optional<glm::dvec3>& given_dni,
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
      const glm::dvec3 d = scene::LatLongDirection(u, v, env->width, env->height);
      const float* p = env->Pixel(u, v);
      if (Luminance(p) > brightest) brightest = Luminance(p), brightest_dir = d;
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
    const double solid_angle = scene::LatLongTexelSolidAngle(static_cast<int>(texel / static_cast<size_t>(env->width)), env->width, env->height);
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

scene::HdrImage SkyOnly(const scene::HdrImage& env, const std::vector<uint8_t>& is_sky, const glm::vec3& sun_dir) {
  constexpr int kThetaBins = 181;  // 1° from the zenith to the nadir
  constexpr int kGammaBins = 90;   // 2° from the sun to its opposite
  const auto bin_of = [&](const glm::dvec3& d) {
    const double theta = glm::degrees(std::acos(std::clamp(d.z, -1.0, 1.0)));
    const double gamma = glm::degrees(std::acos(std::clamp(glm::dot(d, glm::dvec3(sun_dir)), -1.0, 1.0)));
    const int ti = std::min(kThetaBins - 1, static_cast<int>(theta));
    const int gi = std::min(kGammaBins - 1, static_cast<int>(gamma / 2.0));
    return static_cast<size_t>(ti) * kGammaBins + static_cast<size_t>(gi);
  };
  std::vector<glm::dvec3> sum(kThetaBins * kGammaBins, glm::dvec3(0.0));
  std::vector<double> weight(sum.size(), 0.0);
  for (int v = 0; v < env.height; ++v) {
    const double solid_angle = scene::LatLongTexelSolidAngle(v, env.width, env.height);
    for (int u = 0; u < env.width; ++u) {
      if (!is_sky[static_cast<size_t>(v) * env.width + u]) continue;
      const float* p = env.Pixel(u, v);
      const size_t b = bin_of(scene::LatLongDirection(u, v, env.width, env.height));
      sum[b] += solid_angle * glm::dvec3(p[0], p[1], p[2]);
      weight[b] += solid_angle;
    }
  }
  // Means, then fill empty bins: along γ within a θ row, then rows from their nearest filled row.
  std::vector<glm::vec3> mean(sum.size(), glm::vec3(0.0f));
  std::vector<uint8_t> filled(sum.size(), 0), row_filled(kThetaBins, 0);
  for (size_t b = 0; b < sum.size(); ++b) {
    if (weight[b] > 0.0) mean[b] = glm::vec3(sum[b] / weight[b]), filled[b] = 1, row_filled[b / kGammaBins] = 1;
  }
  for (int t = 0; t < kThetaBins; ++t) {
    if (!row_filled[static_cast<size_t>(t)]) continue;
    const size_t row = static_cast<size_t>(t) * kGammaBins;
    for (int g = 0; g < kGammaBins; ++g) {
      if (filled[row + static_cast<size_t>(g)]) continue;
      for (int step = 1; step < kGammaBins; ++step) {
        if (g - step >= 0 && filled[row + static_cast<size_t>(g - step)]) { mean[row + static_cast<size_t>(g)] = mean[row + static_cast<size_t>(g - step)]; break; }
        if (g + step < kGammaBins && filled[row + static_cast<size_t>(g + step)]) { mean[row + static_cast<size_t>(g)] = mean[row + static_cast<size_t>(g + step)]; break; }
      }
    }
  }
  for (int t = 0; t < kThetaBins; ++t) {
    if (row_filled[static_cast<size_t>(t)]) continue;
    for (int step = 1; step < kThetaBins; ++step) {
      const int from = t - step >= 0 && row_filled[static_cast<size_t>(t - step)] ? t - step
                       : t + step < kThetaBins && row_filled[static_cast<size_t>(t + step)] ? t + step : -1;
      if (from < 0) continue;
      std::copy_n(mean.begin() + static_cast<ptrdiff_t>(from) * kGammaBins, kGammaBins,
                  mean.begin() + static_cast<ptrdiff_t>(t) * kGammaBins);
      break;
    }
  }
  scene::HdrImage sky = env;
  for (int v = 0; v < env.height; ++v) {
    for (int u = 0; u < env.width; ++u) {
      if (is_sky[static_cast<size_t>(v) * env.width + u]) continue;
      const glm::vec3 m = mean[bin_of(scene::LatLongDirection(u, v, env.width, env.height))];
      float* p = sky.Pixel(u, v);
      p[0] = m.x, p[1] = m.y, p[2] = m.z;
    }
  }
  return sky;
}

}  // namespace daylit::bake
