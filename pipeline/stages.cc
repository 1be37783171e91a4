#include "pipeline/stages.h"

#include "base/options_check.h"

#include <algorithm>

namespace daylit::pipeline {

CompositeStage::CompositeStage(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                               render::FrameRenderer* renderer, const render::TimeSlider* slider)
    : scene_(scene), bake_(bake), caster_(caster), renderer_(*renderer), slider_(slider) {}

void CompositeStage::Prepare(const scene::TrackedSun& sun) {
  std::vector<float> black(static_cast<size_t>(renderer_.width()) * static_cast<size_t>(renderer_.height()) * 3, 0.0f);
  renderer_.RenderLinear({}, 0.0, sun.dir_in_scene, black.data());
}

void CompositeStage::Skip(const estimation::FrameLight& light) {
  renderer_.FollowLight(light.row.light, light.overcast_share);
}

ImageLight CompositeStage::Process(const capture::Frame& frame, const estimation::FrameLight& light,
                                   const scene::TrackedSun& sun, std::vector<float>* image) {
  const estimation::FrameEstimate& row = light.row;
  const std::optional<UtcTime> relit_to = slider_ != nullptr ? slider_->Target(row.time_utc) : std::nullopt;
  if (!relit_to || !row.HasEstimate()) {
    renderer_.Render(frame, row.light, light.overcast_share, sun.dir_in_scene, image);
    return relit_to ? ImageLight::kOtherLight : ImageLight::kFrameLight;
  }
  // Relit to the slider's time: the frame times E_new / E_now, the objects under the new sun.
  const glm::vec3 next_sun(scene::SunAt(scene_, *relit_to).dir);
  if (relighter_ == nullptr) relighter_ = std::make_unique<relight::ImageRelighter>(scene_, bake_, caster_);
  relighter_->SetSuns(sun.dir_in_scene, next_sun);
  estimation::SunSky next = row.light;
  if (next_sun.z <= 0.0f) next.sun_rgb = glm::dvec3(0.0);
  renderer_.Linearize(frame, image);
  relighter_->Apply(estimation::SplitLight(row.light, light.overcast_share), estimation::SplitLight(next, light.overcast_share),
                    image->data());
  renderer_.RenderLinear(next, light.overcast_share, next_sun, image->data());
  return ImageLight::kOtherLight;
}

RelightStage::RelightStage(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                           const relight::RelightTarget& target, const RelightStageOptions& options,
                           render::FrameRenderer* renderer)
    : target_(target),
      relighter_(scene, bake, caster, options.relight),
      renderer_(renderer),
      linearizer_(scene.response) {
  if (options.gpu) on_gpu_ = std::make_unique<render::ImageRelightGl>(relighter_.width(), relighter_.height());
}

void RelightStage::Relight(const capture::Frame& frame, const estimation::SunSky& now_light, double now_overcast_share,
                           const glm::vec3& now_sun_dir, double now_elevation_deg, std::vector<float>* image) {
  capture::LinearRadiance(frame, linearizer_, image);
  const estimation::SunSky next_light = relight::NewLight(target_, now_light, now_elevation_deg);
  const double next_overcast = relight::NewOvercastShare(target_, now_overcast_share);
  if (relighter_.SetSuns(now_sun_dir, target_.sun_dir_in_scene) && on_gpu_) on_gpu_->SetTerms(relighter_.terms());
  const estimation::LightParts now = estimation::SplitLight(now_light, now_overcast_share);
  const estimation::LightParts next = estimation::SplitLight(next_light, next_overcast);
  const relight::RelightStats stats =
      on_gpu_ ? on_gpu_->Apply(relighter_.terms(), now, next, image->data()) : relighter_.Apply(now, next, image->data());
  clamped_ += stats.clamped, model_pixels_ += stats.model_pixels;
  if (renderer_ != nullptr) renderer_->RenderLinear(next_light, next_overcast, target_.sun_dir_in_scene, image->data());
  ++relit_;
}

ImageLight RelightStage::Process(const capture::Frame& frame, const estimation::FrameLight& light,
                                 const scene::TrackedSun& sun, std::vector<float>* image) {
  if (!light.row.HasEstimate()) {
    ++unrelit_;
    capture::LinearRadiance(frame, linearizer_, image);
    return ImageLight::kFrameLight;
  }
  Relight(frame, light.row.light, light.overcast_share, sun.dir_in_scene, light.row.sun_elevation_deg, image);
  return ImageLight::kOtherLight;
}

double RelightStage::ClampedShare() const {
  return static_cast<double>(clamped_) / static_cast<double>(std::max<size_t>(model_pixels_, 1));
}

std::string RelightStageOptions::Check() const { return Nested("relight", relight.Check()); }

}  // namespace daylit::pipeline
