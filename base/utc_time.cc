#include "base/utc_time.h"

#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include "base/error.h"

namespace daylit {
namespace {

// Reads exactly `digits` decimal digits at text[*pos].
bool ReadDigits(std::string_view text, size_t* pos, int digits, int* value) {
  if (*pos + static_cast<size_t>(digits) > text.size()) return false;
  int v = 0;
  for (int i = 0; i < digits; ++i) {
    const char c = text[*pos + static_cast<size_t>(i)];
    if (c < '0' || c > '9') return false;
    v = v * 10 + (c - '0');
  }
  *pos += static_cast<size_t>(digits);
  *value = v;
  return true;
}

bool Expect(std::string_view text, size_t* pos, char c) {
  if (*pos >= text.size() || text[*pos] != c) return false;
  ++*pos;
  return true;
}

int64_t FloorDiv(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

bool Fail(std::string* why, const char* message) {
  if (why != nullptr) *why = message;
  return false;
}

}  // namespace

int64_t DaysFromCivil(int year, int month, int day) {
  const int64_t y = static_cast<int64_t>(year) - (month <= 2 ? 1 : 0);
  const int64_t era = (y >= 0 ? y : y - 399) / 400;
  const int64_t yoe = y - era * 400;
  const int64_t mp = (month + 9) % 12;
  const int64_t doy = (153 * mp + 2) / 5 + day - 1;
  const int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

void CivilFromDays(int64_t days, int* year, int* month, int* day) {
  const int64_t z = days + 719468;
  const int64_t era = (z >= 0 ? z : z - 146096) / 146097;
  const int64_t doe = z - era * 146097;
  const int64_t yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const int64_t doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const int64_t mp = (5 * doy + 2) / 153;
  const int64_t d = doy - (153 * mp + 2) / 5 + 1;
  const int64_t m = mp < 10 ? mp + 3 : mp - 9;
  *year = static_cast<int>(yoe + era * 400 + (m <= 2 ? 1 : 0));
  *month = static_cast<int>(m);
  *day = static_cast<int>(d);
}

int DaysInMonth(int year, int month) {
  static constexpr int kDays[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  const bool leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
  return month == 2 && leap ? 29 : kDays[month - 1];
}

int64_t UtcTime::UnixDay() const { return DaysFromCivil(year, month, day); }

double UtcTime::SecondsSince(const UtcTime& earlier) const {
  const int64_t days = UnixDay() - earlier.UnixDay();
  const int minutes = (hour - earlier.hour) * 60 + (minute - earlier.minute);
  return static_cast<double>(days) * 86400.0 + minutes * 60.0 + (second - earlier.second);
}

bool TryParseUtcTime(std::string_view text, UtcTime* utc, std::string* why) {
  size_t pos = 0;
  UtcTime t;
  if (!ReadDigits(text, &pos, 4, &t.year) || !Expect(text, &pos, '-') ||
      !ReadDigits(text, &pos, 2, &t.month) || !Expect(text, &pos, '-') ||
      !ReadDigits(text, &pos, 2, &t.day)) {
    return Fail(why, "not an ISO 8601 date (expected YYYY-MM-DDTHH:MM:SSZ)");
  }
  if (!(Expect(text, &pos, 'T') || Expect(text, &pos, ' ')) ||
      !ReadDigits(text, &pos, 2, &t.hour) || !Expect(text, &pos, ':') ||
      !ReadDigits(text, &pos, 2, &t.minute)) {
    return Fail(why, "not an ISO 8601 date and time (expected YYYY-MM-DDTHH:MM:SSZ)");
  }
  if (pos < text.size() && text[pos] == ':') {
    ++pos;
    const size_t start = pos;
    while (pos < text.size() && ((text[pos] >= '0' && text[pos] <= '9') || text[pos] == '.')) {
      ++pos;
    }
    if (pos - start < 2 || text[start + 2 - 1] == '.') {
      return Fail(why, "seconds must have two digits");
    }
    const auto [end, ec] = std::from_chars(text.data() + start, text.data() + pos, t.second);
    if (ec != std::errc() || end != text.data() + pos) return Fail(why, "malformed seconds");
  }
  int offset_minutes = 0;
  if (pos == text.size()) {
    return Fail(why, "time has no zone: append Z for UTC (or an offset such as +02:00)");
  }
  if (text[pos] == 'Z' || text[pos] == 'z') {
    ++pos;
  } else if (text[pos] == '+' || text[pos] == '-') {
    const int sign = text[pos] == '-' ? -1 : 1;
    ++pos;
    int oh = 0, om = 0;
    if (!ReadDigits(text, &pos, 2, &oh)) return Fail(why, "malformed zone offset");
    Expect(text, &pos, ':');
    if (!ReadDigits(text, &pos, 2, &om) || oh > 18 || om > 59) {
      return Fail(why, "malformed zone offset");
    }
    offset_minutes = sign * (oh * 60 + om);
  } else {
    return Fail(why, "unexpected characters after the time (zone must be Z or +HH:MM)");
  }
  if (pos != text.size()) return Fail(why, "unexpected characters after the zone");
  if (t.month < 1 || t.month > 12 || t.day < 1 || t.day > DaysInMonth(t.year, t.month)) {
    return Fail(why, "no such date");
  }
  const bool leap_second_slot = t.hour == 23 && t.minute == 59 && offset_minutes == 0;
  if (t.hour > 23 || t.minute > 59 || !(t.second >= 0.0) ||
      t.second >= (leap_second_slot ? 61.0 : 60.0)) {
    return Fail(why, "no such time of day");
  }
  if (offset_minutes != 0) {
    const int64_t minutes =
        DaysFromCivil(t.year, t.month, t.day) * 1440 + t.hour * 60 + t.minute - offset_minutes;
    const int64_t days = FloorDiv(minutes, 1440);
    const int64_t minute_of_day = minutes - days * 1440;
    CivilFromDays(days, &t.year, &t.month, &t.day);
    t.hour = static_cast<int>(minute_of_day / 60);
    t.minute = static_cast<int>(minute_of_day % 60);
  }
  *utc = t;
  return true;
}

UtcTime ParseUtcTime(std::string_view text, std::string_view where) {
  UtcTime utc;
  std::string why;
  if (!TryParseUtcTime(text, &utc, &why)) {
    ThrowInputError("{}: {} ('{}')", where, why, Excerpt(text));
  }
  return utc;
}

std::string FormatUtcTime(const UtcTime& utc, int decimals) {
  decimals = decimals < 0 ? 0 : (decimals > 9 ? 9 : decimals);
  // Round first so that 59.9996 s printed with 3 decimals does not read "60.000".
  const double scale = std::pow(10.0, decimals);
  double second = std::floor(utc.second * scale + 0.5) / scale;
  UtcTime t = utc;
  const double limit = (t.hour == 23 && t.minute == 59 && utc.second >= 60.0) ? 61.0 : 60.0;
  if (second >= limit) {
    second -= 60.0;
    const int64_t minutes = t.UnixDay() * 1440 + t.hour * 60 + t.minute + 1;
    const int64_t days = FloorDiv(minutes, 1440);
    const int64_t minute_of_day = minutes - days * 1440;
    CivilFromDays(days, &t.year, &t.month, &t.day);
    t.hour = static_cast<int>(minute_of_day / 60);
    t.minute = static_cast<int>(minute_of_day % 60);
  }
  const int width = decimals > 0 ? decimals + 3 : 2;
  return fmt::format("{:04d}-{:02d}-{:02d}T{:02d}:{:02d}:{:0{}.{}f}Z", t.year, t.month, t.day,
                     t.hour, t.minute, second, width, decimals);
}

UtcTime UtcFromUnixSeconds(double seconds) {
  const double days = std::floor(seconds / 86400.0);
  double rest = seconds - days * 86400.0;
  UtcTime utc;
  CivilFromDays(static_cast<int64_t>(days), &utc.year, &utc.month, &utc.day);
  utc.hour = std::min(23, static_cast<int>(rest / 3600.0));
  rest -= utc.hour * 3600.0;
  utc.minute = std::min(59, static_cast<int>(rest / 60.0));
  utc.second = rest - utc.minute * 60.0;
  return utc;
}

double UnixSeconds(const UtcTime& utc) {
  return static_cast<double>(utc.UnixDay()) * 86400.0 + utc.hour * 3600.0 + utc.minute * 60.0 + utc.second;
}

}  // namespace daylit
