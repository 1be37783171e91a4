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
// for y's orientation). y's own reflected light comes from a radiosity solve over cells of the
// model's surfaces (one per 50 cm square of a surface side, 2 m for the cells those see): each
// cell gathers once, by its own hemisphere of rays, which cells it sees and how much sky, and per
// sun its irradiance is iterated from what those reflect (the second bounce, then the third).
// Light under an overhang is local: a slab's sunlit top and its underside, or the sunlit and the
// shadowed half of a wall, are different cells (a surface's mean over both put the top's light on
// the underside, 25-50% too much on a wall under an arcade). With a uniform sky and no reflection,
// T_sun = s·max(0, n·l) and T_clear = T_overcast = V: the model of seed 001. The reflected terms
// are what a courtyard adds: shadowed ground lit by sunlit walls, warm where the walls are red.
//
// The paths (which directions reach the sky, which model points the rays hit, and their ρ_y and
// V_y) do not depend on the sun, so they are traced once per point and kept; a new sun costs one
// shadow ray per bounce point and a table lookup per blocked or low sky direction.
#pragma once

#include <cstdint>
#include <memory>
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
  int cell_rays = 64;           // rays per cell of the radiosity solve (and V_y of bounce points the
                                // capture point does not see)
  float offset_m = 2e-3f;       // ray origins are moved this far along the normal
  bool interreflection = true;  // the reflected terms
  int bounces = 4;              // the first exact at each ray's hit, the others through the cells;
                                // 3 left a tenth of the red light under an arcade out (transfer_test)
  bool close_series = true;     // the bounces past the last as a geometric series (SolveCells)
  bool sky_distribution = true; // the captured sky's (θ, γ) distribution; false: a uniform sky
  bool reaim_sky = true;        // that sky re-aimed at each sun by a physical sky (docs/sky.md);
                                // false: the captured table only read about the new sun

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

