#include "estimation/temporal_filter.h"

#include "base/statistics.h"

#include <algorithm>
#include <vector>

namespace daylit::estimation {
namespace {

double Median(std::vector<double> v) { return MedianInPlace(v, 0.0); }

SunSky WindowMedian(const std::deque<SunSky>& window) {
  SunSky out;
  std::vector<double> sun(window.size()), sky(window.size());
  for (int c = 0; c < 3; ++c) {
    for (size_t i = 0; i < window.size(); ++i) sun[i] = window[i].sun_rgb[c], sky[i] = window[i].sky_rgb[c];
    out.sun_rgb[c] = Median(sun);
    out.sky_rgb[c] = Median(sky);
  }
  return out;
}

}  // namespace

FilteredLight TemporalFilter::Update(double time_s, const std::optional<SunSky>& fit, double confidence) {
  if (last_time_s_ && time_s - *last_time_s_ > options_.restart_gap_s) {
    window_.clear();
    state_.reset();
  }
  last_time_s_ = time_s;
  // Until a first fit arrives there is nothing to hold, so the first usable fit starts the filter
  // whatever its confidence; later, fits below min_confidence do not move the estimate.
  if (!fit || (state_ && confidence < options_.min_confidence)) {
    if (state_) {
      state_->confidence *= 1.0 - options_.smoothing;  // holding: trust fades
      return *state_;
    }
    return FilteredLight{};
  }
  window_.push_back(*fit);
  while (static_cast<int>(window_.size()) > options_.median_window) window_.pop_front();
  if (!state_) {
    state_ = FilteredLight{*fit, confidence};
    return *state_;
  }
  // While the window fills after a restart, the median of what there is.
  const SunSky target = WindowMedian(window_);
  // A fixed gain: the confidence gates frames (above), it does not slow the filter. A scene
  // whose model fits only to 20% still follows a cloud frame by frame.
  const double gain = options_.smoothing;
  state_->light.sun_rgb += gain * (target.sun_rgb - state_->light.sun_rgb);
  state_->light.sky_rgb += gain * (target.sky_rgb - state_->light.sky_rgb);
  state_->confidence += options_.smoothing * (confidence - state_->confidence);
  return *state_;
}

}  // namespace daylit::estimation
