#include "bake/capture_light.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <glm/gtx/component_wise.hpp>

#include "base/log.h"
#include "scene/hdr_image.h"
#include "base/latlong.h"

namespace daylit::bake {

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

}  // namespace daylit::bake
