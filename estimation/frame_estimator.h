// The per-frame estimator of the pipeline (pipeline::LightingPipeline): for one frame and its sun,
// the sampler's strata (re-cast only when the sun has moved), the robust fit of E_sun and E_sky,
// and the temporal filter. It keeps that state between frames but no thread, file or clock of its
// own; the controller owns the loop. Headless: no GL.
#pragma once

#include <string>
#include <vector>

#include "bake/bake.h"
#include "capture/frame_source.h"
#include "estimation/light_interval.h"
#include "estimation/sampler.h"
#include "estimation/sun_colour.h"
#include "estimation/sun_sky_fit.h"
#include "estimation/temporal_filter.h"
#include "scene/raycaster.h"
#include "scene/scene.h"
#include "scene/sun_tracker.h"

namespace daylit::estimation {

struct FrameEstimatorOptions {
  SamplerOptions sampler;
  SunSkyFitOptions fit;
  TemporalFilterOptions filter;
  SunColourOptions sun_colour;
  LightIntervalOptions interval;
  // Empty when every field is in range, else the first problem, naming the field.
  std::string Check() const;
};

// What became of one frame, in estimates.csv's `status` column (FrameStatusName). The light of a
// frame whose status is not IsFitted is the filter's held estimate of the frames before it.
enum class FrameStatus {
  kConverged,      // fitted
  kSkyOnly,        // fitted, E_sky alone: no sunlit sample (sun below the horizon or all in shadow)
  kNotConverged,   // fitted, the reweighting still moving after its iterations: the last iterate
  kTooFewSamples,  // fewer than 10 usable samples: not fitted, the estimate held
  kUnreadable,     // the frame could not be read (decoded): not fitted, the estimate held
};
const char* FrameStatusName(FrameStatus status);  // "converged", "sky_only", ... as in the CSV
FrameStatus FrameStatusOfFit(SunSkyFitStatus status);
inline bool IsFitted(FrameStatus status) {
  return status != FrameStatus::kTooFewSamples && status != FrameStatus::kUnreadable;
}

// One row of estimates.csv.
struct FrameEstimate {
  int frame = 0;
  UtcTime time_utc;
  double sun_elevation_deg = 0.0;  // apparent
  double sun_azimuth_deg = 0.0;    // east of north
  SunSky light;                    // filtered E_sun, E_sky (radiance units, exposure divided out)
  double confidence = 0.0;
  // The 90% interval of the frame's fit (estimation/light_interval.h), relative, taken for the
  // filtered light; a frame without a usable fit holds the last one's.
  LightInterval interval;
  int samples = 0;
  // The fit's strata (not in the CSV): samples the sun reaches well, samples in shadow, and
  // whether the sun was up. Sun up with no sunlit sample: E_sun not observed (the estimate holds).
  int sunlit_samples = 0, shadowed_samples = 0;
  bool sun_up = false;
  FrameStatus status = FrameStatus::kTooFewSamples;

  // False until the first usable fit: the light is all zero before it.
  bool HasEstimate() const { return light.sky_rgb.x + light.sky_rgb.y + light.sky_rgb.z > 0.0; }
  // False: the frame could not be decoded (the estimate holds).
  bool Decoded() const { return status != FrameStatus::kUnreadable; }
};

// What the estimator made of one frame.
struct FrameLight {
  FrameEstimate row;
  // E_overcast / E_sky of the last usable fit, held like the light (0 before the first).
  double overcast_share = 0.0;
  SunSkyFitSummary fit;     // this frame's own fit (status kTooFewSamples for a held frame)
  bool sun_moved = false;   // the strata and transfer terms were redone for this frame
  std::vector<Sample> samples;  // what the fit saw (empty for a held frame)
};

class FrameEstimator {
 public:
  // `caster` is over the scene's model; the estimator keeps references to `bake` and `caster`.
  FrameEstimator(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                 const FrameEstimatorOptions& options);

  // `frame` has pixels of the bake's camera size (a broken caller otherwise: CHECK); `sun` is
  // the frame's (scene::SunTracker).
  FrameLight Estimate(const capture::Frame& frame, const scene::TrackedSun& sun);
  // A frame that could not be read (its index and time only): the filtered estimate holds.
  FrameLight Hold(const capture::Frame& frame, const scene::TrackedSun& sun);

 private:
  FrameEstimate Row(const capture::Frame& frame, const scene::TrackedSun& sun) const;
  double SecondsSinceFirst(const UtcTime& utc);
  // The fit of `samples` with the sun's colour carried over where the frame's own sun is weak
  // (its share of the sunlit samples' light below the fit's confident share), and the colour
  // updated from it.
  SunSkyFitSummary FitWithSunColour(const std::vector<Sample>& samples, const glm::vec3& sun_dir, const UtcTime& utc);

  const bake::SceneBake& bake_;
  FrameEstimatorOptions options_;
  Sampler sampler_;
  TemporalFilter filter_;
  capture::Linearizer linearizer_;
  std::optional<UtcTime> first_utc_;
  double overcast_share_ = 0.0;
  LightInterval interval_;  // the last usable fit's
  // The last sky shape's spread and strata sensitivity made (LightIntervalOptions::sky_shape_every_s),
  // and when, in seconds since the first frame.
  SkyShapeSpread sky_shape_;
  StrataSensitivity sensitivity_;
  std::optional<double> refits_at_s_;
  SunColourMemory sun_colour_;
};

// The stable CSV: frame,time_utc,sun_elevation_deg,sun_azimuth_deg,sun_r,sun_g,sun_b,sky_r,sky_g,
// sky_b,confidence,samples, the interval's bounds (IntervalCsvHeader), status (FrameStatusName).
// Columns are only ever added at the end.
std::string EstimatesCsv(const std::vector<FrameEstimate>& frames);

}  // namespace daylit::estimation
