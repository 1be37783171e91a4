// One frame's lighting as daylit serves it to other renderers (daylit replay/live --serve):
// JSON shaped like WebXR Lighting Estimation's XRLightProbe / XRLightEstimate where a name exists
// (primaryLightDirection, primaryLightIntensity, sphericalHarmonicsCoefficients), plus what
// daylit knows beyond it (E_sky, the sun's position, the confidence). The schema, its units and
// its mapping to ARCore, ARKit and Unity AR Foundation: docs/lighting.schema.json, docs/serve.md.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "capture/response.h"

#include "estimation/frame_estimator.h"
#include "scene/scene.h"
#include "sh/irradiance_volume.h"
#include "sh/sh9.h"

namespace daylit::serve {

// The schema's version: a client checks it before reading the fields.
inline constexpr const char* kLightingSchema = "daylit-lighting/1";

// The relit environment map's parts for one sun, at the size GET /envmap serves (latitude-
// longitude as the scene's map: row 0 the zenith, the centre column along +Y, right toward +X):
// the map is E_sun·sun + E_clear·clear + E_overcast·overcast texel by texel, with the parts of
// estimation::SplitLight. Made once per sun, shared by the frames that have it.
struct EnvMapParts {
  int width = 0, height = 0;
  std::vector<glm::vec3> sun, clear, overcast;
};

// The served map's size.
inline constexpr int kEnvMapWidth = 128, kEnvMapHeight = 64;

// `parts`' maps (each width × height, row-major), area-averaged down to kEnvMapWidth ×
// kEnvMapHeight (or left as they are when not larger).
std::shared_ptr<const EnvMapParts> ShrinkEnvMapParts(int width, int height, const std::vector<glm::vec3>& sun,
                                                     const std::vector<glm::vec3>& clear,
                                                     const std::vector<glm::vec3>& overcast);

// The relit map of `lighting` as interleaved RGB floats (EnvMapParts' size), and as the bytes
// of a half-float RGB OpenEXR.
std::vector<float> RelitEnvMap(const EnvMapParts& parts, const estimation::SunSky& light, double overcast_share);
std::string EnvMapExr(const EnvMapParts& parts, const estimation::SunSky& light, double overcast_share);

struct FrameLighting {
  estimation::FrameEstimate row;   // frame, time, sun position, E_sun, E_sky (filtered), confidence
  double exposure = 1.0;           // k: the frame's linear pixel value per radiance unit
  glm::vec3 sun_scene{0.0f};       // unit, toward the sun, scene coordinates
  glm::vec3 sun_camera{0.0f};      // the same in the camera's (OpenCV: x right, y down, z forward)
  double overcast_share = 0.0;     // E_overcast / E_sky
  sh::Sh9Snapshot volume;          // the irradiance volume (sun excluded); empty without one
  std::shared_ptr<const EnvMapParts> envmap;  // null without a relit map yet
  // The camera frame (capture::Frame::rgb, shared, never written again): encoded by the camera's
  // response, or linear pixel values when `linear_response` is set (then encoded with it for
  // JPEG). Empty when the frame could not be read.
  cv::Mat image;
  std::shared_ptr<const capture::CameraResponse> linear_response;
};

// The message: sphericalHarmonicsCoefficients at `at` (default the volume box's centre), or null
// without a volume.
nlohmann::json LightingJson(const FrameLighting& lighting, const std::optional<glm::vec3>& at = std::nullopt);

// What GET /scene tells a renderer that places its own camera (docs/serve.md): intrinsics,
// world_to_camera and the camera's centre, response and exposure, up, north, units, the virtual
// objects and the volume's box.
std::string SceneJson(const scene::Scene& scene);

// The 27 numbers of sphericalHarmonicsCoefficients from irradiance coefficients (the volume's,
// E(n) = Σ_c e_c Y_c(n)): radiance coefficients L_lm = e_lm / Â_l, the form three.js's LightProbe
// and WebXR's Float32Array take, coefficient-major (c0 R, c0 G, c0 B, c1 R, ...).
std::array<float, 27> RadianceCoefficients(const std::array<float, 27>& irradiance);

}  // namespace daylit::serve
