// Light transport at points of the model (camera pixels, env-map texels) that stays linear in
// the light: the "precomputed per-point terms" of docs/design.md that take the model beyond
// seed 001. Per colour channel,
//
//   L(x) = ρ/π · ( E_sun · T_sun(x) + E_clear · T_clear(x) + E_overcast · T_overcast(x) )
//
// with E_sun the DNI and E_clear + E_overcast = E_sky the DHI, split between a sky shaped like the
// captured one (its (θ, γ) distribution: the bright horizon and the aureole around the sun) and a
// uniform overcast sky. Each T is the irradiance at x per unit of its E:
//
//   T_sun      = s·max(0, n·l) + (1/π) ∫ ρ_y · T_sun,y · cos θ dω
//   T_clear    = ∫ (L_clear(ω) / DHI) · v(x, ω) · cos θ dω + (1/π) ∫ ρ_y · T_clear,y · cos θ dω
//   T_overcast = V + (1/π) ∫ ρ_y · T_overcast,y · cos θ dω
//
// where the integrals run over x's hemisphere and y is the model point a direction ω hits. At y,
// the direct terms are exact (s_y·max(0, n_y·l) by a shadow ray; V_y, times the clear sky's weight
// for y's orientation) and y's own reflected light is its surface's mean over the traced points,
// iterated for a third bounce (each bounce off walls of albedo ~0.3-0.5 adds a few percent
// more). With a uniform sky and no reflection, T_sun = s·max(0, n·l) and T_clear = T_overcast = V:
// the model of seed 001. The reflected terms are what a courtyard adds: shadowed ground lit by
// sunlit walls, warm where the walls are red.
//
// The paths (which directions reach the sky, which model points the rays hit, and their ρ_y and
// V_y) do not depend on the sun, so they are traced once per point and kept; a new sun costs one
// shadow ray per bounce point and a table lookup per blocked or low sky direction.
#pragma once

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>

#include "bake/bake.h"
#include "bake/capture_light.h"
#include "estimation/lighting_model.h"
#include "scene/raycaster.h"

namespace daylit::estimation {

struct TransferOptions {
  int rays = 256;               // cosine-weighted hemisphere rays per point
  int hidden_sky_rays = 64;     // rays for V_y of bounce points the capture point does not see (per cell)
  float offset_m = 2e-3f;       // ray origins are moved this far along the normal
  bool interreflection = true;  // the reflected terms
  int bounces = 3;              // the first exact, the others through per-surface means
  bool sky_distribution = true; // the captured sky's (θ, γ) distribution; false: a uniform sky

  // Empty when every field is in range, else the first problem, naming the field.
  std::string Check() const;
};

// The points a LightTransfer works on: what the bake knows of each (arrays of `count`).
struct TransferPoints {
  const glm::vec3* point = nullptr;
  const glm::vec3* normal = nullptr;  // unit, facing the side that is seen
  const float* sky_visibility = nullptr;
  const uint32_t* surface = nullptr;
  size_t count = 0;

  static TransferPoints Camera(const bake::CameraGBuffer& g);  // the G-buffer's pixels
  static TransferPoints Env(const bake::EnvMapMaps& env);      // the env map's texels
};

// estimation::Transfer (lighting_model.h): irradiance per unit of each part of the light.

class LightTransfer {
 public:
  // `points`: where (indices into it name points below). `bake`: the env maps (albedo and V of
  // bounce points the capture point sees), the per-surface albedo (those it does not) and the
  // captured sky. `capture_position`: scene.envmap.position. `bake`, the arrays behind `points`
  // and `caster` must outlive this.
  LightTransfer(const bake::SceneBake& bake, TransferPoints points, const glm::vec3& capture_position,
                const scene::RayCaster& caster, TransferOptions options = {});

  // T of the points `pixels` under the unit sun `sun_dir` (z ≤ 0: below the horizon, T_sun = 0
  // and both skies are taken as uniform). `direct[p]` is s·max(0, n·l) of point p. Traces the
  // paths of points seen for the first time (in parallel), then evaluates all of them (in
  // parallel). out[k] is the transfer of pixels[k]; `reflected`, if given, receives the part of
  // it that the model reflects (T less the direct sun and sky).
  void Compute(const std::vector<uint32_t>& pixels, const glm::vec3& sun_dir, const float* direct, Transfer* out,
               Transfer* reflected = nullptr);

