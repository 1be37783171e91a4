#include "render/time_slider.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "base/error.h"

namespace daylit::render {
namespace {

constexpr double kDaySeconds = 86400.0;

}  // namespace

double TimeSlider::SolarMinutesOf(const UtcTime& t) const {
  // Local mean solar time leads UTC by 4 minutes per degree east.
  const double solar = UnixSeconds(t) / 60.0 + 4.0 * longitude_deg_;
  return solar - kDayMinutes * std::floor(solar / kDayMinutes);
}

void TimeSlider::SetUtcMinutes(double utc_minutes) {
  const double solar = utc_minutes + 4.0 * longitude_deg_;
  solar_minutes_ = solar - kDayMinutes * std::floor(solar / kDayMinutes);
}

void TimeSlider::SetFraction(double fraction, int snap) {
  const double minutes = std::clamp(fraction, 0.0, 1.0) * kDayMinutes;
  solar_minutes_ = snap > 0 ? snap * std::round(minutes / snap) : minutes;
}

void TimeSlider::Step(int minutes, const UtcTime& frame) {
  if (!solar_minutes_) {
    const int step = std::max(1, std::abs(minutes));
    solar_minutes_ = step * std::round(SolarMinutesOf(frame) / step);
  }
  solar_minutes_ = std::clamp(*solar_minutes_ + minutes, 0.0, static_cast<double>(kDayMinutes));
}

double TimeSlider::Fraction(const UtcTime& t) const { return SolarMinutesOf(t) / kDayMinutes; }

UtcTime TimeSlider::AtFraction(const UtcTime& frame, double fraction) const {
  const double midnight = UnixSeconds(frame) - 60.0 * SolarMinutesOf(frame);
  return UtcFromUnixSeconds(midnight + fraction * kDaySeconds);
}

std::optional<UtcTime> TimeSlider::Target(const UtcTime& frame) const {
  if (!solar_minutes_) return std::nullopt;
  return AtFraction(frame, *solar_minutes_ / kDayMinutes);
}

double ParseUtcTimeOfDay(const std::string& text, const char* where) {
  std::string t = text;
  if (!t.empty() && (t.back() == 'Z' || t.back() == 'z')) t.pop_back();
  const auto digit = [&t](size_t i) { return std::isdigit(static_cast<unsigned char>(t[i])) != 0; };
  if (t.size() == 5 && t[2] == ':' && digit(0) && digit(1) && digit(3) && digit(4)) {
    const int hour = 10 * (t[0] - '0') + (t[1] - '0'), minute = 10 * (t[3] - '0') + (t[4] - '0');
    if (hour < 24 && minute < 60) return 60.0 * hour + minute;
  }
  ThrowInputError("{}: '{}' is not a UTC time of day HH:MM (00:00 to 23:59)", where, text);
}

}  // namespace daylit::render
