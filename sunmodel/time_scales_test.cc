#include "sunmodel/time_scales.h"

#include <gtest/gtest.h>

#include "base/error.h"

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

// Days that end with a leap second have 86 401 s; an instant on one is where it is, not stretched
// over the longer day. Julian dates worked out by hand: 1990-12-31 0h UT is JD 2448256.5 and
// 1995-12-31 0h JD 2450082.5 (Meeus, ch. 7); TAI − UTC is 25 s on the first and 29 s on the
// second, one more from the next day (IERS Bulletin C), so TT − UTC = TAI − UTC + 32.184 s.
TEST(TimeScalesTest, LeapSecondDaysKeepTheirInstants) {
  struct Case {
    const char* utc;
    double jd0;         // 0h UT of the date (or of the next day)
    double seconds;     // UT1 − jd0 in seconds, with UT1 − UTC = 0
    double tt_minus_ut1;
  };
  for (const Case& c : {Case{"1990-12-31T22:11:00Z", 2448256.5, 79860.0, 57.184},
                        Case{"1995-12-31T12:00:00Z", 2450082.5, 43200.0, 61.184},
                        Case{"1995-12-31T23:59:59.5Z", 2450082.5, 86399.5, 61.184},
                        // The leap second itself: TAI 1996-01-01T00:00:29.5, less that day's
                        // 29 s of TAI − UTC: UT1 half a second into 1996, TT 61.184 s later.
                        Case{"1995-12-31T23:59:60.5Z", 2450083.5, 0.5, 61.184},
                        Case{"1996-01-01T00:00:00.5Z", 2450083.5, 0.5, 62.184}}) {
    const TimeScales ts = ResolveTimeScales(ParseUtcTime(c.utc, "t"), {std::nullopt, 0.0});
    EXPECT_NEAR(DaysBetween(ts.ut1_jd1, ts.ut1_jd2, c.jd0, 0.0) * 86400.0, c.seconds, 1e-4) << c.utc;
    EXPECT_NEAR(ts.delta_t_s, c.tt_minus_ut1, 1e-4) << c.utc;
  }
  // A 61st second where no leap second is: said, not taken.
  EXPECT_THROW(ResolveTimeScales(ParseUtcTime("2023-03-01T23:59:60Z", "t"), {}), InputError);
  EXPECT_NO_THROW(ResolveTimeScales(ParseUtcTime("2016-12-31T23:59:60.5Z", "t"), {}));
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
