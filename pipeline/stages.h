// The pipeline's image stages (FrameStage): the augmented frame of daylit replay and live (the
// composite, or with the window's time slider the frame relit to another time of day with the
// objects under that light), and the relit frame of daylit relight.
#pragma once

#include <string>

#include <memory>
#include <vector>

#include "pipeline/lighting_pipeline.h"
#include "relight/image_relight.h"
#include "relight/new_light.h"
#include "render/time_slider.h"
#include "render/frame_renderer.h"
#include "render/image_relight_gl.h"

namespace daylit::pipeline {

class CompositeStage final : public FrameStage {
 public:
  // All kept by reference. `slider` (optional) is read at each frame: while it has a target
  // time, the frame is relit to it (relight::ImageRelighter, made when first needed).
  CompositeStage(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                 render::FrameRenderer* renderer, const render::TimeSlider* slider = nullptr);
  ImageLight Process(const capture::Frame& frame, const estimation::FrameLight& light, const scene::TrackedSun& sun,
                     std::vector<float>* image) override;
  // One composite of a black frame under no light: the renderer's sun-dependent parts, its GL
  // programs and buffers made.
  void Prepare(const scene::TrackedSun& sun) override;
  // The renderer's irradiance volume follows the frame's light (FrameRenderer::FollowLight), so
  // that what the lighting server publishes is this frame's.
  void Skip(const estimation::FrameLight& light) override;

 private:
  const scene::Scene& scene_;
  const bake::SceneBake& bake_;
  const scene::RayCaster& caster_;
  render::FrameRenderer& renderer_;
  const render::TimeSlider* slider_;
  std::unique_ptr<relight::ImageRelighter> relighter_;
};

struct RelightStageOptions {
  relight::ImageRelightOptions relight;
  bool gpu = false;  // ratio and modulation in GL (render::ImageRelightGl); needs a current context
  // Empty when every field is in range, else the first problem, naming the field.
  std::string Check() const;
};

class RelightStage final : public FrameStage {
 public:
  // `renderer` (optional) draws the objects under the new light. All kept by reference.
  RelightStage(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
               const relight::RelightTarget& target, const RelightStageOptions& options,
               render::FrameRenderer* renderer = nullptr);
  // A frame without an estimate yet is written as it is (kFrameLight), and counted.
  ImageLight Process(const capture::Frame& frame, const estimation::FrameLight& light, const scene::TrackedSun& sun,
                     std::vector<float>* image) override;
  // One frame under its own (unfiltered) fit: daylit relight --frame.
  void Relight(const capture::Frame& frame, const estimation::SunSky& now_light, double now_overcast_share,
               const glm::vec3& now_sun_dir, double now_elevation_deg, std::vector<float>* image);

  const relight::ImageRelighter& relighter() const { return relighter_; }
  const relight::RelightTarget& target() const { return target_; }
  int relit() const { return relit_; }
  int unrelit() const { return unrelit_; }
  // Of the model's pixels over all frames relit, the share whose E_now was below the floor.
  double ClampedShare() const;

 private:
  const relight::RelightTarget& target_;
  relight::ImageRelighter relighter_;
  std::unique_ptr<render::ImageRelightGl> on_gpu_;
  render::FrameRenderer* renderer_;
  capture::Linearizer linearizer_;
  size_t clamped_ = 0, model_pixels_ = 0;
  int relit_ = 0, unrelit_ = 0;
};

}  // namespace daylit::pipeline
