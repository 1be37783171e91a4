#include "serve/lighting_message.h"

#include <opencv2/imgproc.hpp>

#include "base/utc_time.h"
#include "scene/hdr_image.h"

namespace daylit::serve {
namespace {

nlohmann::json Xyz(const glm::dvec3& v) { return {{"x", v.x}, {"y", v.y}, {"z", v.z}}; }

// The first width × height values of `map` (a stacked basis may carry more after them),
// area-averaged to out_width × out_height.
std::vector<glm::vec3> Shrink(int width, int height, const std::vector<glm::vec3>& map, int out_width, int out_height) {
  const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  if (out_width == width && out_height == height) return {map.begin(), map.begin() + static_cast<long>(n)};
  const cv::Mat in(height, width, CV_32FC3, const_cast<glm::vec3*>(map.data()));
  std::vector<glm::vec3> out(static_cast<size_t>(out_width) * static_cast<size_t>(out_height));
  cv::Mat shrunk(out_height, out_width, CV_32FC3, out.data());
  cv::resize(in, shrunk, shrunk.size(), 0.0, 0.0, cv::INTER_AREA);  // each texel the mean of those it covers
  return out;
}

}  // namespace

std::shared_ptr<const EnvMapParts> ShrinkEnvMapParts(int width, int height, const std::vector<glm::vec3>& sun,
                                                     const std::vector<glm::vec3>& clear,
                                                     const std::vector<glm::vec3>& overcast) {
  const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  if (width <= 0 || height <= 0 || sun.size() < n || clear.size() < n || overcast.size() < n) return nullptr;
  auto parts = std::make_shared<EnvMapParts>();
  parts->width = std::min(width, kEnvMapWidth);
  parts->height = std::min(height, kEnvMapHeight);
  // The stacked bases (relight::EnvBasis) carry a sky layer after the map: only the map is shrunk.
  parts->sun = Shrink(width, height, sun, parts->width, parts->height);
  parts->clear = Shrink(width, height, clear, parts->width, parts->height);
  parts->overcast = Shrink(width, height, overcast, parts->width, parts->height);
  return parts;
}

std::vector<float> RelitEnvMap(const EnvMapParts& parts, const estimation::SunSky& light, double overcast_share) {
  const estimation::LightParts e = estimation::SplitLight(light, overcast_share);
  std::vector<float> rgb(parts.sun.size() * 3);
  for (size_t i = 0; i < parts.sun.size(); ++i) {
    const glm::vec3 l = e.sun * parts.sun[i] + e.clear * parts.clear[i] + e.overcast * parts.overcast[i];
    rgb[3 * i] = l.r, rgb[3 * i + 1] = l.g, rgb[3 * i + 2] = l.b;
  }
  return rgb;
}

std::string EnvMapExr(const EnvMapParts& parts, const estimation::SunSky& light, double overcast_share) {
  const std::vector<float> rgb = RelitEnvMap(parts, light, overcast_share);
  const size_t n = parts.sun.size();
  std::vector<float> r(n), g(n), b(n);
  for (size_t i = 0; i < n; ++i) r[i] = rgb[3 * i], g[i] = rgb[3 * i + 1], b[i] = rgb[3 * i + 2];
  return scene::EncodeExr(parts.width, parts.height,
                          {{"R", scene::ExrPixelType::kHalf, r.data(), nullptr},
                           {"G", scene::ExrPixelType::kHalf, g.data(), nullptr},
                           {"B", scene::ExrPixelType::kHalf, b.data(), nullptr}});
}

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
      {"exposure", l.exposure},
      {"skyIrradiance", Xyz(r.light.sky_rgb)},
      {"overcastShare", l.overcast_share},
      {"sunElevationDeg", r.sun_elevation_deg},
      {"sunAzimuthDeg", r.sun_azimuth_deg},
      {"sunUp", r.sun_up},
      {"confidence", r.confidence},
      {"hasEstimate", r.HasEstimate()},
      {"status", estimation::FrameStatusName(r.status)},
  };
  // The 90% intervals of E_sun and E_sky (estimation/light_interval.h), around the values above.
  const estimation::IntervalBounds bounds = estimation::BoundsOf(r.light, r.interval);
  const auto interval = [](const std::array<glm::dvec2, 3>& b) {
    return nlohmann::json{{"lo", Xyz({b[0].x, b[1].x, b[2].x})}, {"hi", Xyz({b[0].y, b[1].y, b[2].y})}};
  };
  j["primaryLightIntensityInterval90"] = interval(bounds.sun);
  j["skyIrradianceInterval90"] = interval(bounds.sky);
  j["primaryLightObserved"] = r.interval.sun_observed;
  if (l.volume.empty()) {
    j["sphericalHarmonicsCoefficients"] = nullptr;
    j["sphericalHarmonicsAt"] = nullptr;
  } else {
    // The volume holds its edge beyond its box: the point it was taken at is the nearest inside.
    const glm::vec3 point = glm::clamp(at.value_or(0.5f * (l.volume.min + l.volume.max)), l.volume.min, l.volume.max);
    const std::array<float, 27> c = RadianceCoefficients(l.volume.At(point));
    j["sphericalHarmonicsCoefficients"] = c;
    j["sphericalHarmonicsAt"] = {point.x, point.y, point.z};
  }
  return j;
}

