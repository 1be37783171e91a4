// The irradiance volume's parallax table (sh/irradiance_volume.h): for each probe of the
// volume's grid and each gather direction, the environment-map texel that shows what that
// direction meets from the probe. The bake makes it (bake/bake.h) by ray casting the model.
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
  std::vector<uint32_t> texel;        // [probe · directions + d]; probe = (k·ny + j)·nx + i

  size_t ProbeCount() const { return static_cast<size_t>(resolution.x) * resolution.y * resolution.z; }
  glm::vec3 ProbePosition(int i, int j, int k) const;
};

}  // namespace daylit::sh
