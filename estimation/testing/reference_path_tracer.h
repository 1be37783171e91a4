// For tests: irradiance at a model point by brute-force path tracing, the independent computation
// that estimation::LightTransfer and the bake's capture light are checked against. Lambertian
// surfaces of one albedo each, cosine-weighted paths of up to `depth` bounces, the sun by
// next-event estimation (a shadow ray at every vertex), the sky where a path escapes.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>

#include "bake/sampling.h"
#include "scene/raycaster.h"

namespace daylit::estimation::testing {

struct ReferenceLight {
  glm::vec3 sun_dir{0.0f, 0.0f, 1.0f};                  // unit, toward the sun
  glm::vec3 sun_rgb{0.0f};                              // DNI
  std::function<glm::vec3(const glm::vec3&)> sky;       // radiance toward a unit direction
  std::vector<glm::vec3> albedo;                        // per surface
};

// Irradiance at `x` (unit normal `n`) from everything but the direct sun at x itself.
inline glm::vec3 PathTracedIndirectAndSky(const scene::RayCaster& caster, const ReferenceLight& light, const glm::vec3& x,
                                          const glm::vec3& n, int paths, int depth, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  glm::vec3 sum(0.0f);
  for (int k = 0; k < paths; ++k) {
    glm::vec3 p = x + 2e-3f * n, normal = n, throughput(1.0f);
    for (int d = 0; d < depth; ++d) {
      const float r1 = u(rng), phi = 2.0f * glm::pi<float>() * u(rng), r = std::sqrt(r1);
      const glm::vec3 dir =
          bake::BasisAround(normal) * glm::vec3(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - r1)));
      const scene::RayHit hit = caster.Intersect(p, dir);
      if (!hit.IsHit()) {
        sum += throughput * light.sky(dir) * glm::pi<float>();
        break;
      }
      throughput *= light.albedo[hit.surface];
      p = p + hit.t * dir + 2e-3f * hit.normal, normal = hit.normal;
      const float c = glm::dot(normal, light.sun_dir);
      if (c > 0.0f && !caster.Occluded(p, light.sun_dir)) sum += throughput * light.sun_rgb * c;
    }
  }
  return sum / static_cast<float>(paths);
}

}  // namespace daylit::estimation::testing
