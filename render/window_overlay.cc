#include "render/window_overlay.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

namespace daylit::render {

void DrawOverlay(cv::Mat* bgr, double fps, const estimation::FrameEstimate& row, const capture::Encoder& encode) {
  const auto text = [&](const std::string& line, int x, int y) {
    cv::putText(*bgr, line, {x, y}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
    cv::putText(*bgr, line, {x, y}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  };
  text(fmt::format("frame {}  {:.0f} fps  sun {:.1f} deg up, {:.1f} deg az", row.frame, fps, row.sun_elevation_deg,
                   row.sun_azimuth_deg), 12, 22);
  int y = 34;
  for (const bool sun : {true, false}) {
    const glm::dvec3 e = sun ? row.light.sun_rgb : row.light.sky_rgb;
    const double top = std::max({e.x, e.y, e.z, 1e-9});
    cv::Scalar colour;
    for (int c = 0; c < 3; ++c) colour[2 - c] = 255.0 * encode(static_cast<float>(e[c] / top), c);
    cv::rectangle(*bgr, cv::Rect(12, y, 24, 16), colour, cv::FILLED);
    cv::rectangle(*bgr, cv::Rect(12, y, 24, 16), cv::Scalar(255, 255, 255), 1);
    text(fmt::format("{} {:.3g} {:.3g} {:.3g}", sun ? "E_sun" : "E_sky", e.x, e.y, e.z), 44, y + 13);
    y += 22;
  }
}

int SliderBar::X(double fraction) const { return x0 + static_cast<int>(std::lround(fraction * (x1 - x0))); }

void ApplyInput(const WindowInput& input, const UtcTime& frame_utc, const SliderBar& bar, TimeSlider* slider) {
  for (const WindowKey key : input.keys) {
    switch (key) {
      case WindowKey::kLeft: slider->Step(-15, frame_utc); break;
      case WindowKey::kRight: slider->Step(15, frame_utc); break;
      case WindowKey::kDown: slider->Step(-60, frame_utc); break;
      case WindowKey::kUp: slider->Step(60, frame_utc); break;
      case WindowKey::kBackspace: slider->Off(); break;
    }
  }
  if (input.dragging && bar.Hit(*input.dragging)) {
    slider->SetFraction((input.dragging->x - bar.x0) / static_cast<double>(bar.x1 - bar.x0));
  }
}

void DrawTimeSlider(cv::Mat* bgr, const TimeSlider& slider, const scene::Scene& scene, const UtcTime& frame_utc,
                    const std::optional<scene::SceneSun>& relit_sun, SunlitDay* day) {
  const SliderBar bar = SliderBar::Of(bgr->cols, bgr->rows);
  const double midnight = UnixSeconds(slider.AtFraction(frame_utc, 0.0));
  if (std::abs(midnight - day->midnight) > 1.0) {
    day->midnight = midnight;
    day->up.assign(144, false);
    for (int i = 0; i < 144; ++i) {
      day->up[i] = scene::SunAt(scene, UtcFromUnixSeconds(midnight + 600.0 * (i + 0.5))).dir.z > 0.0;
    }
  }
  for (int i = 0; i < 144; ++i) {
    const cv::Scalar colour = day->up[i] ? cv::Scalar(150, 200, 230) : cv::Scalar(90, 40, 30);
    cv::rectangle(*bgr, cv::Point(bar.X(i / 144.0), bar.y), cv::Point(bar.X((i + 1) / 144.0), bar.y + bar.height), colour,
                  cv::FILLED);
  }
  cv::rectangle(*bgr, cv::Rect(bar.x0, bar.y, bar.x1 - bar.x0, bar.height), cv::Scalar(255, 255, 255), 1);
  for (int hour = 3; hour < 24; hour += 3) {
    cv::line(*bgr, {bar.X(hour / 24.0), bar.y + bar.height}, {bar.X(hour / 24.0), bar.y + bar.height + 4},
             cv::Scalar(255, 255, 255), 1);
  }
  const int now = bar.X(slider.Fraction(frame_utc));
  cv::line(*bgr, {now, bar.y - 4}, {now, bar.y + bar.height + 4}, cv::Scalar(255, 255, 255), 2);
  const auto text = [&](const std::string& line) {
    cv::putText(*bgr, line, {bar.x0, bar.y - 8}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
    cv::putText(*bgr, line, {bar.x0, bar.y - 8}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  };
  const std::optional<UtcTime> target = slider.Target(frame_utc);
  if (!target || !relit_sun) {
    text(target ? "no estimate yet: shown as it is" : "time of day: <- -> 15 min, up/down 1 h, or click the bar");
    return;
  }
  const int x = bar.X(*slider.solar_minutes() / TimeSlider::kDayMinutes);
  cv::circle(*bgr, {x, bar.y + bar.height / 2}, 7, cv::Scalar(0, 200, 255), cv::FILLED, cv::LINE_AA);
  cv::circle(*bgr, {x, bar.y + bar.height / 2}, 7, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  const int solar = static_cast<int>(std::lround(*slider.solar_minutes()));
  const UtcTime utc = UtcFromUnixSeconds(60.0 * std::round(UnixSeconds(*target) / 60.0));
  const double elevation = relit_sun->position.ApparentElevationDeg();
  text(fmt::format("relit to {:02d}:{:02d} UTC (solar {:02d}:{:02d}), sun {}  [Backspace: the frame's own time]",
                   utc.hour, utc.minute, solar / 60 % 24, solar % 60,
                   relit_sun->dir.z > 0.0 ? fmt::format("{:.1f} deg up, {:.1f} deg az", elevation, relit_sun->position.azimuth_deg)
                                          : fmt::format("{:.1f} deg below the horizon: sky only", -elevation)));
}

}  // namespace daylit::render
