#include "estimation/lighting_model.h"

#include <algorithm>

namespace daylit::estimation {

LightParts SplitLight(const SunSky& light, double overcast_share) {
  const float o = static_cast<float>(std::clamp(overcast_share, 0.0, 1.0));
  const glm::vec3 sky(light.sky_rgb);
  return {glm::vec3(light.sun_rgb), (1.0f - o) * sky, o * sky};
}

}  // namespace daylit::estimation
