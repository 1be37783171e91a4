#include "pipeline/lighting_pipeline.h"

#include <algorithm>
#include <ctime>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "base/check.h"
#include "base/options_check.h"
#include "base/log.h"
#include "base/progress.h"
#include "base/statistics.h"
#include "base/utc_time.h"
#include "capture/read_ahead.h"

namespace daylit::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

double MillisecondsSince(Clock::time_point t0) { return 1e3 * std::chrono::duration<double>(Clock::now() - t0).count(); }

// The wall clock (a camera's frames carry its time), seconds since the Unix epoch.
double UnixSecondsNow() {
  timespec now{};
  ::clock_gettime(CLOCK_REALTIME, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

}  // namespace

std::string LightingPipelineOptions::Check() const {
  if (max_frames && *max_frames < 1) return fmt::format("max_frames: {} is not a number of frames (≥ 1)", *max_frames);
  return FirstProblem({Nested("estimator", estimator.Check()), Nested("sun", sun.Check())});
}

LightingPipeline::LightingPipeline(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                                   const LightingPipelineOptions& options)
    : scene_(scene), bake_(bake), caster_(caster), options_(options) {
  const std::string why = options.Check();
  DAYLIT_CHECK(why.empty(), "{}", why);
}

bool LightingPipeline::StopRequested() const {
  if (options_.stop != nullptr && options_.stop->load()) return true;
  return std::any_of(sinks_.begin(), sinks_.end(), [](const FrameSink* sink) { return sink->StopRequested(); });
}

PipelineRun LightingPipeline::Run(std::unique_ptr<capture::FrameSource> source) {
  DAYLIT_CHECK(video_ == nullptr || stage_ != nullptr, "a video needs a stage that makes its images");
  // The set-up comes first: a camera streams from the read-ahead's first frame on. For a camera,
  // that includes the stage's first composite (its sun-dependent parts for the sun of now, which
  // the first frames will have, and its GL programs): a second or more with software GL. The
  // estimator's first frame is left as it is (a few hundred ms, within the read-ahead's queue):
  // its estimates are a recording's, whatever the sun before it.
  scene::SunTracker sun_tracker(scene_, options_.sun);
  estimation::FrameEstimator estimator(scene_, bake_, caster_, options_.estimator);
  const bool live = source->live();
  if (live && stage_ != nullptr) stage_->Prepare(sun_tracker.Update(UtcFromUnixSeconds(UnixSecondsNow())));
  // A camera's read-ahead never keeps it waiting (the driver would drop frames); its queue holds
  // what arrives during a slow frame (a sun move: a few hundred ms) so that every frame is still
  // estimated: up to kLiveQueueBytes of frames, the most lag.
  const size_t frame_bytes = static_cast<size_t>(bake_.camera.width) * static_cast<size_t>(bake_.camera.height) * 3 * sizeof(float);
  const int live_depth = static_cast<int>(std::clamp<size_t>(kLiveQueueBytes / std::max<size_t>(frame_bytes, 1), 4, 64));
  std::unique_ptr<capture::FrameSource> frames = capture::ReadAhead(std::move(source), live ? live_depth : 4);
  PipelineRun run;
  // A recording's length is known; a live camera's is max_frames, else until stopped.
  std::optional<size_t> total;
  if (scene_.frame_times) total = scene_.frame_times->frames.size();
  if (options_.max_frames) total = std::min(total.value_or(SIZE_MAX), static_cast<size_t>(*options_.max_frames));
  std::optional<Progress> progress;
  if (total) progress.emplace(options_.progress_label, *total);
  std::vector<double> estimate_ms, stage_ms;
  const Clock::time_point start = Clock::now();
  for (size_t i = 0; !total || i < *total; ++i) {
    if (StopRequested()) break;
    capture::Frame frame;
    const capture::FrameStatus status = frames->Next(&frame);
    if (status == capture::FrameStatus::kEnd) break;
    const scene::TrackedSun& sun = sun_tracker.Update(frame.utc);
    bool readable = status == capture::FrameStatus::kFrame;
    if (readable && (frame.rgb.cols != bake_.camera.width || frame.rgb.rows != bake_.camera.height)) {
      Log().warn("{}: frame {} is {}x{}, not the camera's {}x{}; skipped", scene_.file.string(), frame.index,
                 frame.rgb.cols, frame.rgb.rows, bake_.camera.width, bake_.camera.height);
      readable = false;
    }
    const Clock::time_point began = Clock::now();
    const estimation::FrameLight light = readable ? estimator.Estimate(frame, sun) : estimator.Hold(frame, sun);
    if (readable) (light.sun_moved ? run.sun_moves_ms : estimate_ms).push_back(MillisecondsSince(began));
    if (readable && live) run.latency_ms.push_back(1e3 * (UnixSecondsNow() - UnixSeconds(frame.utc)));
    if (!readable) {
      ++run.undecodable;
      frame.rgb.release();
    }
    run.frames.push_back(light.row);
    if (!options_.first_output_frame || frame.index >= *options_.first_output_frame) {
      // Behind a camera (a newer frame already waits), the estimate is all this frame gets: its
      // image is the last one again, so that the camera is never outrun.
      const bool behind = live && readable && stage_ != nullptr && run.composited > 0 && frames->waiting() > 0;
      if (behind) ++run.composites_skipped;
      const double ms = Deliver(frame, light, sun, !behind);
      if (ms >= 0.0) {
        stage_ms.push_back(ms);
        ++run.composited;
      }
    }
    const double fps = static_cast<double>(i + 1) / std::max(std::chrono::duration<double>(Clock::now() - start).count(), 1e-9);
    if (progress) {
      progress->Advance();
      if (readable) progress->SetSuffix(fmt::format("{:.0f} fps", fps));
    } else if ((i + 1) % 100 == 0) {
      const estimation::SunSky& e = light.row.light;
      Log().info("{} frames, {:.0f} fps; E_sun ({:.3g}, {:.3g}, {:.3g}), E_sky ({:.3g}, {:.3g}, {:.3g})", i + 1, fps,
                 e.sun_rgb.x, e.sun_rgb.y, e.sun_rgb.z, e.sky_rgb.x, e.sky_rgb.y, e.sky_rgb.z);
    }
  }
  run.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  run.dropped = frames->stats().dropped, run.skipped = frames->stats().skipped;
  run.median_estimate_ms = MedianInPlace(estimate_ms, static_cast<double>(NAN));
  run.median_stage_ms = MedianInPlace(stage_ms, 0.0);
  return run;
}

double LightingPipeline::Deliver(const capture::Frame& frame, const estimation::FrameLight& light,
                                 const scene::TrackedSun& sun, bool image) {
  const bool readable = !frame.rgb.empty();
  double ms = -1.0;
  PipelineFrame out{frame, light, sun};
  if (stage_ != nullptr && readable) {
    if (image) {
      if (video_ != nullptr) image_ = video_->TakeBuffer();
      const Clock::time_point t0 = Clock::now();
      out.image_light = stage_->Process(frame, light, sun, &image_);
      ms = MillisecondsSince(t0);
      out.image = &image_;
    } else {
      stage_->Skip(light);
    }
  }
  for (FrameSink* sink : sinks_) sink->Consume(out);
  if (video_ != nullptr) {
    // A frame that could not be read, or had no image made, shows the last one again, so the
    // video keeps its timing.
    video_->Write(out.image != nullptr ? std::move(image_) : std::vector<float>{}, frame.exposure);
    image_.clear();
  }
  return ms;
}

}  // namespace daylit::pipeline
