#include "bake/parallax.h"

#include "base/latlong.h"

namespace daylit::bake {

uint32_t ParallaxTexel(const glm::vec3& origin, const glm::vec3& dir, const scene::RayHit& hit,
                       const glm::vec3& capture, int width, int height) {
  if (hit.IsHit()) return static_cast<uint32_t>(LatLongTexel(glm::dvec3(origin + hit.t * dir - capture), width, height));
  const uint32_t map_texels = static_cast<uint32_t>(width) * static_cast<uint32_t>(height);
  return map_texels + static_cast<uint32_t>(LatLongTexel(glm::dvec3(dir), width, height));
}

}  // namespace daylit::bake
