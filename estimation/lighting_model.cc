#include "estimation/lighting_model.h"

#include <glm/gtc/constants.hpp>

namespace daylit::estimation {

ShadingTerms TermsOf(const glm::dvec3& n, const glm::dvec3& l, double sun_visibility,
                     double sky_visibility) {
  return {sun_visibility * glm::max(0.0, glm::dot(n, l)), sky_visibility};
}

glm::dvec3 Irradiance(const ShadingTerms& terms, const SunSky& light) {
  return light.sun_rgb * terms.sun + light.sky_rgb * terms.sky;
}

glm::dvec3 Radiance(const glm::dvec3& albedo, const ShadingTerms& terms, const SunSky& light) {
  return albedo * glm::one_over_pi<double>() * Irradiance(terms, light);
}

glm::dvec3 AlbedoOf(const glm::dvec3& radiance, const glm::dvec3& irradiance) {
  glm::dvec3 albedo(0.0);
  for (int c = 0; c < 3; ++c) {
    if (irradiance[c] > 0.0) albedo[c] = glm::pi<double>() * radiance[c] / irradiance[c];
  }
  return albedo;
}

}  // namespace daylit::estimation
