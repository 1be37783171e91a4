// Estimation over a whole recording (`daylit estimate`): for each frame, the sun from the
// ephemeris, the sampler's strata (re-cast only when the sun has moved), the robust fit, the
// temporal filter. Headless: no GL. The controller owns the loop; the estimators stay stateless.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "estimation/sampler.h"
#include "estimation/sun_sky_fit.h"
#include "estimation/temporal_filter.h"
#include "scene/scene.h"

namespace daylit::estimation {

struct FrameEstimate;

// What a replay does with each frame after its estimate (render it, say), on the estimating
// thread. `frame` is empty (no pixels) when it could not be read; `sun_dir` is unit, in scene
// coordinates; `overcast_share` is the fit's E_overcast / E_sky (0 when the frame had no usable fit).
using FrameHook = std::function<void(const FrameEstimate& row, const capture::Frame& frame, const glm::vec3& sun_dir,
                                     double overcast_share)>;

struct EstimateOptions {
  SamplerOptions sampler;
  SunSkyFitOptions fit;
  TemporalFilterOptions filter;
  std::optional<int> max_frames;              // stop after this many (a live camera runs until stopped)
  const std::atomic<bool>* stop = nullptr;    // set (e.g. by Ctrl-C) to end the run after the frame at hand
  FrameHook on_frame;                          // optional, called once per frame in order
  std::string progress_label = "estimate";
};

struct FrameEstimate {
  int frame = 0;
  UtcTime time_utc;
  double sun_elevation_deg = 0.0;  // apparent
  double sun_azimuth_deg = 0.0;    // east of north
  SunSky light;                    // filtered E_sun, E_sky (radiance units, exposure divided out)
  double confidence = 0.0;
  int samples = 0;
  bool decoded = true;             // false: the frame could not be decoded (the estimate holds)

  // False until the first usable fit: the light is all zero before it.
  bool HasEstimate() const { return light.sky_rgb.x + light.sky_rgb.y + light.sky_rgb.z > 0.0; }
};

struct EstimateRun {
  std::vector<FrameEstimate> frames;
  int undecodable = 0;
  double seconds = 0.0;               // wall time of the loop, decoding included (on its own thread)
  double median_frame_ms = 0.0;       // everything after decoding, median over frames without a sun move
  std::vector<double> sun_moves_ms;   // the frames with one: shadow rays, strata, transfer terms
};

// Runs over the frames of the scene's FrameSource: every frame of a recording (video or images),
// or a live camera's until `max_frames` or `stop`. A frame that cannot be read holds the
// estimate; while a camera is unplugged nothing comes, and the estimate holds too.
EstimateRun EstimateRecording(const scene::Scene& scene, const bake::SceneBake& bake, const EstimateOptions& options);
// The same from a source the caller opened (a camera checked before the bake, say).
EstimateRun EstimateRecording(const scene::Scene& scene, const bake::SceneBake& bake, const EstimateOptions& options,
                              std::unique_ptr<capture::FrameSource> source);

// The unfiltered fit of one frame (its position in frames.csv), as the estimator makes it:
// decodes the recording up to it. Throws InputError if the position is out of range or the frame
// cannot be decoded. `caster`: the scene's model.
struct FrameFit {
  FrameEstimate row;       // light and confidence: the fit's own
  SunSkyFitSummary fit;
  glm::vec3 sun_dir{0.0f};  // unit, scene coordinates
  capture::Frame frame;     // the frame it was fitted to
};
FrameFit FitFrame(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster, size_t position,
                  const EstimateOptions& options);
// The same for a frame already read.
FrameFit FitDecodedFrame(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                         capture::Frame frame, const EstimateOptions& options);

// The stable CSV: frame,time_utc,sun_elevation_deg,sun_azimuth_deg,sun_r,sun_g,sun_b,sky_r,sky_g,
// sky_b,confidence,samples.
std::string EstimatesCsv(const std::vector<FrameEstimate>& frames);

// Against groundtruth.csv: median over frames of |estimate/truth − 1| per channel, for E_sun
// (frames where the true E_sun is > 0), E_sky, and the sun/sky ratio.
struct TruthComparison {
  glm::dvec3 sun_error{0.0}, sky_error{0.0}, ratio_error{0.0};
  int frames = 0;
  std::vector<SunSky> truth;  // per frame, aligned with the estimates
};
TruthComparison CompareWithTruth(const std::vector<FrameEstimate>& frames, const std::filesystem::path& groundtruth_csv);

// Estimate vs truth over time, per channel: a PNG with a sun panel and a sky panel.
void PlotEstimates(const std::vector<FrameEstimate>& frames, const TruthComparison* truth,
                   const std::string& title, const std::filesystem::path& png);

}  // namespace daylit::estimation
