// Scene self-calibration from the footage: the model's north and the camera's clock, from where
// the frames' shadows fall (docs/calibrate.md). The sun's direction comes from the ephemeris, so a
// north read off a map 1° wrong or a clock minutes off puts the model's shadows beside the
// frame's; this measures the correction that puts them back.
//
// Two steps. ObserveShadows reads the recording once, estimating the light as `daylit estimate`
// does, and keeps for each burst with sun how sunlit each pixel of the model looked (σ, the
// median over the burst's clearest frames: walkers and noise fall out). FitNorthAndClock then
// searches the north and clock offsets whose ray-cast shadows agree best with σ over all bursts:
// a coarse grid, then halving steps, then a quadratic through the last grid. Headless: no GL.
#pragma once

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "bake/bake.h"
#include "capture/frame_source.h"
#include "capture/response.h"
#include "estimation/frame_estimator.h"
#include "base/utc_time.h"
#include "scene/raycaster.h"
#include "scene/scene.h"

namespace daylit::calibrate {

struct ObserveOptions {
  int frames_per_burst = 9;         // the clearest frames of each burst whose median gives σ
  double min_sun_to_sky = 1.0;      // a frame counts as clear when Σ E_sun / Σ E_sky is at least this
  double min_cos = 0.15;            // pixels whose normal is nearer the sun's grazing angle are left out
  int max_frames = 0;               // 0: the whole recording
  // Pixels this close to an edge between two surfaces (or the sky) in the bake's G-buffer are left
  // out: where the pose is off, they show the other surface (pose refinement sets ~a degree's worth).
  int silhouette_margin_px = 0;
  // > 0: a burst longer than this (seconds) is cut into stretches this long, each its own burst
  // with its own sun. A live camera's stream is one burst, and over ten minutes the sun moves
  // 2.5°: a median over frames that far apart would blur the shadows it measures.
  double max_burst_s = 0.0;
};

// One burst's view of the shadows.
struct BurstShadows {
  int burst = 0;                  // counting the recording's bursts (frames < 2 s apart) from 0
  UtcTime time;                   // the median time of its frames used (the scene's clock, offset included)
  int first_frame = 0, last_frame = 0;
  int frames = 0;                 // clear frames in σ
  std::vector<uint32_t> pixels;   // camera pixels (row-major G-buffer index)
  std::vector<float> sunlit;      // σ per pixel: 0 shadow, 1 sunlit (clamped)
};

struct ShadowObservations {
  std::vector<BurstShadows> bursts;  // those with sun and clear frames
  int frames_read = 0;
  int bursts_seen = 0;               // all bursts of the recording, with sun or not
};

// What ObserveShadows does, a frame at a time, for a loop that already estimates the frames
// (`daylit estimate`'s quick check): Add each frame in order with its estimate, then Finish.
class ShadowObserver {
 public:
  ShadowObserver(const scene::Scene& scene, const bake::SceneBake& bake, const ObserveOptions& options = {});
  // `frame`: readable, of the bake's camera size; `row`: its estimate.
  void Add(const capture::Frame& frame, const estimation::FrameEstimate& row);
  // A frame that could not be read: it still ends a burst.
  void AddUnreadable(const capture::Frame& frame);
  ShadowObservations Finish();
  // Bursts closed so far that showed the sun on the model (they will be in Finish's bursts).
  size_t sunlit_bursts() const { return out_.bursts.size(); }

 private:
  struct ClearFrame {
    double sun_to_sky = 0.0;
    UtcTime utc;
    int index = 0;
    std::vector<float> sigma;
  };
  void Step(const capture::Frame& frame);
  void CloseBurst();

