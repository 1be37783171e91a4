#include "bake/capture_light.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <glm/gtx/component_wise.hpp>

#include "base/log.h"
#include "scene/latlong.h"

namespace daylit::bake {
namespace {

float Luminance(const float* rgb) { return 0.2126f * rgb[0] + 0.7152f * rgb[1] + 0.0722f * rgb[2]; }

}  // namespace

glm::vec3 TexelRadiance(const scene::HdrImage& env, int texel) {
  const float* p = &env.rgb[static_cast<size_t>(texel) * 3];
  return {p[0], p[1], p[2]};
}

glm::vec3 Lookup(const scene::HdrImage& env, const glm::vec3& dir) {
  return TexelRadiance(env, scene::LatLongTexel(glm::dvec3(dir), env.width, env.height));
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
  // Empty bins (directions the capture point never sees as sky, such as the low sky behind the
  // buildings) get a harmonic fill in log radiance: each is the mean of its four neighbours,
  // iterated to convergence, so holes blend between the known sky on every side. Copying the
  // nearest filled bin instead carried the bright aureole 40° away into the dim sky at 90° from
  // the sun and made shaded walls too warm.
  std::vector<glm::vec3> log_mean(sum.size(), glm::vec3(0.0f));
  std::vector<uint8_t> known(sum.size(), 0);
  bool any = false;
  for (size_t b = 0; b < sum.size(); ++b) {
    if (weight[b] <= 0.0) continue;
    log_mean[b] = glm::log(glm::max(glm::vec3(sum[b] / weight[b]), glm::vec3(1e-6f)));
    known[b] = 1;
    any = true;
  }
  if (!any) return env;  // no sky at all: nothing to fill from
  glm::vec3 known_mean(0.0f);
  float known_count = 0.0f;
  for (size_t b = 0; b < sum.size(); ++b) known_mean += known[b] ? log_mean[b] : glm::vec3(0.0f), known_count += known[b];
  for (size_t b = 0; b < sum.size(); ++b) {
    if (!known[b]) log_mean[b] = known_mean / known_count;
  }
  const auto at = [&](int t, int g) { return log_mean[static_cast<size_t>(std::clamp(t, 0, kThetaBins - 1)) * kGammaBins + static_cast<size_t>(std::clamp(g, 0, kGammaBins - 1))]; };
  for (int iteration = 0; iteration < 2000; ++iteration) {
    float change = 0.0f;
    for (int t = 0; t < kThetaBins; ++t) {
      for (int g = 0; g < kGammaBins; ++g) {
        const size_t b = static_cast<size_t>(t) * kGammaBins + static_cast<size_t>(g);
        if (known[b]) continue;
        const glm::vec3 next = 0.25f * (at(t - 1, g) + at(t + 1, g) + at(t, g - 1) + at(t, g + 1));
        change = std::max(change, glm::compMax(glm::abs(next - log_mean[b])));
        log_mean[b] = next;
      }
    }
    if (change < 1e-4f) break;
  }
  std::vector<glm::vec3> mean(sum.size());
  for (size_t b = 0; b < sum.size(); ++b) mean[b] = known[b] ? glm::vec3(sum[b] / weight[b]) : glm::exp(log_mean[b]);
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
