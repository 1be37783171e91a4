// What the virtual objects do to the light on the real surfaces the camera sees (seed 001 §3.2,
// with contact shadows the seed did not have). A real point with albedo ρ and irradiance B shows
// L_cam = ρ/π·B; an object takes ΔB from it, so
//
//   L_new = L_cam · (B − ΔB) / B = L_cam − ρ/π · ΔB,
//   ΔB = E_sun·max(0, n·l)·(s − s') + E_blocked − E_reflected
//
// with B read from the frame itself (so the light walls reflect into a shadow stays in it; the
// bare model's E_sky·V + E_sun·s·max(0, n·l) leaves it out and made shadows 20-40% too dark).
// s is the share of the sun's 0.53° disc the point sees past the real model, s' past the objects
// too, over the pixel's footprint: a virtual shadow inside a real one changes nothing (no double
// darkening), and shadows have penumbrae and edges a pixel wide, as a camera sees them. E_blocked is the light arriving from the directions an object now covers: the
// sky and the reflecting real surfaces behind it, read from the relit environment map with
// parallax as the irradiance volume's probes read it (a covered ray's texel is the one showing
// the real point behind the object from the capture position, or the sky layer's in its own
// direction where nothing real is behind it: bake/parallax.h).
// Without a map it is E_sky times the share of the sky covered. E_reflected is what the objects
// send back the same directions (SetObjectRadiance, from composite::ObjectLight). ρ is the bake's camera albedo.
// Embree rays against the objects' meshes: the covered directions once (the objects do not move),
// the sun whenever it is handed another direction (scene::SunTracker's: a new one only when the sun
// has moved).
#pragma once

#include <string>

#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "bake/bake.h"
#include "estimation/lighting_model.h"
#include "relight/env_relight.h"
#include "scene/raycaster.h"
#include "scene/scene.h"

namespace daylit::composite {

struct ObjectShadowOptions {
  int sky_rays = 256;          // cosine-weighted rays per pixel for V' (as the bake's V)
  float reach_radii = 12.0f;   // pixels farther than this many bounding radii from every object
                               // lose under 0.7% of their light to it and are skipped
  float offset_m = 2e-3f;      // ray origins off the surface, as in the bake
  int sun_rays = 16;           // over the sun's 0.53° disc, for penumbrae
  // Empty when every field is in range, else the first problem, naming the field.
  std::string Check() const;
};

class ObjectShadows {
 public:
  // `objects` is a caster over scene::ObjectsModel(scene.objects); `real` over the scene's model.
  ObjectShadows(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& real,
                const scene::RayCaster& objects, const ObjectShadowOptions& options = {});

  // Recasts the sun rays when `sun_dir` is not the direction of the last cast (or there was none);
  // the pipeline hands on a new one only when the sun has moved (scene::SunTracker). Returns
  // whether it did.
  bool SetSun(const glm::vec3& sun_dir);

  // The light from the directions the objects cover, per unit of each light, from the relit
  // map's basis (relight::EnvRelighter::Basis) for the current sun: call it whenever that changes. Until
  // then a covered direction carries E_sky per unit solid angle share.
  void SetEnvBasis(const relight::EnvBasis& basis);

  // The objects reflect light too: a covered direction also brings the radiance of the object's
  // surface it meets, so the ground beside a sunlit white sphere gets brighter, and what an object
  // takes from a shaded wall is partly given back. These are the triangle sides of the objects'
  // model (triangle·2, + 1 for its back) that covered directions meet, sorted.
  const std::vector<uint32_t>& ReflectingSides() const { return reflecting_sides_; }
  // Their radiance per unit of E_sun, E_clear and E_overcast (composite::ObjectLight), one value
  // per ReflectingSides() entry in each part. Until it is given the objects reflect nothing.
  void SetObjectRadiance(const std::array<std::vector<glm::vec3>, 3>& radiance);

  // Takes the objects' share from a linear RGB frame in radiance units (camera size, row-major, 3
  // floats per pixel) under `light` with its overcast share (as relight::EnvRelighter::Relight); pixels
  // the objects do not touch are left exactly as they were.
  void Apply(const estimation::SunSky& light, double overcast_share, float* rgb);

  // Pixels that lose light from directions an object covers, and those in an object's sun shadow.
  size_t SkyLossPixels() const;
  size_t ShadowPixels() const;

 private:
  struct Affected {
    uint32_t pixel;
    float cos_sun = 0.0f;    // max(0, n·l)
    bool covers = false;     // an object covers some of the point's hemisphere
    float sky_lost = 0.0f;   // share of the cosine-weighted sky the objects cover
    uint32_t first = 0, count = 0;  // its covered rays' stacked-map indices in covered_texels_
    float sun_lost = 0.0f;   // s − s': the share of the sun's disc the point sees past the real
                             // model (s) but not past the objects too (s')
    uint32_t neighbours = 0;  // bit (dy + 2)·5 + dx + 2: the 5×5 neighbour is on the frame and the same surface
    glm::vec3 covered_sun{0.0f}, covered_clear{0.0f}, covered_overcast{0.0f};  // ray_weight·Σ basis over covered rays
    glm::vec3 reflected_sun{0.0f}, reflected_clear{0.0f}, reflected_overcast{0.0f};  // ray_weight·Σ the objects' radiance
  };
  // What Apply reads of each affected pixel (in the same order): the irradiance it loses per
  // unit of E_sun, E_clear and E_overcast. Remade after the sun or the basis changed.
  struct Loss {
    uint32_t pixel, neighbours;
    glm::vec3 sun, clear, overcast;
  };
  void FindNeighbours(Affected* a) const;
  // A pixel's footprint on its surface: the steps of one pixel along x and y.
  struct Footprint {
    glm::vec3 dx, dy;
  };
  Footprint FootprintOf(uint32_t pixel) const;
  void PrepareLoss();

  const bake::CameraGBuffer& gbuffer_;
  const scene::RayCaster& real_;
  const scene::RayCaster& objects_;
  ObjectShadowOptions options_;
  std::vector<glm::vec4> spheres_;  // objects' bounding spheres (centre, radius)
  std::vector<Affected> affected_;  // sorted by pixel
  std::vector<uint32_t> covered_texels_;
  std::vector<uint32_t> covered_sides_;     // per covered ray, its object side's index in reflecting_sides_
  std::vector<uint32_t> reflecting_sides_;
  float ray_weight_ = 0.0f;         // π/N: E = ray_weight · Σ L over covered rays
  bool has_basis_ = false;
  std::vector<glm::vec3> pi_over_albedo_;  // per camera pixel: B = π·L/ρ
  std::vector<Loss> loss_;          // one per affected_, in its order
  std::vector<uint32_t> row_begin_;  // per camera row (and one past): its first pixel in affected_
  bool loss_ready_ = false;
  std::vector<float> weighted_;      // Apply's π·L/ρ
  std::vector<glm::vec3> disc_;     // directions over the sun's disc
  std::vector<glm::vec2> jitter_;   // per direction, where in the pixel (−0.5 … 0.5) its ray leaves
  glm::vec3 sun_{0.0f};
  bool has_sun_ = false;
};

}  // namespace daylit::composite
