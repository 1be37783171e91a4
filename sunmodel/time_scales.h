// From a UTC timestamp to the time scales the ephemeris needs: UT1 (Earth rotation) and TT
// (the Sun's orbital position). ΔT = TT − UT1 matters: 1 s of UT1 is 0.004° of sun.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "base/utc_time.h"

namespace daylit::sunmodel {

// What the caller knows about Earth's rotation for this instant; both optional.
struct EarthOrientation {
  std::optional<double> delta_t_s;  // TT − UT1 in seconds
  std::optional<double> dut1_s;     // UT1 − UTC in seconds; absent means 0
  // Empty when plausible, else the problem naming the field as the caller spells it (a CSV
  // column, a command-line option): |dut1| < 0.9 s (the IERS keeps UTC so), ΔT finite within
  // [−1000, 20000] s (about −500 to 3000 CE by Morrison & Stephenson).
  std::string Check(std::string_view delta_t_name = "delta_t_s", std::string_view dut1_name = "dut1_s") const;
};

enum class DeltaTSource {
  kGiven,            // delta_t_s was given
  kLeapSeconds,      // 1960 on: TT − UTC from ERFA's leap-second table, UT1 = UTC + dut1
  kHistoricalModel,  // 1800–1960: Espenak & Meeus (2006) polynomials, input taken as UT1
  kLongTermModel,    // outside: Morrison & Stephenson (2004) parabola, seconds to minutes off
};

std::string_view DeltaTSourceName(DeltaTSource source);

struct TimeScales {
  double ut1_jd1 = 0.0, ut1_jd2 = 0.0;  // two-part Julian date, UT1
  double tt_jd1 = 0.0, tt_jd2 = 0.0;    // two-part Julian date, TT
  double delta_t_s = 0.0;               // TT − UT1 actually used
  DeltaTSource source = DeltaTSource::kGiven;
  // Bound on the UT1 error in seconds when nothing was given (0 when delta_t_s was given);
  // multiply by 0.00417 for degrees of sun. See docs/sunmodel.md.
  double ut1_uncertainty_s = 0.0;
};

// Resolves UT1 and TT for `utc`. Never fails for a valid UtcTime.
TimeScales ResolveTimeScales(const UtcTime& utc, const EarthOrientation& orientation);

// ΔT (TT − UT1, seconds) from Espenak & Meeus, "Five Millennium Canon of Solar Eclipses"
// (NASA/TP-2006-214141), polynomial expressions, for a decimal year in 1800–2005; outside that,
// Morrison & Stephenson (2004) −20 + 32·u², u = (year − 1820)/100.
double ModelDeltaT(double decimal_year);

}  // namespace daylit::sunmodel
