// Temporal filtering of the per-frame estimates: no flicker, yet a cloud covering the sun shows on
// the frame it arrives. Per channel of E_sun and E_sky: optionally the median of the last
// `median_window` fits (1 by default: a median of 3 stops a single wild fit but delays every cloud
// edge by a frame); then a change within the noise band (`noise_band` × the value itself: E_sun's
// band is a share of E_sun, E_sky's of E_sky) is smoothed with gain `smoothing`, and what lies
// beyond the band is taken at once.
// Fits below `min_confidence` are skipped (the estimate holds). A gap in time (the next burst of a
// recording, a camera that was unplugged) restarts the filter.
//
// Lag (defaults): a step larger than the band is followed on the same frame to within
// 0.7 × 3% = 2.1% of the value before the step, and that remainder decays by 0.7 per frame.
// Noise within the band is damped to 0.42 of its standard deviation (exponential smoothing with
// gain 0.3; tested). The per-frame fits on the recordings jitter by about 0.3% (median).
#pragma once

#include <string>

#include <deque>
#include <optional>

#include "estimation/lighting_model.h"

namespace daylit::estimation {

struct TemporalFilterOptions {
  int median_window = 1;         // frames, odd, ≥ 1
  double noise_band = 0.03;      // changes within this share of the value itself are smoothed
  double smoothing = 0.3;        // per-frame gain within the band, in (0, 1]
  double min_confidence = 0.05;  // fits below this do not move the estimate (the first one starts it)
  double restart_gap_s = 60.0;   // a longer gap between frames restarts the filter
  // Empty when every field is in range, else the first problem, naming the field.
  std::string Check() const;
};

struct FilteredLight {
  SunSky light;
  double confidence = 0.0;  // the filter's own: an exponential average of the fits' confidences
};

class TemporalFilter {
 public:
  explicit TemporalFilter(TemporalFilterOptions options = {}) : options_(options) {}

  // Feeds the fit of the frame at `time_s` (seconds, any origin, non-decreasing) and returns the
  // filtered light. A frame without a usable fit passes `std::nullopt`: the estimate holds.
  FilteredLight Update(double time_s, const std::optional<SunSky>& fit, double confidence);

 private:
  TemporalFilterOptions options_;
  std::deque<SunSky> window_;
  std::optional<FilteredLight> state_;
  std::optional<double> last_time_s_;
};

}  // namespace daylit::estimation
