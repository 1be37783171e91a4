// The lighting server's sink (replay and live --serve): each frame's lighting handed to
// serve::LightingServer.
#pragma once

#include <memory>

#include "capture/response.h"
#include "pipeline/lighting_pipeline.h"
#include "render/frame_renderer.h"
#include "scene/scene.h"
#include "serve/lighting_server.h"

namespace daylit::pipeline {

// Each frame's lighting to the lighting server: the estimate, the sun in scene and camera
// coordinates, the irradiance volume as the renderer left it (a copy of its coefficients), the
// relit map's parts (shrunk once per sun) and the camera frame (shared, not copied).
class ServeSink : public FrameSink {
 public:
  ServeSink(const scene::Scene& scene, const render::FrameRenderer& renderer, serve::LightingServer* server)
      : scene_(scene), renderer_(renderer), server_(server),
        response_(std::make_shared<const capture::CameraResponse>(scene.response)) {}
  void Consume(const PipelineFrame& f) override;

 private:
  const scene::Scene& scene_;
  const render::FrameRenderer& renderer_;
  serve::LightingServer* server_;
  std::shared_ptr<const capture::CameraResponse> response_;
  std::shared_ptr<const serve::EnvMapParts> envmap_;
  int envmap_generation_ = 0;
};

}  // namespace daylit::pipeline
