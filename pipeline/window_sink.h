// The pipeline's window (daylit replay/live --window): each frame's image encoded as the video
// would be, with the overlay (fps, the sun, E_sun/E_sky) and the time slider, whose keys and
// clicks it applies for the next frame. Closing the window asks the pipeline to stop.
#pragma once

#include <chrono>

#include <opencv2/core.hpp>

#include "pipeline/lighting_pipeline.h"
#include "render/time_slider.h"
#include "render/gl_window.h"
#include "render/window_overlay.h"

namespace daylit::pipeline {

class WindowSink final : public FrameSink {
 public:
  // All kept by reference; `slider` is the one the CompositeStage reads.
  WindowSink(const scene::Scene& scene, render::GlWindow* window, render::TimeSlider* slider);
  void Consume(const PipelineFrame& frame) override;
  bool StopRequested() const override { return closed_; }

 private:
  const scene::Scene& scene_;
  render::GlWindow& window_;
  render::TimeSlider& slider_;
  const capture::Encoder to_screen_;
  cv::Mat shown_rgb_, shown_;
  std::chrono::steady_clock::time_point last_shown_;
  double shown_fps_ = 0.0;
  render::SunlitDay sunlit_day_;
  bool closed_ = false;
};

}  // namespace daylit::pipeline