  // The clear sky's radiance per unit DHI toward each of `dirs` under the unit sun `sun_dir`;
  // 1/π (a uniform sky) without a captured sky or with the sun down.
  std::vector<glm::vec3> ClearSkyPerUnitDhi(const glm::vec3& sun_dir, const std::vector<glm::vec3>& dirs) const;

  size_t TracedPixels() const { return paths_.size(); }
  // Whether T_clear differs from T_overcast: a captured sky with the sun up.
  bool HasSkyDistribution() const { return !sky_.empty(); }

 private:
  struct Bounce {
    glm::vec3 point;    // already moved off its surface
    glm::vec3 normal;
    glm::vec3 albedo;
    float sky_visibility;
    uint32_t surface;
    uint32_t orientation;  // index into orientations_
  };
  struct Paths {
    uint32_t orientation = 0;                     // of the pixel's normal
    uint32_t low_sky_begin = 0, low_sky_end = 0;  // into low_sky_
    uint32_t blocked_begin = 0, blocked_end = 0;  // into blocked_
    uint32_t bounce_begin = 0, bounce_end = 0;    // into bounces_
  };
  struct OpenSky {
    glm::vec3 clear{0.0f};  // ∫ (L_clear/DHI) max(0, n·ω) dω over the upper hemisphere
    float uniform = 0.0f;   // ∫ (1/π) max(0, n·ω) dω over the upper hemisphere
  };
  // One pixel's rays as traced, before they are stored in the flat arrays below.
  struct TracedPixel {
    std::vector<glm::vec3> low_sky;  // rays that escape below the horizon
    std::vector<glm::vec3> blocked;  // rays above the horizon that the model stops
    std::vector<Bounce> bounces;
  };
  // The clear sky under one sun, normalised to a unit DHI; off (uniform only) at night or
  // without a captured sky.
  struct ClearSky {
    bool on = false;
    glm::vec3 inv_dhi{0.0f};
    std::vector<OpenSky> open;  // per orientation
  };
  // Traces the paths of the pixels not traced yet (Trace's steps follow).
  void Trace(const std::vector<uint32_t>& pixels);
  void TraceHemispheres(const std::vector<uint32_t>& fresh, std::vector<TracedPixel>* traced) const;
  Bounce BounceAt(const glm::vec3& y, const scene::RayHit& hit) const;
  void FillHiddenSkyVisibility(std::vector<TracedPixel>* traced);
  void StorePaths(const std::vector<uint32_t>& fresh, const std::vector<TracedPixel>& traced);
  // Compute's steps: the direct terms and the first bounce per pixel, then the further bounces.
  ClearSky ClearSkyUnder(const glm::vec3& sun_dir) const;
  void DirectAndFirstBounce(const std::vector<uint32_t>& pixels, const glm::vec3& sun_dir, const float* direct,
                            const ClearSky& sky, Transfer* out, std::vector<Transfer>* reflected) const;
  void AddFurtherBounces(const std::vector<uint32_t>& pixels, const std::vector<Transfer>& reflected, Transfer* out,
                         Transfer* reflected_out) const;
  uint32_t OrientationOf(const glm::vec3& normal);  // index into orientations_, added if new
  static constexpr float kCellSize = 0.25f;         // m, for V of hidden bounce points
  static uint64_t CellOf(const Bounce& b);          // surface, cell and side (hashed)
  // What an unoccluded surface of each orientation receives from the clear sky and a uniform one.
  std::vector<OpenSky> OpenSkyIntegrals(const glm::vec3& sun_dir, const glm::vec3& inv_dhi) const;

  const bake::SceneBake& bake_;
  TransferPoints points_;
  glm::vec3 capture_position_;
  const scene::RayCaster& caster_;
  TransferOptions options_;
  bake::SkyDistribution sky_;       // empty: uniform sky
  std::vector<glm::vec3> hemisphere_;
  std::vector<int32_t> slot_;       // per G-buffer pixel: index into paths_, −1 until traced
  std::vector<Paths> paths_;
  std::vector<glm::vec3> low_sky_, blocked_;
  std::vector<Bounce> bounces_;
  std::vector<glm::vec3> orientations_;  // distinct normals of pixels and bounce points (to ~1°)
  std::unordered_map<uint64_t, uint32_t> orientation_of_;
  std::unordered_map<uint64_t, float> hidden_cells_;  // V per cell of hidden bounce points
};

}  // namespace daylit::estimation
