// The virtual objects drawn into the camera frame in linear light (seed 001's rendering):
//   - the background is the linear frame in radiance units, with relight::ObjectShadows already
//     applied (the objects' shadows and sky loss on real surfaces are computed per pixel on the
//     CPU, from the bake's G-buffer);
//   - the real model is drawn into depth only, a phantom, so real walls hide objects behind them;
//   - each object fragment is L = ρ/π (E_sun·v·max(0, n·l) + E_volume(p, n)): v from a sun shadow
//     map of the real model and the objects (so real walls shade objects, and objects each other
//     and themselves), E_volume the SH9 irradiance volume, trilinear per fragment;
//   - 4× MSAA in RGBA32F, resolved and read back as linear floats.
// Needs a current GL 3.3 core context (render/gl_context.h).
#pragma once

#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "estimation/lighting_model.h"
#include "scene/scene.h"

namespace daylit::render {

struct CompositeInput {
  const float* background = nullptr;  // camera-size linear RGB, row-major from the top row
  estimation::SunSky light;           // E_sun (DNI) and E_sky, radiance units
  glm::vec3 sun_dir{0.0f, 0.0f, 1.0f};  // unit, toward the sun, scene coordinates
  const std::vector<float>* volume = nullptr;  // IrradianceVolume::coefficients(); null: no indirect light
};

struct CompositorOptions {
  int samples = 4;             // MSAA
  int shadow_map_size = 2048;  // texels over the objects' bounds, seen from the sun
};

class Compositor {
 public:
  explicit Compositor(const scene::Scene& scene, const CompositorOptions& options = {});
  ~Compositor();
  Compositor(const Compositor&) = delete;
  Compositor& operator=(const Compositor&) = delete;

  int width() const;
  int height() const;

  // The irradiance each object vertex loses per unit E_sun and per unit E_sky, all objects in
  // scene::ObjectMesh order (relight::ObjectBounce); applied with the volume's light.
  void SetObjectLosses(const std::vector<glm::vec3>& sun_loss, const std::vector<glm::vec3>& sky_loss);

  // Renders one frame; `out` receives camera-size linear RGB, row-major from the top row.
  void Render(const CompositeInput& input, std::vector<float>* out);

 private:
  struct Gl;
  std::unique_ptr<Gl> gl_;
};

}  // namespace daylit::render
