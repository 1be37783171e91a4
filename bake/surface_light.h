// Light at points of the model by ray casting (Embree): the cosine-weighted sky visibility V,
// the irradiance at env-map capture time with the env map itself as the light (for albedo by
// inverse rendering), and the per-frame sun visibility s.
#pragma once

#include <string>
#include <unordered_map>

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "bake/capture_light.h"
#include "base/progress.h"
#include "scene/hdr_image.h"
#include "scene/raycaster.h"

namespace daylit::bake {

struct RayOptions {
  int hemisphere_rays = 256;  // per point, stratified cosine-weighted: V within 0.01 (tests)
  float offset_m = 2e-3f;     // ray origins are moved this far along the normal (self-hits)
  // Empty when every field is in range, else the first problem, naming the field.
  std::string Check() const;
};

// Radiance of model points the capture point cannot see (the env map shows what hides them):
// L = ρ_s/π · (E_sun·s·max(0, n·l) + E_indirect) with the surface's albedo and the indirect
// irradiance of the point's cell (25 cm of one side of its surface), gathered by the cell's own
// rays. Indirect light under an overhang is local: the hidden underside of an arcade's roof gets
// 40% of what the roof's visible texels get, and a surface median gave it all of it.
struct HiddenSurfaceModel {
  std::vector<glm::vec3> albedo;    // per surface
  std::vector<glm::vec3> indirect;  // per surface: median E − E_sun over its visible texels
  std::unordered_map<uint64_t, glm::vec3> cell_indirect;  // CellKey -> E − E_sun at the cell's centre

  static constexpr float kCellSize = 0.25f;  // m
  // The cell of point y on `surface`, seen from the side its unit `normal` faces.
  static uint64_t CellKey(const glm::vec3& y, const glm::vec3& normal, uint32_t surface);
  // The cell's indirect irradiance, or the surface's where the cell was not gathered.
  glm::vec3 IndirectAt(const glm::vec3& y, const glm::vec3& normal, uint32_t surface) const;
};

// What the scene looked like at capture time.
struct CaptureScene {
  const scene::RayCaster* caster = nullptr;
  const HdrImage* env = nullptr;  // captured radiance, sun disc removed
  const HdrImage* sky = nullptr;  // SkyOnly(env): sky radiance in every direction
  const std::vector<float>* env_distance = nullptr;    // per texel: capture point to its hit (< 0: sky)
  const std::vector<uint32_t>* env_surface = nullptr;  // per texel: the surface it shows
  const std::vector<glm::vec3>* env_normal = nullptr;  // per texel: that surface's normal (facing the capture)
  const HiddenSurfaceModel* hidden = nullptr;         // null: hidden points take the texel's radiance
  glm::vec3 capture_position{0.0f};
  CaptureSun sun;
};

// Whether the capture point sees model point y (on `surface`, unit `normal` facing the side that
// is looked at, at `toward` = y − capture position) in the env texel toward it, whose own ray hits
// `seen_surface` with unit normal `seen_normal` at `seen_distance` (< 0: sky), in a map
// `env_height` texels high. A texel that shows the same plane from the same side may hit it a
// little off y (grazing views); another face of the same surface (a slab's front edge in front of
// its underside) is something else in front of y.
bool CaptureSees(const glm::vec3& toward, const glm::vec3& normal, uint32_t surface, float seen_distance,
                 uint32_t seen_surface, const glm::vec3& seen_normal, int env_height);

// For each point (unit normal facing its visible side): V = share of cosine-weighted rays that
// reach the sky, and E = E_sun·s·max(0, n·l) + π·mean(L_in), where L_in is the sky's radiance
// for rays that escape and, for rays that hit the model at y, y's radiance in the env map (the
// texel toward y from the capture position: one bounce), or the HiddenSurfaceModel's where the
// capture point does not see y. `direct` (optional) receives the E_sun·s·max(0, n·l) part.
// Parallel over points.
void IntegrateCaptureIrradiance(const CaptureScene& capture, const RayOptions& options, const glm::vec3* points,
                                const glm::vec3* normals, size_t count, float* sky_visibility, glm::vec3* irradiance,
                                glm::vec3* direct, Progress* progress);

// The cells of the hidden points that `options.hemisphere_rays` rays from the points hit, each
// gathered from its centre (dropped onto the plane of the hit that found it first) like
// IntegrateCaptureIrradiance gathers a point, hidden points of its own taking their surface's
// indirect light; into `hidden->cell_indirect`. `capture.hidden` must be `hidden`.
void GatherHiddenCells(const CaptureScene& capture, const RayOptions& options, const glm::vec3* points,
                       const glm::vec3* normals, size_t count, HiddenSurfaceModel* hidden, Progress* progress);

// V alone, with occlusion rays (cheaper than IntegrateCaptureIrradiance).
void SkyVisibility(const scene::RayCaster& caster, const RayOptions& options, const glm::vec3* points,
                   const glm::vec3* normals, size_t count, float* sky_visibility, Progress* progress);

// Sun visibility s ∈ {0, 1} toward unit `sun_dir`: 0 where the normal faces away or a shadow ray
// hits the model. This is what the online stages re-run when the sun has moved.
void SunVisibility(const scene::RayCaster& caster, const glm::vec3* points, const glm::vec3* normals, size_t count,
                   const glm::vec3& sun_dir, float offset_m, uint8_t* visible);

// The direct-sun term s·max(0, n·l) of the points `indices` of `points`/`normals` (for each
// index i: direct[i], and visible[i] = s if `visible` is given; other entries untouched). 0 for
// a sun at or below the horizon. This is what the online stages re-run when the sun has moved.
void DirectSun(const scene::RayCaster& caster, const glm::vec3* points, const glm::vec3* normals,
               const std::vector<uint32_t>& indices, const glm::vec3& sun_dir, float offset_m, float* direct,
               uint8_t* visible = nullptr);

}  // namespace daylit::bake
