#include "pipeline/window_sink.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>

namespace daylit::pipeline {

WindowSink::WindowSink(const scene::Scene& scene, render::GlWindow* window, render::TimeSlider* slider)
    : scene_(scene),
      window_(*window),
      slider_(*slider),
      to_screen_(scene.response),
      last_shown_(std::chrono::steady_clock::now()) {}

void WindowSink::Consume(const PipelineFrame& frame) {
  if (frame.image == nullptr) return;  // could not be read: the window keeps the last frame
  const estimation::FrameEstimate& row = frame.light.row;
  const int width = frame.frame.rgb.cols, height = frame.frame.rgb.rows;
  shown_rgb_.create(height, width, CV_32FC3);
  to_screen_.Apply(frame.image->data(), static_cast<float>(frame.frame.exposure), shown_rgb_.ptr<float>(),
                   frame.image->size());
  shown_rgb_.convertTo(shown_, CV_8UC3, 255.0);
  cv::cvtColor(shown_, shown_, cv::COLOR_RGB2BGR);
  const auto now = std::chrono::steady_clock::now();
  const double dt = std::max(std::chrono::duration<double>(now - last_shown_).count(), 1e-3);
  shown_fps_ = shown_fps_ == 0.0 ? 1.0 / dt : 0.9 * shown_fps_ + 0.1 / dt;
  last_shown_ = now;
  render::DrawOverlay(&shown_, shown_fps_, row, to_screen_);
  std::optional<scene::SceneSun> relit_sun;
  if (frame.image_light == ImageLight::kOtherLight && row.HasEstimate()) {
    if (const std::optional<UtcTime> target = slider_.Target(row.time_utc)) relit_sun = scene::SunAt(scene_, *target);
  }
  render::DrawTimeSlider(&shown_, slider_, scene_, row.time_utc, relit_sun, &sunlit_day_);
  if (!window_.Show(shown_)) closed_ = true;  // closed: end as Ctrl-C does
  render::ApplyInput(window_.TakeInput(), row.time_utc, render::SliderBar::Of(width, height), &slider_);
}

}  // namespace daylit::pipeline
