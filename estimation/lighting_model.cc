#include "estimation/lighting_model.h"

#include <algorithm>

namespace daylit::estimation {

LightParts SplitLight(const SunSky& light, double overcast_share) {
  const float o = static_cast<float>(std::clamp(overcast_share, 0.0, 1.0));
  const glm::vec3 sky = glm::max(glm::vec3(light.sky_rgb), glm::vec3(0.0f));
  const glm::vec3 overcast = glm::min(glm::vec3(o * (sky.x + sky.y + sky.z) / 3.0f), sky);
  return {glm::vec3(light.sun_rgb), sky - overcast, overcast};
}

}  // namespace daylit::estimation
