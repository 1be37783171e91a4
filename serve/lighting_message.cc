#include "serve/lighting_message.h"

#include "base/utc_time.h"

namespace daylit::serve {
namespace {

nlohmann::json Xyz(const glm::dvec3& v) { return {{"x", v.x}, {"y", v.y}, {"z", v.z}}; }

}  // namespace

std::array<float, 27> RadianceCoefficients(const std::array<float, 27>& irradiance) {
  std::array<float, 27> out{};
  for (size_t k = 0; k < 27; ++k) out[k] = static_cast<float>(irradiance[k] / sh::kCosineLobe[k / 3]);
  return out;
}

nlohmann::json LightingJson(const FrameLighting& l, const std::optional<glm::vec3>& at) {
  const estimation::FrameEstimate& r = l.row;
  nlohmann::json j = {
      {"version", kLightingSchema},
      {"frame", r.frame},
      {"time_utc", FormatUtcTime(r.time_utc)},
      {"primaryLightDirection", Xyz(l.sun_scene)},
      {"primaryLightDirectionCamera", Xyz(l.sun_camera)},
      {"primaryLightIntensity", Xyz(r.light.sun_rgb)},
      {"skyIrradiance", Xyz(r.light.sky_rgb)},
      {"overcastShare", l.overcast_share},
      {"sunElevationDeg", r.sun_elevation_deg},
      {"sunAzimuthDeg", r.sun_azimuth_deg},
      {"sunUp", r.sun_up},
      {"confidence", r.confidence},
      {"hasEstimate", r.HasEstimate()},
  };
  if (l.volume.empty()) {
    j["sphericalHarmonicsCoefficients"] = nullptr;
    j["sphericalHarmonicsAt"] = nullptr;
  } else {
    const glm::vec3 point = at.value_or(0.5f * (l.volume.min + l.volume.max));
    const std::array<float, 27> c = RadianceCoefficients(l.volume.At(point));
    j["sphericalHarmonicsCoefficients"] = c;
    j["sphericalHarmonicsAt"] = {point.x, point.y, point.z};
  }
  return j;
}

}  // namespace daylit::serve
