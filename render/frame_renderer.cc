#include "render/frame_renderer.h"

#include "base/error.h"
#include "scene/object_mesh.h"

namespace daylit::render {

FrameRenderer::FrameRenderer(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                             const CompositorOptions& options)
    : scene_(scene),
      caster_(caster),
      objects_model_(scene::ObjectsModel(scene.objects)),
      objects_(objects_model_),
      shadows_(scene, bake, caster, objects_),
      bounce_(scene, bake, caster, objects_),
      relighter_(bake, scene.envmap ? glm::vec3(scene.envmap->position) : glm::vec3(0.0f), caster),
      compositor_(scene, options),
      linearizer_(scene.response) {
  scene::CheckObjectsOutsideModel(objects_model_, caster, scene.file.string());
  if (!bake.gather.directions.empty()) {
    volume_ = std::make_unique<relight::IrradianceVolume>(bake.gather, relight::ProbesInsideModel(bake.gather, caster));
  }
}

void FrameRenderer::Linearize(const capture::Frame& frame, std::vector<float>* linear) const {
  if (frame.rgb.cols != width() || frame.rgb.rows != height() || frame.rgb.type() != CV_32FC3) {
    ThrowInputError("frame {}: {}x{}, not the camera's {}x{}", frame.index, frame.rgb.cols, frame.rgb.rows, width(), height());
  }
  capture::LinearRadiance(frame, linearizer_, linear);
}

void FrameRenderer::Render(const capture::Frame& frame, const estimation::SunSky& light, double overcast_share,
                           const glm::vec3& sun_dir, std::vector<float>* out) {
  Linearize(frame, out);
  RenderLinear(light, overcast_share, sun_dir, out->data());
}

void FrameRenderer::RenderLinear(const estimation::SunSky& light, double overcast_share, const glm::vec3& sun_dir,
                                 float* image) {
  CompositeInput input;
  input.light = light;
  input.sun_dir = sun_dir;
  if (volume_) {
    if (bounce_.SetSun(sun_dir)) compositor_.SetObjectLosses(bounce_.sun_loss(), bounce_.sky_loss());
    // The relit map is linear in E_sun, E_clear and E_overcast, and so is the volume: the three
    // parts are recomputed when the sun moves, and each frame only combines them.
    if (relighter_.SetSun(sun_dir)) {
      relighter_.Basis(&basis_);
      shadows_.SetEnvBasis(basis_);
      const std::vector<glm::vec3>* maps[3] = {&basis_.sun, &basis_.clear, &basis_.overcast};
      for (size_t i = 0; i < 3; ++i) {
        volume_->Update(*maps[i]);
        volume_parts_[i] = volume_->coefficients();
      }
    }
    const relight::LightParts e = relight::SplitLight(light, overcast_share);
    volume_->SetCombination({&volume_parts_[0], &volume_parts_[1], &volume_parts_[2]}, {e.sun, e.clear, e.overcast});
    input.volume = volume_.get();
  }
  shadows_.SetSun(sun_dir);
  shadows_.Apply(light, overcast_share, image);
  compositor_.Render(input, image);
}

}  // namespace daylit::render
