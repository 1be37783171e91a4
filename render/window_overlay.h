// What daylit's window draws over the frames (daylit replay/live --window): frames per second,
// the sun, E_sun and E_sky as swatches, and the time slider's bar over the site's solar day with
// the keys and clicks that move it. OpenCV drawing into the shown BGR image; no GL.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "base/utc_time.h"
#include "capture/response.h"
#include "estimation/frame_estimator.h"
#include "render/time_slider.h"
#include "render/gl_window.h"
#include "scene/scene.h"

namespace daylit::render {

// Frames per second, the sun, and E_sun and E_sky as swatches of their colour (at full
// brightness, encoded as the image is) with their values.
void DrawOverlay(cv::Mat* bgr, double fps, const estimation::FrameEstimate& row, const capture::Encoder& encode);

// The time slider's bar along the bottom of a width × height image.
struct SliderBar {
  int x0, x1, y, height;
  static SliderBar Of(int width, int height) { return {16, width - 16, height - 22, 10}; }
  bool Hit(const cv::Point2d& p) const { return p.y >= y - 14 && p.y <= y + height + 14 && p.x >= x0 - 8 && p.x <= x1 + 8; }
  int X(double fraction) const;
};

// Arrow keys move the slider by 15 min (left, right) or an hour (down, up); Backspace turns it off
// (the frame's own time); a click or drag on the bar puts it there.
void ApplyInput(const WindowInput& input, const UtcTime& frame_utc, const SliderBar& bar, TimeSlider* slider);

// Where the sun is up over one solar day, sampled every 10 minutes, for shading the bar's night;
// kept between frames and recomputed when the day changes.
struct SunlitDay {
  double midnight = -1.0;  // the day's start, Unix seconds
  std::vector<bool> up;
};

// The bar, the frame's time on it, and the slider's target with its sun (`relit_sun`: null when
// the frame is shown as it is).
void DrawTimeSlider(cv::Mat* bgr, const TimeSlider& slider, const scene::Scene& scene, const UtcTime& frame_utc,
                    const std::optional<scene::SceneSun>& relit_sun, SunlitDay* day);

}  // namespace daylit::render