  const scene::Scene& scene_;
  const bake::SceneBake& bake_;
  ObserveOptions options_;
  capture::Linearizer linearizer_;
  std::vector<uint32_t> diffuse_;  // the G-buffer's diffuse pixels
  std::vector<ClearFrame> kept_;   // the burst's clearest frames so far, at most frames_per_burst
  int first_ = 0, last_ = 0;
  std::optional<UtcTime> previous_;
  UtcTime start_;                  // the burst's (or stretch's) first frame
  ShadowObservations out_;
};

// Reads the scene's frames (a recording) with the estimator. Throws InputError naming the scene
// when the recording has no frames.
ShadowObservations ObserveShadows(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                                  const ObserveOptions& options = {});

struct FitOptions {
  bool north = true, clock = true;
  bool pose = false;                 // also a small camera rotation (within ±pose_range_deg per axis)
  double pose_range_deg = 2.0;
  double north_range_deg = 10.0;     // searched either side of the scene's north
  double clock_range_s = 1800.0;     // and of its clock
  double north_step_deg = 1.0;       // of the coarse grid
  double clock_step_s = 120.0;
  double north_tolerance_deg = 0.02; // the halving stops below these steps
  double clock_tolerance_s = 5.0;
  int coarse_stride = 8;             // the coarse grid sees every n-th pixel of each burst
  // Bursts spanning less than this (seconds) are one time of day: north and clock trade along the
  // sun's path, so only north is fitted and the clock held (FitResult::note says so).
  double min_span_for_both_s = 1800.0;
};

// A small rotation of the camera about its own centre: an axis-angle vector in camera coordinates
// (x right, y down, z forward), degrees. world_to_camera becomes Rδ·R, its translation Rδ·t.
scene::RigidPose RotatedPose(const scene::RigidPose& cam_from_world, const glm::dvec3& rotation_deg);

struct FitResult {
  bool north_fitted = false, clock_fitted = false;
  double north_offset_deg = 0.0;     // add to scene.json's north_azimuth_deg
  double clock_offset_s = 0.0;       // add to frames.clock_offset_s
  // One standard deviation: the jackknife over bursts with three or more, else the width of the
  // score's minimum (where it rises by the score's own noise).
  double north_sigma_deg = 0.0, clock_sigma_s = 0.0;
  int bursts = 0, frames = 0;
  size_t pixels = 0;                 // pixels compared, all bursts
  size_t edge_pixels = 0;            // of which change sides within the search range: the edges
  double disagree_before = 0.0;      // share of the edge pixels on the wrong side at the scene's values
  double disagree_after = 0.0;       // and at the fitted ones
  // Cohen's kappa of the model's sunlit/shadowed sides against the frames' at the fitted values,
  // over the compared pixels (every coarse_stride-th), and the highest kappa with the sun turned
  // 20° or 40° either way from the fitted (ShadowCheck::SunSkill).
  double kappa_after = 0.0;
  double kappa_away = -1.0;
  bool at_range_edge = false;        // the best lies on the search range's edge: the truth may be beyond it
  // With pose refinement (FitOptions::pose): the camera's rotation (RotatedPose) that puts the
  // model's shadows and edges on the frame's, and its jackknife σ per axis.
  bool pose_fitted = false;
  glm::dvec3 rotation_deg{0.0};
  glm::dvec3 rotation_sigma_deg{0.0};
  std::string note;                  // what the footage could not separate, if anything
};

// The north and clock offsets whose shadows agree best with `observed`. Throws InputError when no
// burst has sunlit pixels (overcast, or the sun on none of the model's diffuse surfaces).
FitResult FitNorthAndClock(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                           const ShadowObservations& observed, const FitOptions& options = {});

// FitNorthAndClock, then again without the pixels whose albedo the bake took from the wrong side
// of a capture-time shadow edge, were north off by what the first fit found (the bake derives
// albedo with the capture's sun, so a north 3° off darkens or brightens a band along the env map's
// shadow edges, and that band pulls the shadows toward the old north: by 0.2° at 3° on
// courtyard-a).
FitResult Calibrate(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                    const ShadowObservations& observed, const FitOptions& options = {});

// 1 for the camera pixels whose albedo came from a capture-time sun on the other side of a shadow
// edge for some north between the scene's and the scene's + `north_offset_deg` (dilated by 2 px).
std::vector<uint8_t> CaptureEdgeMask(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                                     double north_offset_deg);

// When the env map's own sun (its brightest texel, bake::CaptureSun) lies further from the
// ephemeris sun at capture than any north within ±`north_range_deg` could move it (plus 1°), a
// message saying so: the scene's north (or envmap.time_utc) is off beyond the search. Empty
// otherwise, or without an env map with the sun above the horizon.
std::string EnvMapSunBeyondRange(const scene::Scene& scene, const bake::SceneBake& bake, double north_range_deg);

// The unit direction toward the sun at `utc` + `clock_offset_s`, for the scene with its north moved
// by `north_offset_deg`.
glm::vec3 SunWith(const scene::Scene& scene, const UtcTime& utc, double north_offset_deg, double clock_offset_s);

inline constexpr double kShadowCheckNorthRangeDeg = 3.0;  // CheckShadows searches north this far either side
// At or below this ShadowCheck::SunSkill the model is taken not to be the footage's: 0.4 is the top
// of "fair" agreement on Landis & Koch's scale for kappa (Biometrics 33:159-174, 1977). Measured:
// 0.55-0.98 on the bundled recordings, 0.26 or less with another camera's pose or another scene's
// model (docs/calibrate.md).
inline constexpr double kShadowCheckMinSunSkill = 0.4;

// The share of edge pixels (those whose side changes within ±`north_range_deg`) that the model's
// shadows put on the wrong side of the frames' ones, at the scene's own values: the quick check
// of `info` and `estimate`, and the north offset that would fit best (north only, clock held).
struct ShadowCheck {
  double disagree = 0.0;
  double north_offset_deg = 0.0;
  size_t edge_pixels = 0;
  double disagree_best = 0.0;   // the share on the wrong side at the best north
  // Cohen's kappa of the sides at the best north (the agreement beyond sides drawn at random with
  // the same shares: 0.74-0.99 on the bundled recordings), and with the sun turned 20-40° away:
  // what the scene's layout alone gives (ground sunlit in both, the walls' shade in both), with no
  // sun in it. A model that is not the footage's still gets 0.3-0.8 from the layout.
  double kappa = 0.0;
  double kappa_away = 0.0;
  // What the frames' own sun adds to the agreement a sun turned away leaves: a kappa with the
  // turned sun as its chance, (kappa − k0) / (1 − k0), k0 = max(kappa_away, 0). A turned sun that
  // agrees less than chance (kappa_away < 0) is no lower baseline than chance itself: taken as
  // it was, it raised the skill of a kappa of 0.3 to 0.42 at kappa_away = −0.2.
  double SunSkill() const {
    const double chance = std::max(kappa_away, 0.0);
    return chance >= 1.0 ? 0.0 : (kappa - chance) / (1.0 - chance);
  }
  // The model, pose, north and place are the footage's, as far as its shadows tell.
  bool ModelMatchesFootage() const { return SunSkill() > kShadowCheckMinSunSkill; }
};
std::optional<ShadowCheck> CheckShadows(const scene::Scene& scene, const bake::SceneBake& bake,
                                        const scene::RayCaster& caster, const ShadowObservations& observed);

}  // namespace daylit::calibrate
