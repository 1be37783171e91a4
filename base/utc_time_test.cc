#include "base/utc_time.h"

#include <gtest/gtest.h>

#include <random>

#include "base/error.h"

namespace daylit {
namespace {

TEST(UtcTimeTest, UnixSecondsRoundTrip) {
  EXPECT_EQ(FormatUtcTime(UtcFromUnixSeconds(0.0)), "1970-01-01T00:00:00.000Z");
  EXPECT_EQ(FormatUtcTime(UtcFromUnixSeconds(1700000000.25)), "2023-11-14T22:13:20.250Z");  // a well-known instant
  const UtcTime t = ParseUtcTime("2026-06-21T05:00:00.125Z", "test");
  EXPECT_DOUBLE_EQ(UnixSeconds(t), 1782018000.125);
  EXPECT_EQ(UtcFromUnixSeconds(UnixSeconds(t)).SecondsSince(t), 0.0);
}

TEST(UtcTimeTest, ParsesZuluWithFraction) {
  const UtcTime t = ParseUtcTime("2026-06-21T05:00:00.100Z", "test");
  EXPECT_EQ(t.year, 2026);
  EXPECT_EQ(t.month, 6);
  EXPECT_EQ(t.day, 21);
  EXPECT_EQ(t.hour, 5);
  EXPECT_EQ(t.minute, 0);
  EXPECT_NEAR(t.second, 0.1, 1e-12);
}

TEST(UtcTimeTest, OffsetsAreConvertedToUtcAcrossDayAndYear) {
  const UtcTime t = ParseUtcTime("2027-01-01T01:30:00+02:00", "test");
  EXPECT_EQ(FormatUtcTime(t, 0), "2026-12-31T23:30:00Z");
  const UtcTime w = ParseUtcTime("2003-10-17 12:30:30-0700", "test");
  EXPECT_EQ(FormatUtcTime(w, 0), "2003-10-17T19:30:30Z");
}

TEST(UtcTimeTest, RejectsTimeWithoutZoneAndNamesTheProblem) {
  UtcTime t;
  std::string why;
  EXPECT_FALSE(TryParseUtcTime("2026-06-21T05:00:00", &t, &why));
  EXPECT_NE(why.find("no zone"), std::string::npos) << why;
  try {
    ParseUtcTime("2026-06-21T05:00:00", "frames.csv:3");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("frames.csv:3: ", 0), 0u) << e.what();
  }
}

TEST(UtcTimeTest, RejectsImpossibleDatesAndTimes) {
  UtcTime t;
  std::string why;
  for (const char* bad : {"2026-02-29T00:00:00Z", "2026-13-01T00:00:00Z", "2026-06-21T24:00:00Z",
                          "2026-06-21T12:60:00Z", "2026-06-21T12:00:60Z", "2026-06-21T12:00Z0",
                          "21/06/2026 12:00Z", "", "2026-06-21T12:00:00+25:00"}) {
    EXPECT_FALSE(TryParseUtcTime(bad, &t, &why)) << bad;
  }
  EXPECT_TRUE(TryParseUtcTime("2016-12-31T23:59:60.5Z", &t, &why)) << "leap second: " << why;
  EXPECT_TRUE(TryParseUtcTime("2024-02-29T00:00Z", &t, &why)) << why;
}

TEST(UtcTimeTest, CivilDaysRoundTripOverFiveCenturies) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int64_t> days(DaysFromCivil(1800, 1, 1), DaysFromCivil(2300, 1, 1));
  for (int i = 0; i < 20000; ++i) {
    const int64_t d = days(rng);
    int y = 0, m = 0, dd = 0;
    CivilFromDays(d, &y, &m, &dd);
    ASSERT_EQ(DaysFromCivil(y, m, dd), d);
  }
  EXPECT_EQ(DaysFromCivil(1970, 1, 1), 0);
  EXPECT_EQ(DaysFromCivil(2000, 3, 1) - DaysFromCivil(2000, 2, 28), 2);  // 2000 is leap
  EXPECT_EQ(DaysFromCivil(1900, 3, 1) - DaysFromCivil(1900, 2, 28), 1);  // 1900 is not
}

TEST(UtcTimeTest, FormatRoundsWithoutPrintingSixtySeconds) {
  const UtcTime t = ParseUtcTime("2026-06-21T05:59:59.9996Z", "test");
  EXPECT_EQ(FormatUtcTime(t, 3), "2026-06-21T06:00:00.000Z");
  EXPECT_DOUBLE_EQ(ParseUtcTime("1969-12-31T23:00:00Z", "t")
                       .SecondsSince(ParseUtcTime("1970-01-01T00:00:00Z", "t")),
                   -3600.0);
  EXPECT_DOUBLE_EQ(ParseUtcTime("2026-06-21T16:00:09.9Z", "t")
                       .SecondsSince(ParseUtcTime("2026-06-21T05:00:00Z", "t")),
                   11 * 3600 + 9.9);
}

}  // namespace
}  // namespace daylit