std::string SceneJson(const scene::Scene& scene) {
  const scene::CameraIntrinsics& k = scene.intrinsics;
  nlohmann::json rotation = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) {
    rotation.push_back({scene.cam_from_world.rotation[0][r], scene.cam_from_world.rotation[1][r], scene.cam_from_world.rotation[2][r]});
  }
  const glm::dvec3 t = scene.cam_from_world.translation, center = scene.Camera().CenterInWorld();
  nlohmann::json j = {
      {"version", kLightingSchema},
      {"name", scene.name},
      {"units", "m"},
      {"up", {0, 0, 1}},
      {"north_azimuth_deg", scene.north_azimuth_deg},
      {"camera",
       {{"convention", "OpenCV: x right, y down, z forward; x_cam = R x_world + t"},
        {"width", k.width}, {"height", k.height}, {"fx", k.fx}, {"fy", k.fy}, {"cx", k.cx}, {"cy", k.cy},
        {"world_to_camera", {{"rotation", rotation}, {"translation", {t.x, t.y, t.z}}}},
        {"center", {center.x, center.y, center.z}}}},
  };
  j["camera"]["response"] = scene.response.Describe();
  j["camera"]["exposure"] = scene.exposure;
  nlohmann::json objects = nlohmann::json::array();
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const scene::VirtualObject& o = scene.objects[i];
    const glm::dvec3 albedo = o.albedo.value_or(glm::dvec3(0.5));
    nlohmann::json object = {
        {"position", {o.position.x, o.position.y, o.position.z}},
        {"rotation_deg", {o.rotation_deg.x, o.rotation_deg.y, o.rotation_deg.z}},
        {"scale", {o.scale.x, o.scale.y, o.scale.z}},
        {"albedo", {albedo.x, albedo.y, albedo.z}},
    };
    switch (o.kind) {
      case scene::MeshKind::kSphere: object["mesh"] = "sphere", object["radius"] = o.radius; break;
      case scene::MeshKind::kBox: object["mesh"] = "box", object["size"] = {o.size.x, o.size.y, o.size.z}; break;
      case scene::MeshKind::kFile: object["mesh"] = "file", object["file"] = o.file.filename().string(); break;
    }
    objects.push_back(std::move(object));
  }
  j["objects"] = std::move(objects);
  if (scene.volume) {
    j["volume"] = {{"min", {scene.volume->min.x, scene.volume->min.y, scene.volume->min.z}},
                   {"max", {scene.volume->max.x, scene.volume->max.y, scene.volume->max.z}}};
  }
  return j.dump();
}

}  // namespace daylit::serve
