#include "sunmodel/time_scales.h"

#include <gtest/gtest.h>

namespace daylit::sunmodel {
namespace {

double DaysBetween(double a1, double a2, double b1, double b2) { return (a1 - b1) + (a2 - b2); }

TEST(TimeScalesTest, GivenDeltaTIsUsedExactly) {
  const TimeScales ts =
      ResolveTimeScales(ParseUtcTime("2003-10-17T19:30:30Z", "t"), {67.0, 0.0});
  EXPECT_EQ(ts.source, DeltaTSource::kGiven);
  EXPECT_NEAR(DaysBetween(ts.tt_jd1, ts.tt_jd2, ts.ut1_jd1, ts.ut1_jd2) * 86400.0, 67.0, 1e-6);
  // SPA Table A5.1: JD 2452930.312847.
  EXPECT_NEAR(ts.ut1_jd1 + ts.ut1_jd2, 2452930.312847, 1e-6);
}

TEST(TimeScalesTest, LeapSecondTableGivesTtMinusUtcExactly) {
  // Since 2017-01-01, TAI − UTC = 37 s, so TT − UTC = 69.184 s.
  const TimeScales ts = ResolveTimeScales(ParseUtcTime("2026-06-21T05:00:00Z", "t"), {});
  EXPECT_EQ(ts.source, DeltaTSource::kLeapSeconds);
  EXPECT_NEAR(ts.delta_t_s, 69.184, 1e-6);
  EXPECT_DOUBLE_EQ(ts.ut1_uncertainty_s, 0.9);
  // A given UT1 − UTC moves UT1, not TT.
  const TimeScales with_dut1 =
      ResolveTimeScales(ParseUtcTime("2026-06-21T05:00:00Z", "t"), {std::nullopt, 0.25});
  EXPECT_NEAR(with_dut1.delta_t_s, 69.184 - 0.25, 1e-6);
  EXPECT_NEAR(DaysBetween(with_dut1.tt_jd1, with_dut1.tt_jd2, ts.tt_jd1, ts.tt_jd2), 0.0, 1e-11);
  EXPECT_DOUBLE_EQ(with_dut1.ut1_uncertainty_s, 0.0);
}

TEST(TimeScalesTest, ModelAgreesWithObservedDeltaT) {
  // Observed ΔT (IERS / Astronomical Almanac, rounded): 1900.0 −2.7 s, 1950.0 29.15 s,
  // 1980.0 50.54 s, 2000.0 63.83 s. The model must hold them to about a second.
  EXPECT_NEAR(ModelDeltaT(1900.0), -2.7, 1.0);
  EXPECT_NEAR(ModelDeltaT(1950.0), 29.15, 1.0);
  EXPECT_NEAR(ModelDeltaT(1980.0), 50.54, 1.0);
  EXPECT_NEAR(ModelDeltaT(2000.0), 63.83, 1.0);
  // And the leap-second route in its era (|UT1 − UTC| < 0.9 s) must agree with the model.
  for (int year = 1973; year < 2005; ++year) {
    UtcTime t;
    t.year = year;
    t.month = 7;
    const TimeScales ts = ResolveTimeScales(t, {});
    EXPECT_NEAR(ts.delta_t_s, ModelDeltaT(year + 0.5), 1.5) << year;
  }
}

TEST(TimeScalesTest, BeforeUtcTheModelIsUsed) {
  UtcTime t;
  t.year = 1910;
  t.month = 3;
  const TimeScales ts = ResolveTimeScales(t, {});
  EXPECT_EQ(ts.source, DeltaTSource::kHistoricalModel);
  EXPECT_NEAR(ts.delta_t_s, 10.5, 1.5);  // observed ΔT in 1910: about 10.4 s
}

}  // namespace
}  // namespace daylit::sunmodel
