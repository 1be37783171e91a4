// The time slider of daylit's window (replay and live with --window): a time of day to relight
// the frames to (relight::ImageRelighter), or off. The bar spans the site's local mean solar day,
// midnight to midnight at its longitude (UTC + longitude / 15°·h), so any site's day is in one
// piece and noon sits near the middle; the relit instant is that time of day on the frame's own
// solar day. Pure arithmetic, no window: the drawing and the input are the app's.
#pragma once

#include <optional>
#include <string>

#include "base/utc_time.h"

namespace daylit::render {

class TimeSlider {
 public:
  static constexpr int kDayMinutes = 24 * 60;

  explicit TimeSlider(double longitude_deg) : longitude_deg_(longitude_deg) {}

  bool active() const { return solar_minutes_.has_value(); }
  void Off() { solar_minutes_.reset(); }
  // The relit time as minutes of the solar day, [0, 1440]; none when off.
  std::optional<double> solar_minutes() const { return solar_minutes_; }

  // Starts at a UTC time of day (minutes past 00:00Z, [0, 1440)): the instant of the frame's solar
  // day whose UTC clock reads that.
  void SetUtcMinutes(double utc_minutes);
  // A click or drag at `fraction` of the bar (0 = its left end), kept on whole `snap` minutes.
  void SetFraction(double fraction, int snap = 5);
  // Moves it by `minutes` (an arrow key), clamped to the day. From off, it starts at `frame`'s own
  // time of day, rounded to the step.
  void Step(int minutes, const UtcTime& frame);

  // Where instant `t` sits on its own solar day's bar, [0, 1).
  double Fraction(const UtcTime& t) const;
  // The instant to relight `frame` to; none when off.
  std::optional<UtcTime> Target(const UtcTime& frame) const;
  // The instant at `fraction` of `frame`'s solar day (for drawing the day: where the sun is up).
  UtcTime AtFraction(const UtcTime& frame, double fraction) const;

 private:
  double SolarMinutesOf(const UtcTime& t) const;
  double longitude_deg_;
  std::optional<double> solar_minutes_;
};

// "HH:MM" (a UTC time of day, optionally ending in "Z") as minutes past midnight. Throws
// InputError "<where>: ..." when malformed.
double ParseUtcTimeOfDay(const std::string& text, const char* where);

}  // namespace daylit::render