// The light of the bounces a solve left out, added to `light` (its cells after the last pass,
// `one_back` and `two_back` after the two before): each further bounce is taken to add a share r
// of the one before, r the ratio of the last two passes' increments summed over all cells (per
// part and channel; the dominant eigenvalue of the cells' transport, at most 0.9), so the tail is
// Δ·r/(1 − r) for each cell's last increment Δ.
void CloseGeometricSeries(const std::vector<Transfer>& two_back, const std::vector<Transfer>& one_back,
                          std::vector<Transfer>* light);

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

  // The captured sky (about the capture's sun; empty without one).
  const sky::SkyDistribution& CapturedSky() const { return sky_; }
  size_t TracedPixels() const { return paths_.size(); }
  size_t Cells() const { return cells_.size(); }
  // Whether T_clear differs from T_overcast: a captured sky with the sun up.
  bool HasSkyDistribution() const { return !sky_.empty(); }

 private:
  static constexpr uint32_t kNoCell = 0xffffffffu;
  struct Bounce {
    glm::vec3 point;    // already moved off its surface
    glm::vec3 normal;
    glm::vec3 albedo;
    float sky_visibility;  // < 0 until known
    uint32_t surface;
    uint32_t orientation;      // index into orientations_
    uint32_t cell;             // index into cells_ (kNoCell: none): where its own reflected light comes from
  };
  // A square of one side of a surface: the node of the radiosity solve.
  struct Cell {
    glm::vec3 origin;  // its centre dropped onto the plane of the bounce point that made it
    glm::vec3 normal;
    uint32_t level;    // 1: seen by the points, 2: seen by a level-1 cell, ...
    bool traced = false;
    bool expanded = false;  // its hits have cells
    float sky_visibility = 0.0f;
    uint32_t bounce_begin = 0, bounce_end = 0;  // into cell_bounces_
    uint32_t sky_begin = 0, sky_end = 0;        // into cell_sky_: its rays that reach the sky
  };
  struct Paths {
    uint32_t orientation = 0;                     // of the pixel's normal
    uint32_t block = 0;                           // into blocks_; the ranges below are into its lists
    uint32_t low_sky_begin = 0, low_sky_end = 0;
    uint32_t blocked_begin = 0, blocked_end = 0;
    uint32_t bounce_begin = 0, bounce_end = 0;
  };
  // The paths of up to kBlockPixels pixels traced together, in one list per kind of ray.
  struct PathBlock {
    std::vector<glm::vec3> low_sky;  // rays that escape below the horizon
    std::vector<glm::vec3> blocked;  // rays above the horizon that the model stops
    std::vector<Bounce> bounces;     // their hits
  };
  static constexpr size_t kBlockPixels = 64;
  struct OpenSky {
    glm::vec3 clear{0.0f};  // ∫ (L_clear/DHI) max(0, n·ω) dω over the upper hemisphere
    float uniform = 0.0f;   // ∫ (1/π) max(0, n·ω) dω over the upper hemisphere
  };
  // The clear sky under one sun, normalised to a unit DHI; off (uniform only) at night or
  // without a captured sky.
  struct ClearSky {
    bool on = false;
    sky::SkyDistribution table;  // the captured sky re-aimed at this sun
    glm::vec3 inv_dhi{0.0f};
    std::vector<OpenSky> open;  // per orientation
    std::vector<glm::vec3> cell_weight;  // per cell: π·L_clear/DHI over its open rays
  };
  // Traces the paths of the pixels not traced yet (Trace's steps follow).
  void Trace(const std::vector<uint32_t>& pixels);
  void TraceHemispheres(const std::vector<uint32_t>& fresh);  // appends their blocks and paths
  Bounce BounceAt(const glm::vec3& y, const scene::RayHit& hit) const;
  // Cells for the bounce points of the blocks from `first_block` on, traced with their hits'
  // cells down to the level the bounces need; then V of every hidden bounce point.
  void TraceCells(size_t first_block);
  uint32_t CellFor(const Bounce& b, uint32_t level);  // finds or adds (untraced) its cell
  void TraceNewCells(const std::vector<uint32_t>& cells);
  void FillHiddenSkyVisibility(size_t first_block);
  // Compute's steps: the direct terms and the first bounce per pixel, then the further bounces.
  ClearSky ClearSkyUnder(const glm::vec3& sun_dir) const;
  // What a bounce point reflects of its direct light per unit of each part: ρ_y times its direct
  // sun (`sun_cos`: s_y·max(0, n_y·l)), clear and overcast terms.
  Transfer DirectReflected(const Bounce& b, float sun_cos, const ClearSky& sky) const;
  // Each cell's reflected irradiance (what reaches it from the cells it sees), iterated
  // bounces − 1 times.
  std::vector<Transfer> SolveCells(const glm::vec3& sun_dir, const ClearSky& sky);
  void DirectAndReflected(const std::vector<uint32_t>& pixels, const glm::vec3& sun_dir, const float* direct,
                          const ClearSky& sky, const std::vector<Transfer>& cell_light, Transfer* out,
                          Transfer* reflected) const;
  uint32_t OrientationOf(const glm::vec3& normal);  // index into orientations_, added if new
  static uint32_t OrientationKey(const glm::vec3& normal);  // the normal quantised to ~1°
  uint32_t OrientationOfKey(uint32_t key);                   // index into orientations_, added if new
  static constexpr float kCellSize = 0.5f;          // m, level-1 cells; deeper ones 4× that
  static float CellEdge(uint32_t level);                     // m
  static uint64_t CellKey(const Bounce& b, uint32_t level);  // bake::SurfaceCellKey at that level's size
  // What an unoccluded surface of each orientation receives from the clear sky and a uniform one.
  std::vector<OpenSky> OpenSkyIntegrals(const sky::SkyDistribution& table, const glm::vec3& inv_dhi) const;

  const bake::SceneBake& bake_;
  TransferPoints points_;
  glm::vec3 capture_position_;
  const scene::RayCaster& caster_;
  TransferOptions options_;
  sky::SkyDistribution sky_;        // as captured; empty: uniform sky
  std::vector<glm::vec3> hemisphere_;
  std::vector<int32_t> slot_;       // per G-buffer pixel: index into paths_, −1 until traced
  std::vector<Paths> paths_;
  std::vector<PathBlock> blocks_;
  std::vector<glm::vec3> orientations_;  // distinct normals of pixels and bounce points (to ~1°)
  std::unordered_map<uint32_t, uint32_t> orientation_of_;  // OrientationKey → index
  std::vector<Cell> cells_;
  std::vector<Bounce> cell_bounces_;              // the hits of each cell's rays
  std::vector<uint32_t> cell_sky_;                // the others' directions, packed
  std::unordered_map<uint64_t, uint32_t> cell_of_;  // CellKey -> index into cells_
  std::vector<Transfer> own_;  // SolveCells' per hit, kept: 70 MB on courtyard-c, faulted in once, not per sun
};

}  // namespace daylit::estimation
