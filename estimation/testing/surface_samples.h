// For tests: samples of five planar surfaces, each seeing about the same sky all over, the case
// that tells E_sun from the surfaces' own shadows (SunSkyFitOptions::sun_from_shadows) apart from
// the whole scene's. The first and last all sunlit (facing the sun at cosines 0.9 and 0.3), the
// second and fourth partly in a cast shadow (0.75, 0.45; 40% shaded), the third all in shade.
// Albedo 0.2-0.6, light reflected onto each up to 0.1 of a unit sun, pixel noise 1%.
#pragma once

#include <array>
#include <random>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>

#include "estimation/sun_sky_fit.h"

namespace daylit::estimation::testing {

// Lit by `light`; the sky reaching surface j differs from the model's by `sky_factor[j]` (a
// photographed sky unlike the captured one, a wrong albedo) and its direct sun by `sun_factor[j]`
// (gloss seen from one side, a wrong normal). Sample i is on surface i mod 5 and at pixel i.
inline std::vector<Sample> SurfaceSamples(const SunSky& light, const std::array<double, 5>& sky_factor, std::mt19937& rng,
                                          const std::array<double, 5>& sun_factor = {1.0, 1.0, 1.0, 1.0, 1.0}) {
  const std::array<float, 5> cosine{0.9f, 0.75f, 0.6f, 0.45f, 0.3f};
  const std::array<float, 5> visibility{0.5f, 0.6f, 0.55f, 0.6f, 0.5f};  // a wall sees the same sky all over
  std::uniform_real_distribution<float> albedo(0.2f, 0.6f), v(0.0f, 0.05f), pick(0, 1), bounce(0.0f, 0.1f);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  std::vector<Sample> samples(5000);
  for (size_t i = 0; i < samples.size(); ++i) {
    Sample& s = samples[i];
    s.surface = static_cast<uint32_t>(i % 5);
    s.pixel = static_cast<uint32_t>(i);
    s.albedo = glm::vec3(albedo(rng));
    s.sunlit = s.surface == 0 || s.surface == 4 || (s.surface != 2 && pick(rng) >= 0.4f);
    const float direct = s.sunlit ? cosine[s.surface] : 0.0f, reflected = bounce(rng);
    s.sun = glm::vec3(direct + reflected);
    s.sky = glm::vec3(visibility[s.surface] + v(rng));
    s.overcast = s.sky;
    const float n = 1.0f + noise(rng);
    for (int c = 0; c < 3; ++c) {
      s.radiance[c] = n * static_cast<float>(s.albedo[c] / glm::pi<double>() *
                                             ((sun_factor[s.surface] * direct + reflected) * light.sun_rgb[c] +
                                              sky_factor[s.surface] * s.sky[c] * light.sky_rgb[c]));
    }
  }
  return samples;
}

}  // namespace daylit::estimation::testing
