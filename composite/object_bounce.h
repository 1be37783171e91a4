// The light a virtual object loses because it shades the real ground around it. The irradiance
// volume sees the real scene as the camera does, without the objects, so an object's underside
// would get the sunlit ground's bounce even where the object's own shadow lies. Per vertex of
// each object (scene::ShadingMesh order), cosine-weighted rays find the real points y it sees;
// their radiance drops by ρ_y/π (E_sun cos_y (s_y − s'_y) + E_sky ΔV_y), where s' and ΔV are the
// sun and sky the objects take from y (as in ObjectShadows). The vertex's irradiance then drops
// by E_sun·A_sun + E_sky·A_sky with, over its N rays,
//   A_sun = (1/N) Σ ρ_y cos_y (s_y − s'_y),  A_sky = (1/N) Σ ρ_y ΔV_y
// (RGB, ρ the surface's albedo from the bake). A_sky once; A_sun when handed another sun direction
// (scene::SunTracker's: a new one only when the sun moved).
#pragma once

#include <string>

#include <vector>

#include <glm/glm.hpp>

#include "bake/bake.h"
#include "scene/raycaster.h"
#include "scene/scene.h"

namespace daylit::composite {

struct ObjectBounceOptions {
  int rays = 64;       // per vertex, cosine-weighted
  int sky_rays = 32;   // per real point seen, for ΔV
  float offset_m = 2e-3f;
  // Empty when every field is in range, else the first problem, naming the field.
  std::string Check() const;
};

class ObjectBounce {
 public:
  // At the vertices of every object's scene::ShadingMesh, in order.
  ObjectBounce(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& real,
               const scene::RayCaster& objects, const ObjectBounceOptions& options = {});
  // At the given points of the objects' surfaces, with unit normals facing out.
  ObjectBounce(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& real,
               const scene::RayCaster& objects, const std::vector<glm::vec3>& positions,
               const std::vector<glm::vec3>& normals, const ObjectBounceOptions& options = {});

  bool SetSun(const glm::vec3& sun_dir);

  // Per vertex (or point), in order: the irradiance lost per unit E_sun and per unit E_sky.
  const std::vector<glm::vec3>& sun_loss() const { return sun_loss_; }
  const std::vector<glm::vec3>& sky_loss() const { return sky_loss_; }

 private:
  struct Seen {
    uint32_t vertex;
    glm::vec3 point, normal, albedo_over_n;  // ρ_y / N
  };
  const scene::RayCaster& real_;
  const scene::RayCaster& objects_;
  ObjectBounceOptions options_;
  std::vector<Seen> seen_;
  std::vector<glm::vec3> sun_loss_, sky_loss_;
  glm::vec3 sun_{0.0f};
  bool has_sun_ = false;
};

}  // namespace daylit::composite
