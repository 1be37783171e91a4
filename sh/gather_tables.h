// The irradiance volume's parallax table (sh/irradiance_volume.h): for each probe of the
// volume's grid and each gather direction, the environment-map texel that shows what that
// direction meets from the probe, or, where the direction escapes, the sky layer's texel in that
// direction (bake/parallax.h). The bake makes it (bake/bake.h) by ray casting the model.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace daylit::sh {

// Seed 001's "which pixels of the environment map are used in which key point".
struct GatherTables {
  glm::vec3 min{0.0f}, max{0.0f};
  glm::ivec3 resolution{0};
  std::vector<glm::vec3> directions;  // SphericalFibonacci(gather_directions)
  // [probe · directions + d]; probe = (k·ny + j)·nx + i. An index into the stacked map: below
  // map_texels the env map's texel, from map_texels on the sky layer's (bake/parallax.h).
  std::vector<uint32_t> texel;
  size_t map_texels = 0;  // W·H of the env map

  size_t ProbeCount() const { return static_cast<size_t>(resolution.x) * resolution.y * resolution.z; }
  glm::vec3 ProbePosition(int i, int j, int k) const;
};

}  // namespace daylit::sh
