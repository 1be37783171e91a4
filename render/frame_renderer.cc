#include "render/frame_renderer.h"

#include "base/options_check.h"

#include "base/check.h"
#include "base/error.h"
#include "scene/object_mesh.h"

namespace daylit::render {
namespace {

CompositorOptions CompositorFor(const FrameRendererOptions& options, const scene::Scene& scene) {
  CompositorOptions compositor = options.compositor;
  compositor.lights = scene.objects.empty() ? 0 : options.lights;
  return compositor;
}

}  // namespace

FrameRenderer::FrameRenderer(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                             const FrameRendererOptions& options)
    : objects_model_(scene::ObjectsModel(scene.objects)),
      objects_(objects_model_),
      shadows_(scene, bake, caster, objects_),
      bounce_(scene, bake, caster, objects_),
      object_light_(scene, bake, caster, objects_, shadows_.ReflectingSides()),
      relighter_(bake, scene.envmap ? glm::vec3(scene.envmap->position) : glm::vec3(0.0f), caster),
      compositor_(scene, CompositorFor(options, scene)),
      linearizer_(scene.response) {
  DAYLIT_CHECK(options.Check().empty(), "{}", options.Check());
  scene::CheckObjectsOutsideModel(objects_model_, caster, scene.file.string());
  // The volume lights the objects, or with lights:N gives what the objects reflect onto the real
  // surfaces only.
  if (!bake.gather.directions.empty()) {
    volume_ = std::make_unique<sh::IrradianceVolume>(bake.gather, bake::ProbesInsideModel(bake.gather, caster));
  }
  if (options.lights > 0 && !scene.objects.empty()) {
    if (!scene.envmap) ThrowInputError("{}: --lighting lights:{} needs the scene's envmap", scene.file.string(), options.lights);
    std::vector<glm::vec3> centres;
    for (const scene::VirtualObject& o : scene.objects) centres.push_back(glm::vec3(o.position));
    env_lights_ = std::make_unique<lightfit::EnvLights>(options.lights, caster, centres, glm::vec3(scene.envmap->position),
                                                       bake.env.width, bake.env.height);
  }
}

int ParseLighting(const std::string& text, const char* where) {
  if (text == "volume") return 0;
  if (text.rfind("lights:", 0) == 0) {
    const std::string n = text.substr(7);
    if (!n.empty() && n.size() <= 3 && n.find_first_not_of("0123456789") == std::string::npos) {
      const int count = std::stoi(n);
      if (count >= 1 && count <= lightfit::EnvLights::kMaxLights) return count;
      ThrowInputError("{}: {} lights; give 1 to {}", where, count, lightfit::EnvLights::kMaxLights);
    }
  }
  ThrowInputError("{}: '{}' is not volume or lights:N", where, text);
}

void FrameRenderer::Linearize(const capture::Frame& frame, std::vector<float>* linear) const {
  if (frame.rgb.cols != width() || frame.rgb.rows != height() || frame.rgb.type() != CV_32FC3) {
    DAYLIT_CHECK(false, "frame {}: {}x{}, not the camera's {}x{}", frame.index, frame.rgb.cols, frame.rgb.rows, width(), height());
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
  const estimation::LightParts e = estimation::SplitLight(light, overcast_share);
  if (volume_ || env_lights_) {
    if (bounce_.SetSun(sun_dir)) compositor_.SetObjectLosses(bounce_.sun_loss(), bounce_.sky_loss());
    // The relit map is linear in E_sun, E_clear and E_overcast, and so are the volume and the
    // lights' irradiances: the three parts are made when the sun moves, and each frame only
    // combines them.
    if (relighter_.SetSun(sun_dir)) {
      relighter_.Basis(&basis_);
      ++basis_generation_;
      shadows_.SetEnvBasis(basis_);
      if (env_lights_) env_lights_->SetBasis(basis_);
      const std::vector<glm::vec3>* maps[3] = {&basis_.sun, &basis_.clear, &basis_.overcast};
      for (size_t i = 0; i < 3; ++i) {
        if (!volume_) continue;
        volume_->Update(*maps[i]);
        volume_parts_[i] = volume_->coefficients();
      }
      UpdateObjectLight(sun_dir);
    }
  }
  if (env_lights_) {
    // The lights are fitted again when the combination has drifted too far (lightfit::EnvLights).
    input.lights = &env_lights_->Update(e);
    input.lights_generation = env_lights_->generation();
  } else if (volume_) {
    FollowLight(light, overcast_share);
    input.volume = volume_.get();
  }
  shadows_.SetSun(sun_dir);
  shadows_.Apply(light, overcast_share, image);
  compositor_.Render(input, image);
}

void FrameRenderer::FollowLight(const estimation::SunSky& light, double overcast_share) {
  if (!volume_ || env_lights_ || volume_parts_[0].empty()) return;  // no volume, or none made yet
  const estimation::LightParts e = estimation::SplitLight(light, overcast_share);
  volume_->SetCombination({&volume_parts_[0], &volume_parts_[1], &volume_parts_[2]}, {e.sun, e.clear, e.overcast});
}

void FrameRenderer::UpdateObjectLight(const glm::vec3& sun_dir) {
  // Each side's indirect light, part by part, from the volume (none without one).
  const std::vector<glm::vec3>& points = object_light_.points();
  const std::vector<glm::vec3>& normals = object_light_.normals();
  std::array<std::vector<glm::vec3>, 3> indirect;
  for (size_t k = 0; k < 3; ++k) {
    indirect[k].assign(points.size(), glm::vec3(0.0f));
    if (!volume_) continue;
    std::array<glm::vec3, 3> unit = {glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f)};
    unit[k] = glm::vec3(1.0f);
    volume_->SetCombination({&volume_parts_[0], &volume_parts_[1], &volume_parts_[2]}, unit);
    for (size_t i = 0; i < points.size(); ++i) indirect[k][i] = volume_->Irradiance(points[i], normals[i]);
  }
  object_light_.SetSun(sun_dir);
  std::array<std::vector<glm::vec3>, 3> radiance;
  object_light_.Radiance(indirect, &radiance);
  shadows_.SetObjectRadiance(radiance);
}

std::string FrameRendererOptions::Check() const {
  return FirstProblem({Nested("compositor", compositor.Check()),
                       InClosed("lights", lights, 0, lightfit::EnvLights::kMaxLights)});
}

}  // namespace daylit::render
