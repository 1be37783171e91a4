// One frame of the augmented video, from a fitted frame (pipeline::FitRecordingFrame or the replay's
// estimate) to the composite in linear radiance units: the frame linearised with the camera
// response and its exposure divided out, the objects' shadows and sky loss applied to the real
// surfaces (composite::ObjectShadows) less what the objects reflect onto them
// (composite::ObjectLight), the environment map relit with the estimate and the irradiance
// volume updated from it, then the objects drawn (Compositor). Needs a current GL
// context; everything sun-dependent is recomputed only when the sun has moved.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "estimation/frame_estimator.h"
#include "render/compositor.h"
#include "lightfit/env_lights.h"
#include "relight/env_relight.h"
#include "sh/irradiance_volume.h"
#include "composite/object_bounce.h"
#include "composite/object_light.h"
#include "composite/object_shadows.h"
#include "scene/raycaster.h"
#include "scene/scene.h"

namespace daylit::render {

struct FrameRendererOptions {
  CompositorOptions compositor;
  // 0: the objects' light besides the sun is the irradiance volume. N > 0: N directional lights
  // and an ambient term fitted to the relit env map (lightfit::EnvLights), each casting shadows
  // (daylit render/replay --lighting lights:N).
  int lights = 0;
  // Empty when every field is in range, else the first problem, naming the field.
  std::string Check() const;
};

// "volume" → 0, "lights:N" → N (1..16); InputError "<where>: ..." otherwise.
int ParseLighting(const std::string& text, const char* where);

class FrameRenderer {
 public:
  // `caster` is over the scene's model; the renderer's parts keep references to all three.
  FrameRenderer(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                const FrameRendererOptions& options = {});

  // The composite of `frame` under `light` (the estimate, filtered or not) and the sun `sun_dir`.
  void Render(const capture::Frame& frame, const estimation::SunSky& light, double overcast_share,
              const glm::vec3& sun_dir, std::vector<float>* out);
  // The same from the frame linearised already (`image`, width × height × 3, in place): a
  // relit frame, say (relight::ImageRelighter).
  void RenderLinear(const estimation::SunSky& light, double overcast_share, const glm::vec3& sun_dir, float* image);

  // A frame without a composite (a live camera's while the pipeline is behind): the irradiance
  // volume follows `light` as Render would leave it, from the parts made for the last sun, at
  // the cost of one weighted sum (volume() then reads it). No GL.
  void FollowLight(const estimation::SunSky& light, double overcast_share);

  // The frame linearised in radiance units, as Render starts from (for comparisons).
  void Linearize(const capture::Frame& frame, std::vector<float>* linear) const;
  const composite::ObjectShadows& shadows() const { return shadows_; }
  // The irradiance volume as the last Render left it (sun excluded); null without one.
  const sh::IrradianceVolume* volume() const { return volume_.get(); }
  // The relit map's parts for the current sun (EnvRelighter::Basis), and how many times they
  // were made: a reader copies them again only when that count moved. Empty before the first
  // Render with a volume or lights.
  const relight::EnvBasis& env_basis() const { return basis_; }
  int env_basis_generation() const { return basis_generation_; }
  const relight::EnvRelighter& relighter() const { return relighter_; }
  // With --lighting lights:N, the lights (null otherwise).
  const lightfit::EnvLights* env_lights() const { return env_lights_.get(); }
  int width() const { return compositor_.width(); }
  int height() const { return compositor_.height(); }

 private:
  // The objects' own radiance for a new sun, from the volume's parts (composite::ObjectLight).
  void UpdateObjectLight(const glm::vec3& sun_dir);

  scene::SceneModel objects_model_;  // before objects_, which keeps a reference to it
  scene::RayCaster objects_;
  composite::ObjectShadows shadows_;
  composite::ObjectBounce bounce_;
  composite::ObjectLight object_light_;  // what the objects reflect onto the real surfaces
  relight::EnvRelighter relighter_;
  std::unique_ptr<sh::IrradianceVolume> volume_;
  Compositor compositor_;
  capture::Linearizer linearizer_;
  relight::EnvBasis basis_;
  int basis_generation_ = 0;
  std::array<std::vector<float>, 3> volume_parts_;  // the volume per unit E_sun, E_clear, E_overcast
  std::unique_ptr<lightfit::EnvLights> env_lights_;  // --lighting lights:N
};

}  // namespace daylit::render
