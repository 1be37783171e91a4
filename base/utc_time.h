// UTC instants as written in recordings and CSV files: ISO 8601 with an explicit zone.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace daylit {

// A UTC calendar instant. `second` may reach 60.x only at 23:59 (a leap second).
struct UtcTime {
  int year = 2000;
  int month = 1;   // 1..12
  int day = 1;     // 1..31
  int hour = 0;    // 0..23
  int minute = 0;  // 0..59
  double second = 0.0;

  // Days since 1970-01-01 of the date (proleptic Gregorian).
  int64_t UnixDay() const;
  // Seconds from `earlier` to this instant, ignoring leap seconds (as POSIX time does), exact to
  // the double precision of the seconds field; for durations and ordering within a recording.
  // The ephemeris uses the calendar fields, never this.
  double SecondsSince(const UtcTime& earlier) const;
};

// Parses "YYYY-MM-DDTHH:MM[:SS[.fff]]" followed by "Z" or a "+HH:MM"/"-HH:MM"/"+HHMM" offset
// (converted to UTC); a space may stand for the "T". Returns false and sets `why` (without
// the text itself) when the text is malformed, out of range or has no zone.
bool TryParseUtcTime(std::string_view text, UtcTime* utc, std::string* why);

// As TryParseUtcTime, but throws InputError "<where>: <why> ('<text>')".
UtcTime ParseUtcTime(std::string_view text, std::string_view where);

// "2026-06-21T05:00:00.000Z" with `decimals` digits of the second (0..9).
std::string FormatUtcTime(const UtcTime& utc, int decimals = 3);

// The instant `seconds` after 1970-01-01T00:00:00Z (POSIX time: no leap seconds), and back.
UtcTime UtcFromUnixSeconds(double seconds);
double UnixSeconds(const UtcTime& utc);
// `utc` moved by `seconds` (POSIX time: no leap seconds).
inline UtcTime ShiftedUtc(const UtcTime& utc, double seconds) { return UtcFromUnixSeconds(UnixSeconds(utc) + seconds); }

// Proleptic Gregorian calendar <-> days since 1970-01-01 (H. Hinnant's civil-day algorithms).
int64_t DaysFromCivil(int year, int month, int day);
void CivilFromDays(int64_t days, int* year, int* month, int* day);
int DaysInMonth(int year, int month);

}  // namespace daylit
