// The pipeline controller (design.md's online pipeline): it owns the frame loop of daylit
// estimate, replay, live and relight. For each frame of a FrameSource (a recording or a live
// camera, read ahead on its own thread): the sun (one scene::SunTracker, one sun-moved rule), the
// per-frame estimate (estimation::FrameEstimator, no thread of its own), an optional stage that
// makes the frame's image (the composite of FrameRenderer, or the relit frame), then the sinks
// (window, truth comparison, ...) and the video. Commands only parse, build these and call Run().
#pragma once

#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "capture/async_video_writer.h"
#include "capture/frame_source.h"
#include "estimation/frame_estimator.h"
#include "scene/raycaster.h"
#include "scene/scene.h"
#include "scene/sun_tracker.h"

namespace daylit::pipeline {

// Which light a stage's image shows.
enum class ImageLight {
  kFrameLight,  // the frame's own (the composite): comparable with the recording's truth
  kOtherLight,  // another sun or light (relit): not comparable
};

// One frame as the sinks see it, valid during the call only.
struct PipelineFrame {
  const capture::Frame& frame;                  // rgb empty: the frame could not be read
  const estimation::FrameLight& light;          // its estimate (row: the CSV row)
  const scene::TrackedSun& sun;
  const std::vector<float>* image = nullptr;    // the stage's image (linear radiance, camera size); null
                                                // without a stage or pixels
  ImageLight image_light = ImageLight::kFrameLight;
};

// Makes each readable frame's image after its estimate (the only work that may need GL).
class FrameStage {
 public:
  virtual ~FrameStage() = default;
  // `image` is resized by the stage to width × height × 3; it may hold the previous frame's.
  virtual ImageLight Process(const capture::Frame& frame, const estimation::FrameLight& light,
                             const scene::TrackedSun& sun, std::vector<float>* image) = 0;
  // Before a live camera's first frame: the one-time and sun-dependent work for `sun`, so that
  // the first frames do not wait for it. Optional.
  virtual void Prepare(const scene::TrackedSun& /*sun*/) {}
  // A readable frame whose image is left out (a live camera's while the pipeline is behind):
  // whatever cheap state the sinks read should follow its light. Optional.
  virtual void Skip(const estimation::FrameLight& /*light*/) {}
};

struct PipelineRun;

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  // Every frame in order, readable or not, on the pipeline's thread.
  virtual void Consume(const PipelineFrame& frame) = 0;
  // True once the sink wants the run to end (a closed window).
  virtual bool StopRequested() const { return false; }
};

struct LightingPipelineOptions {
  estimation::FrameEstimatorOptions estimator;
  scene::SunTrackerOptions sun;
  std::optional<int> max_frames;         // ≥ 1: stop after this many (a live camera runs until stopped)
  // Frames numbered below this are estimated (the filter needs them) but not handed to the stage,
  // the sinks or the video (daylit relight --frames a:b).
  std::optional<int> first_output_frame;
  const std::atomic<bool>* stop = nullptr;  // set (Ctrl-C) to end the run after the frame at hand
  std::string progress_label = "estimate";

  // Empty when valid, else the first problem, naming the field.
  std::string Check() const;
};

struct PipelineRun {
  std::vector<estimation::FrameEstimate> frames;  // every frame read, in order
  int undecodable = 0;
  int dropped = 0;  // a live camera: frames its driver's sequence numbers show were never delivered
  int skipped = 0;  // a live camera: frames given up unread because newer ones were waiting
  // With a stage: frames whose image was made, and a live camera's frames that had only their
  // estimate because a newer one was already waiting (their image is the last one again).
  int composited = 0;
  int composites_skipped = 0;
  // A live camera: each frame's age when its estimate was done (wall clock minus its capture
  // instant), ms: how far the pipeline runs behind the camera.
  std::vector<double> latency_ms;
  double seconds = 0.0;              // wall time of the loop, decoding (on its own thread) included
  double median_estimate_ms = 0.0;   // the estimate after decoding, median over frames without a sun move
  std::vector<double> sun_moves_ms;  // the estimate of frames with one: shadow rays, strata, transfer terms
  double median_stage_ms = 0.0;      // the stage (relight, render), median over frames that had it
};

class LightingPipeline {
 public:
  // `options` must Check() empty (the commands validate them first: CHECK). `caster` is over
  // the scene's model, shared with the stage; all three are kept by reference.
  LightingPipeline(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                   const LightingPipelineOptions& options);

  // Optional; not owned. Without a stage the pipeline only estimates (daylit estimate).
  void SetStage(FrameStage* stage) { stage_ = stage; }
  void AddSink(FrameSink* sink) { sinks_.push_back(sink); }
  // Optional; not owned: each output frame's image is written to it (a repeat of the last frame
  // for one that could not be read). Needs a stage.
  void SetVideo(capture::AsyncVideoWriter* video) { video_ = video; }

  // Runs over `source` until its end, `max_frames`, `stop` or a sink's stop. A frame that cannot
  // be read holds the estimate; while a camera is unplugged nothing comes and the estimate holds.
  // A live camera is never kept waiting: every frame it delivers is estimated, and while a newer
  // one waits the stage is left out (composites_skipped); only behind by more than the
  // read-ahead's queue (kLiveQueueBytes) are frames given up unestimated (skipped). Before the
  // camera's first frame, the stage is prepared for the sun of now (FrameStage::Prepare).
  PipelineRun Run(std::unique_ptr<capture::FrameSource> source);

 private:
  bool StopRequested() const;
  // The stage (if `image`), the sinks and the video for one frame; the stage's time in ms, or < 0
  // without one.
  double Deliver(const capture::Frame& frame, const estimation::FrameLight& light, const scene::TrackedSun& sun,
                 bool image);

  // A live camera's read-ahead queue: 256 MiB of frames (41 at 960×540, 10 at 1920×1080), 4 to 64.
  static constexpr size_t kLiveQueueBytes = size_t{256} << 20;

  const scene::Scene& scene_;
  const bake::SceneBake& bake_;
  const scene::RayCaster& caster_;
  LightingPipelineOptions options_;
  FrameStage* stage_ = nullptr;
  std::vector<FrameSink*> sinks_;
  capture::AsyncVideoWriter* video_ = nullptr;
  std::vector<float> image_;
};

}  // namespace daylit::pipeline
