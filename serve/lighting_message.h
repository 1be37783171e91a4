// One frame's lighting as daylit serves it to other renderers (daylit replay/live --serve):
// JSON shaped like WebXR Lighting Estimation's XRLightProbe / XRLightEstimate where a name exists
// (primaryLightDirection, primaryLightIntensity, sphericalHarmonicsCoefficients), plus what
// daylit knows beyond it (E_sky, the sun's position, the confidence). The schema, its units and
// its mapping to ARCore, ARKit and Unity AR Foundation: docs/lighting.schema.json, docs/serve.md.
#pragma once

#include <array>
#include <optional>
#include <string>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "estimation/frame_estimator.h"
#include "sh/irradiance_volume.h"
#include "sh/sh9.h"

namespace daylit::serve {

// The schema's version: a client checks it before reading the fields.
inline constexpr const char* kLightingSchema = "daylit-lighting/1";

struct FrameLighting {
  estimation::FrameEstimate row;   // frame, time, sun position, E_sun, E_sky (filtered), confidence
  glm::vec3 sun_scene{0.0f};       // unit, toward the sun, scene coordinates
  glm::vec3 sun_camera{0.0f};      // the same in the camera's (OpenCV: x right, y down, z forward)
  double overcast_share = 0.0;     // E_overcast / E_sky
  sh::Sh9Snapshot volume;          // the irradiance volume (sun excluded); empty without one
};

// The message: sphericalHarmonicsCoefficients at `at` (default the volume box's centre), or null
// without a volume.
nlohmann::json LightingJson(const FrameLighting& lighting, const std::optional<glm::vec3>& at = std::nullopt);

// The 27 numbers of sphericalHarmonicsCoefficients from irradiance coefficients (the volume's,
// E(n) = Σ_c e_c Y_c(n)): radiance coefficients L_lm = e_lm / Â_l, the form three.js's LightProbe
// and WebXR's Float32Array take, coefficient-major (c0 R, c0 G, c0 B, c1 R, ...).
std::array<float, 27> RadianceCoefficients(const std::array<float, 27>& irradiance);

}  // namespace daylit::serve
