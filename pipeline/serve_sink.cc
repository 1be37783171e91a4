#include "pipeline/serve_sink.h"

#include <utility>

#include <glm/glm.hpp>

namespace daylit::pipeline {

void ServeSink::Consume(const PipelineFrame& f) {
  auto l = std::make_shared<serve::FrameLighting>();
  l->row = f.light.row;
  l->exposure = f.frame.exposure;
  l->overcast_share = f.light.overcast_share;
  l->sun_scene = f.sun.dir_in_scene;
  l->sun_camera = glm::vec3(scene_.cam_from_world.rotation * glm::dvec3(f.sun.dir_in_scene));
  if (const sh::IrradianceVolume* volume = renderer_.volume()) volume->Snapshot(&l->volume);
  if (renderer_.env_basis_generation() != envmap_generation_) {
    const relight::EnvBasis& basis = renderer_.env_basis();
    const relight::EnvRelighter& map = renderer_.relighter();
    envmap_ = serve::ShrinkEnvMapParts(map.width(), map.height(), basis.sun, basis.clear, basis.overcast);
    envmap_generation_ = renderer_.env_basis_generation();
  }
  l->envmap = envmap_;
  l->image = f.frame.rgb;
  if (f.frame.linear) l->linear_response = response_;
  server_->Publish(std::move(l));
}

}  // namespace daylit::pipeline
