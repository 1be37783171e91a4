#include "sunmodel/time_scales.h"

#include <erfa.h>

#include <cmath>

#include <fmt/format.h>

#include "base/error.h"

namespace daylit::sunmodel {

std::string EarthOrientation::Check(std::string_view delta_t_name, std::string_view dut1_name) const {
  if (dut1_s && !(std::abs(*dut1_s) < 0.9)) {
    return fmt::format("{}: {} s is not UT1 − UTC (|UT1 − UTC| < 0.9 s always)", dut1_name, *dut1_s);
  }
  if (delta_t_s && !(*delta_t_s >= -1000.0 && *delta_t_s <= 20000.0)) {
    return fmt::format("{}: {} s is outside [-1000, 20000] (TT − UT1 from 500 BCE to 3000 CE)", delta_t_name, *delta_t_s);
  }
  return {};
}

namespace {

constexpr double kSecondsPerDay = 86400.0;

// UTC (and ERFA's TAI − UTC table) starts in 1960. Past the table's end eraDat keeps the last
// TAI − UTC and returns status +1 ("dubious year"), which we accept.
constexpr int kFirstUtcYear = 1960;

double Horner(double t, std::initializer_list<double> coefficients_high_first) {
  double value = 0.0;
  for (const double c : coefficients_high_first) value = value * t + c;
  return value;
}

}  // namespace

std::string_view DeltaTSourceName(DeltaTSource source) {
  switch (source) {
    case DeltaTSource::kGiven: return "given";
    case DeltaTSource::kLeapSeconds: return "leap-second table";
    case DeltaTSource::kHistoricalModel: return "Espenak-Meeus model";
    case DeltaTSource::kLongTermModel: return "long-term parabola";
  }
  return "?";
}

double ModelDeltaT(double y) {
  // Espenak & Meeus (2006), "Polynomial expressions for Delta T", valid ranges as published.
  if (y >= 1800.0 && y < 1860.0) {
    return Horner(y - 1800.0, {0.000000000875, -0.0000001699, 0.0000121272, -0.00037436,
                               0.0041116, 0.0068612, -0.332447, 13.72});
  }
  if (y >= 1860.0 && y < 1900.0) {
    return Horner(y - 1860.0, {1.0 / 233174.0, -0.0004473624, 0.01680668, -0.251754, 0.5737, 7.62});
  }
  if (y >= 1900.0 && y < 1920.0) {
    return Horner(y - 1900.0, {-0.000197, 0.0061966, -0.0598939, 1.494119, -2.79});
  }
  if (y >= 1920.0 && y < 1941.0) {
    return Horner(y - 1920.0, {0.0020936, -0.076100, 0.84493, 21.20});
  }
  if (y >= 1941.0 && y < 1961.0) {
    return Horner(y - 1950.0, {1.0 / 2547.0, -1.0 / 233.0, 0.407, 29.07});
  }
  if (y >= 1961.0 && y < 1986.0) {
    return Horner(y - 1975.0, {-1.0 / 718.0, -1.0 / 260.0, 1.067, 45.45});
  }
  if (y >= 1986.0 && y < 2005.0) {
    return Horner(y - 2000.0, {0.00002373599, 0.000651814, 0.0017275, -0.060374, 0.3345, 63.86});
  }
  const double u = (y - 1820.0) / 100.0;
  return -20.0 + 32.0 * u * u;
}

TimeScales ResolveTimeScales(const UtcTime& utc, const EarthOrientation& orientation) {
  TimeScales ts;
  const double dut1 = orientation.dut1_s.value_or(0.0);
  // ERFA's quasi-JD for UTC: a day that ends with a leap second has 86 401 s, and only then may
  // the seconds reach 60.x at 23:59 (else status +2, "time after end of day", +3 with a dubious
  // year). Before 1960 (status +1) the date is plain UT.
  double u1 = 0.0, u2 = 0.0;
  const int status = eraDtf2d("UTC", utc.year, utc.month, utc.day, utc.hour, utc.minute, utc.second, &u1, &u2);
  if (status >= 2) {
    ThrowInputError("{}: no leap second ends that UTC day, so its last minute has 60 seconds (IERS table in ERFA)",
                    FormatUtcTime(utc));
  }
  if (status < 0) ThrowInputError("{}: not a calendar date ERFA accepts (status {})", FormatUtcTime(utc), status);
  if (utc.year >= kFirstUtcYear) {
    // UT1 = UTC + DUT1 and TT = TAI + 32.184 s, both through ERFA from the quasi-JD, which
    // takes the leap second into account. Reading the quasi-JD as a plain Julian date put an
    // instant late on such a day up to 1 s late (0.92 s at 22:11: 0.004° of sun).
    if (eraUtcut1(u1, u2, dut1, &ts.ut1_jd1, &ts.ut1_jd2) < 0) {
      ThrowInputError("{}: ERFA cannot take it to UT1", FormatUtcTime(utc));
    }
    if (orientation.delta_t_s) {
      ts.source = DeltaTSource::kGiven;
      ts.delta_t_s = *orientation.delta_t_s;
      ts.tt_jd1 = ts.ut1_jd1, ts.tt_jd2 = ts.ut1_jd2 + ts.delta_t_s / kSecondsPerDay;
      return ts;
    }
    // TT − UTC is exact from the leap-second table; only UT1 − UTC is unknown, and leap
    // seconds keep it within 0.9 s.
    double tai1 = 0.0, tai2 = 0.0;
    eraUtctai(u1, u2, &tai1, &tai2);
    eraTaitt(tai1, tai2, &ts.tt_jd1, &ts.tt_jd2);
    ts.source = DeltaTSource::kLeapSeconds;
    ts.delta_t_s = ((ts.tt_jd1 - ts.ut1_jd1) + (ts.tt_jd2 - ts.ut1_jd2)) * kSecondsPerDay;
    ts.ut1_uncertainty_s = orientation.dut1_s ? 0.0 : 0.9;
    return ts;
  }
  ts.ut1_jd1 = u1;
  ts.ut1_jd2 = u2 + dut1 / kSecondsPerDay;
  if (orientation.delta_t_s) {
    ts.source = DeltaTSource::kGiven;
    ts.delta_t_s = *orientation.delta_t_s;
  } else {
    const double decimal_year = utc.year + (utc.month - 0.5) / 12.0;
    ts.delta_t_s = ModelDeltaT(decimal_year);
    const bool historical = decimal_year >= 1800.0;
    ts.source = historical ? DeltaTSource::kHistoricalModel : DeltaTSource::kLongTermModel;
    ts.ut1_uncertainty_s = historical ? 1.0 : 60.0;
  }
  ts.tt_jd1 = ts.ut1_jd1;
  ts.tt_jd2 = ts.ut1_jd2 + ts.delta_t_s / kSecondsPerDay;
  return ts;
}

}  // namespace daylit::sunmodel
