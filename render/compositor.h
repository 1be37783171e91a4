// The virtual objects drawn into the camera frame in linear light (seed 001's rendering):
//   - the background is the linear frame in radiance units, with composite::ObjectShadows already
//     applied (the objects' shadows and sky loss on real surfaces are computed per pixel on the
//     CPU, from the bake's G-buffer);
//   - the real model is drawn into depth only, a phantom, so real walls hide objects behind them;
//   - each object fragment is L = ρ/π (E_sun·v·max(0, n·l) + E_volume(p, n)): v from a sun shadow
//     map of the real model and the objects (so real walls shade objects, and objects each other
//     and themselves), E_volume the SH9 irradiance volume: its coefficients trilinear at the
//     vertices, interpolated across each triangle, evaluated with the fragment's normal;
//   - 4× MSAA in RGBA32F over transparent black, resolved, read back and blended over the frame
//     by its coverage (as MSAA over the frame drawn first, without drawing it).
// Only the rectangle the objects project to is drawn and read back (the rest of the
// frame is the background as it was), and the sun's shadow map is redrawn only when it is handed
// another sun direction than the last (a new one only when the sun has moved: scene::SunTracker).
// Needs a current GL 3.3 core context (render/gl_context.h).
#pragma once

#include <string>

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "estimation/lighting_model.h"
#include "sh/irradiance_volume.h"
#include "lightfit/lights.h"
#include "scene/scene.h"

namespace daylit::render {

struct CompositeInput {
  estimation::SunSky light;           // E_sun (DNI) and E_sky, radiance units
  glm::vec3 sun_dir{0.0f, 0.0f, 1.0f};  // unit, toward the sun, scene coordinates
  const sh::IrradianceVolume* volume = nullptr;  // updated for this frame; always the same one; null: no indirect light
  // Instead of the volume (null), directional lights and an ambient term per object, in the
  // scene's order (lightfit::EnvLights: the same directions for all, as many as
  // CompositorOptions::lights, each light's irradiance as seen from that object), each light with
  // a shadow map of the objects (the real model's occlusion is in each object's lights). The shadow
  // maps are redrawn when `lights_generation` changes.
  const std::vector<lightfit::LightSet>* lights = nullptr;
  int lights_generation = 0;
};

struct CompositorOptions {
  int samples = 4;             // MSAA
  int shadow_map_size = 2048;  // texels over the objects' bounds, seen from the sun
  int lights = 0;                    // the number of CompositeInput::lights it is made for (0 to 16)
  int light_shadow_map_size = 1024;  // the shadow map's size for each of them
  // Empty when every field is in range, else the first problem, naming the field.
  std::string Check() const;
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
  // scene::ShadingMesh order (composite::ObjectBounce); applied with the volume's light.
  void SetObjectLosses(const std::vector<glm::vec3>& sun_loss, const std::vector<glm::vec3>& sky_loss);

  // Draws the objects into `image`: camera-size linear RGB, row-major from the top row, holding
  // the background (the frame with the objects' shadows applied).
  void Render(const CompositeInput& input, float* image);

  // The pixels the objects can cover (x, y of the top-left corner, width, height; empty without
  // objects): their projection, a pixel wider. Pixels outside it are never changed.
  struct Rect {
    int x = 0, y = 0, width = 0, height = 0;
  };
  const Rect& objects_rect() const;

 private:
  struct Gl;
  // Render's steps, in order.
  void UpdateShadowMaps(const CompositeInput& input, const glm::vec3& sun);
  void UpdateVertexLight(const sh::IrradianceVolume& volume);
  void DrawObjects(const CompositeInput& input, const glm::vec3& sun);
  void BlendOver(float* image);

  std::unique_ptr<Gl> gl_;
};

}  // namespace daylit::render
