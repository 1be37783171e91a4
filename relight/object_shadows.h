// What the virtual objects do to the light on the real surfaces the camera sees (seed 001 §3.2,
// with contact shadows the seed did not have). Per camera pixel on the model, with n its normal,
// l the sun, s its sun visibility through the real model, V its sky visibility (the bake's):
//
//   L_new = L_cam · (E_sky·V' + E_sun·s'·max(0, n·l)) / (E_sky·V + E_sun·s·max(0, n·l))
//
// s' = s unless an object is between the point and the sun: a virtual shadow inside a real one
// changes nothing (no double darkening). V' = V less the cosine-weighted share of the sky that
// an object hides from the point. Both come from Embree rays against the objects' meshes: V' once
// (the objects do not move), s' whenever the sun moves by more than 0.05°.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "bake/bake.h"
#include "estimation/lighting_model.h"
#include "scene/raycaster.h"
#include "scene/scene.h"

namespace daylit::relight {

struct ObjectShadowOptions {
  int sky_rays = 256;          // cosine-weighted rays per pixel for V' (as the bake's V)
  float reach_radii = 12.0f;   // pixels farther than this many bounding radii from every object
                               // lose under 0.7% of their sky to it and are skipped
  float offset_m = 2e-3f;      // ray origins off the surface, as in the bake
};

class ObjectShadows {
 public:
  // `objects` is a caster over scene::ObjectsModel(scene.objects); `real` over the scene's model.
  ObjectShadows(const scene::Scene& scene, const bake::CameraGBuffer& gbuffer, const scene::RayCaster& real,
                const scene::RayCaster& objects, const ObjectShadowOptions& options = {});

  // Recasts the sun rays when the sun has moved more than 0.05° since the last cast (or never
  // was). Returns whether it did.
  bool SetSun(const glm::vec3& sun_dir);

  // Multiplies a linear RGB frame (camera size, row-major, 3 floats per pixel) by the ratio above
  // for `light`; pixels the objects do not touch are left exactly as they were.
  void Apply(const estimation::SunSky& light, float* rgb) const;

  // The ratio at one pixel (1 where the objects change nothing), for tests and the report.
  glm::vec3 Ratio(const estimation::SunSky& light, size_t pixel) const;

  // Pixels whose sky an object hides (ΔV > 0), and those in an object's sun shadow only.
  size_t SkyLossPixels() const;
  size_t ShadowPixels() const;

 private:
  struct Affected {
    uint32_t pixel;
    float cos_sun = 0.0f;    // max(0, n·l)
    float sky = 0.0f;        // V
    float sky_lost = 0.0f;   // V − V'
    uint8_t sun_real = 0;    // s
    uint8_t sun_with = 0;    // s'
  };

  const bake::CameraGBuffer& gbuffer_;
  const scene::RayCaster& real_;
  const scene::RayCaster& objects_;
  ObjectShadowOptions options_;
  std::vector<glm::vec4> spheres_;  // objects' bounding spheres (centre, radius)
  std::vector<Affected> affected_;  // sorted by pixel
  std::vector<uint32_t> lit_;       // model pixels facing the sun whose sun ray passes an object's sphere
  glm::vec3 sun_{0.0f};
  bool has_sun_ = false;
};

}  // namespace daylit::relight
