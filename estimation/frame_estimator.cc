#include "estimation/frame_estimator.h"

#include "base/options_check.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <glm/gtx/component_wise.hpp>

#include "base/check.h"
#include "base/error.h"
#include "sky/atmosphere.h"

namespace daylit::estimation {
namespace {

glm::vec3 CapturePoint(const scene::Scene& scene) {
  return scene.envmap ? glm::vec3(scene.envmap->position) : glm::vec3(0.0f);
}

// Kasten and Young's relative air mass toward the (apparent) sun direction, sky/atmosphere.h.
double AirMass(const glm::vec3& sun_dir) {
  return sky::RelativeAirMass(glm::degrees(std::asin(std::clamp(static_cast<double>(sun_dir.z), -1.0, 1.0))));
}

}  // namespace

FrameEstimator::FrameEstimator(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                               const FrameEstimatorOptions& options)
    : bake_(bake),
      options_(options),
      sampler_(bake, CapturePoint(scene), caster, options.sampler),
      filter_(options.filter),
      linearizer_(scene.response) {
  DAYLIT_CHECK(options.Check().empty(), "{}", options.Check());
  // The capture's sun above the atmosphere: its DNI over the transmittance at its elevation.
  const sky::SkyDistribution& sky = sampler_.transfer().CapturedSky();
  const glm::dvec3 dni(bake.capture_sun.dni_rgb);
  if (bake.capture_sun.above_horizon && glm::compMin(dni) > 0.0 && !sky.empty()) {
    const glm::dvec3 above = dni / glm::max(sky.SunUnder(sky.sun(), glm::dvec3(1.0)), glm::dvec3(1e-9));
    sun_colour_ = SunColourMemory(options.sun_colour, above, AirMass(sky.sun()));
  } else {
    sun_colour_ = SunColourMemory(options.sun_colour);
  }
}

SunSkyFitSummary FrameEstimator::FitWithSunColour(const std::vector<Sample>& samples, const glm::vec3& sun_dir,
                                                  const UtcTime& utc) {
  const sky::SkyDistribution& sky = sampler_.transfer().CapturedSky();
  if (!options_.sun_colour.on || sky.empty() || sun_dir.z <= 0.0f) return FitSunSky(options_.fit, samples);
  const SunColourMemory::Colour carried = sun_colour_.At(utc, AirMass(sun_dir));
  // The colour here: above the atmosphere times its transmittance toward this sun (relative to the
  // capture's, which cancels in a colour). A weak sun takes it (MixWithCarriedColour).
  const glm::dvec3 transmittance = sky.SunUnder(sun_dir, glm::dvec3(1.0));
  SunSkyFitSummary fit = FitSunSkyAsCarried(options_.fit, samples, carried.above * transmittance, carried.weight);
  if (!fit.IsUsable() || fit.sunlit_samples == 0) return fit;
  // The frame's own sun (unmixed) measures the colour, as well as its weight says.
  if (glm::compMin(fit.own.sun_rgb) > 0.0) {
    sun_colour_.Measure(utc, fit.own.sun_rgb / glm::max(transmittance, glm::dvec3(1e-9)), SunColourWeight(fit));
  }
  return fit;
}

FrameEstimate FrameEstimator::Row(const capture::Frame& frame, const scene::TrackedSun& sun) const {
  FrameEstimate row;
  row.frame = frame.index;
  row.time_utc = frame.utc;
  row.sun_elevation_deg = sun.position.ApparentElevationDeg();
  row.sun_azimuth_deg = sun.position.azimuth_deg;
  return row;
}

double FrameEstimator::SecondsSinceFirst(const UtcTime& utc) {
  if (!first_utc_) first_utc_ = utc;
  return utc.SecondsSince(*first_utc_);
}

FrameLight FrameEstimator::Estimate(const capture::Frame& frame, const scene::TrackedSun& sun) {
  DAYLIT_CHECK(frame.rgb.cols == bake_.camera.width && frame.rgb.rows == bake_.camera.height,
               "frame {} is {}x{}, the camera {}x{}", frame.index, frame.rgb.cols, frame.rgb.rows, bake_.camera.width,
               bake_.camera.height);
  FrameLight out;
  out.row = Row(frame, sun);
  const double t_s = SecondsSinceFirst(frame.utc);
  out.sun_moved = sampler_.SetSun(sun.dir_in_scene);
  out.samples = sampler_.Draw(frame.rgb, frame.exposure, frame.linear ? nullptr : &linearizer_);
  out.fit = FitWithSunColour(out.samples, sun.dir_in_scene, frame.utc);
  const FilteredLight filtered =
      filter_.Update(t_s, out.fit.IsUsable() ? std::optional<SunSky>(out.fit.light) : std::nullopt, out.fit.confidence);
  if (out.fit.IsUsable()) {
    overcast_share_ = out.fit.overcast_share;
    if (!refits_at_s_ || t_s < *refits_at_s_ || t_s - *refits_at_s_ >= options_.interval.sky_shape_every_s) {
      if (options_.interval.sky_shape) {
        sky_shape_ = SkyShapeSpreadOfFit(options_.interval, options_.fit, out.samples, out.fit, bake_.camera.surface);
      }
      if (options_.interval.strata_sensitivity) {
        sensitivity_ = StrataSensitivityOfFit(options_.interval, options_.fit, out.samples, out.fit);
      }
      refits_at_s_ = t_s;
    }
    interval_ = IntervalOfFit(options_.interval, options_.fit, out.samples, out.fit, bake_.camera.surface, sky_shape_,
                              sensitivity_);
  }
  out.overcast_share = overcast_share_;
  out.row.interval = interval_;
  out.row.light = filtered.light;
  out.row.confidence = filtered.confidence;
  out.row.samples = static_cast<int>(out.samples.size());
  out.row.sunlit_samples = out.fit.sunlit_samples;
  out.row.shadowed_samples = out.fit.shadowed_samples;
  out.row.sun_up = out.fit.sun_up;
  out.row.status = FrameStatusOfFit(out.fit.status);
  return out;
}

FrameLight FrameEstimator::Hold(const capture::Frame& frame, const scene::TrackedSun& sun) {
  FrameLight out;
  out.row = Row(frame, sun);
  out.row.status = FrameStatus::kUnreadable;
  const FilteredLight held = filter_.Update(SecondsSinceFirst(frame.utc), std::nullopt, 0.0);
  out.row.light = held.light;
  out.row.confidence = held.confidence;
  out.row.interval = interval_;
  out.overcast_share = overcast_share_;
  out.fit.message = "the frame could not be read";
  return out;
}

const char* FrameStatusName(FrameStatus status) {
  switch (status) {
    case FrameStatus::kConverged: return "converged";
    case FrameStatus::kSkyOnly: return "sky_only";
    case FrameStatus::kNotConverged: return "not_converged";
    case FrameStatus::kTooFewSamples: return "too_few_samples";
    case FrameStatus::kUnreadable: return "unreadable";
  }
  return "unknown";
}

FrameStatus FrameStatusOfFit(SunSkyFitStatus status) {
  switch (status) {
    case SunSkyFitStatus::kConverged: return FrameStatus::kConverged;
    case SunSkyFitStatus::kSkyOnly: return FrameStatus::kSkyOnly;
    case SunSkyFitStatus::kNoConvergence: return FrameStatus::kNotConverged;
    case SunSkyFitStatus::kTooFewSamples: return FrameStatus::kTooFewSamples;
  }
  return FrameStatus::kTooFewSamples;
}

std::string EstimatesCsv(const std::vector<FrameEstimate>& frames) {
  fmt::memory_buffer out;
  fmt::format_to(std::back_inserter(out), "frame,time_utc,sun_elevation_deg,sun_azimuth_deg,sun_r,sun_g,sun_b,sky_r,"
                                          "sky_g,sky_b,confidence,samples,{},status\n",
                 IntervalCsvHeader());
  for (const FrameEstimate& f : frames) {
    fmt::format_to(std::back_inserter(out), "{},{},{:.4f},{:.4f},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.4f},{}",
                   f.frame, FormatUtcTime(f.time_utc), f.sun_elevation_deg, f.sun_azimuth_deg, f.light.sun_rgb.x,
                   f.light.sun_rgb.y, f.light.sun_rgb.z, f.light.sky_rgb.x, f.light.sky_rgb.y, f.light.sky_rgb.z,
                   f.confidence, f.samples);
    fmt::format_to(std::back_inserter(out), "{},{}\n", IntervalCsvFields(BoundsOf(f.light, f.interval)),
                   FrameStatusName(f.status));
  }
  return fmt::to_string(out);
}

std::string FrameEstimatorOptions::Check() const {
  return FirstProblem({Nested("sampler", sampler.Check()), Nested("fit", fit.Check()), Nested("filter", filter.Check()),
                       Nested("sun_colour", sun_colour.Check()), Nested("interval", interval.Check())});
}

}  // namespace daylit::estimation
