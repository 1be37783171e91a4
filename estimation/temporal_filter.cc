#include "estimation/temporal_filter.h"

#include "base/options_check.h"

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
  // Per channel, a change within the noise band (a share of the value itself) is smoothed with
  // gain `smoothing`; what lies beyond it is taken at once. Noise is damped, a cloud edge is
  // followed on the frame it arrives, lagging by at most (1 − gain)·band. A band shared by E_sun
  // and E_sky would be a third of E_sky under a strong low sun and hold the sky back for frames.
  for (int c = 0; c < 3; ++c) {
    for (double* value : {&state_->light.sun_rgb[c], &state_->light.sky_rgb[c]}) {
      const double band = options_.noise_band * *value;
      const double d = (value == &state_->light.sun_rgb[c] ? target.sun_rgb[c] : target.sky_rgb[c]) - *value;
      const double small = std::clamp(d, -band, band);
      *value += options_.smoothing * small + (d - small);
    }
  }
  state_->confidence += options_.smoothing * (confidence - state_->confidence);
  return *state_;
}

std::string TemporalFilterOptions::Check() const {
  if (median_window % 2 == 0) return fmt::format("median_window: {} frames is not odd", median_window);
  return FirstProblem({InClosed("median_window", median_window, 1, 99), InClosed("noise_band", noise_band, 0.0, 1.0),
                       InOpenClosed("smoothing", smoothing, 0.0, 1.0), InClosed("min_confidence", min_confidence, 0.0, 1.0),
                       InOpenClosed("restart_gap_s", restart_gap_s, 0.0, 1e9)});
}

}  // namespace daylit::estimation
