// The window's time slider: the solar day it spans at any longitude, the instant it relights a
// frame to, the keys' steps and the bar's clicks.
#include "render/time_slider.h"

#include <gtest/gtest.h>

#include "base/error.h"

namespace daylit::render {
namespace {

UtcTime At(const char* text) { return ParseUtcTime(text, "test"); }

void ExpectSameInstant(const std::optional<UtcTime>& got, const char* want) {
  ASSERT_TRUE(got.has_value());
  EXPECT_NEAR(UnixSeconds(*got), UnixSeconds(At(want)), 1e-3) << FormatUtcTime(*got) << " vs " << want;
}

TEST(TimeSliderTest, OffUntilSet) {
  TimeSlider slider(0.0);
  EXPECT_FALSE(slider.active());
  EXPECT_FALSE(slider.Target(At("2026-06-21T09:12:00Z")).has_value());
  slider.SetUtcMinutes(18 * 60 + 30);
  EXPECT_TRUE(slider.active());
  slider.Off();
  EXPECT_FALSE(slider.Target(At("2026-06-21T09:12:00Z")).has_value());
}

TEST(TimeSliderTest, AUtcTimeOfDayOnTheFramesOwnSolarDay) {
  // At Greenwich the solar day is the UTC day.
  TimeSlider greenwich(0.0);
  greenwich.SetUtcMinutes(18 * 60 + 30);
  ExpectSameInstant(greenwich.Target(At("2026-06-21T09:12:00Z")), "2026-06-21T18:30:00Z");
  EXPECT_DOUBLE_EQ(*greenwich.solar_minutes(), 18 * 60 + 30);
  // 150° east, solar time is UTC + 10 h: 22:00Z on the 21st is 08:00 on the 22nd, whose noon is
  // 02:00Z on the 22nd. A UTC day would have split this site's day in two.
  TimeSlider east(150.0);
  east.SetUtcMinutes(2 * 60);
  EXPECT_DOUBLE_EQ(*east.solar_minutes(), 12 * 60);
  ExpectSameInstant(east.Target(At("2026-06-21T22:00:00Z")), "2026-06-22T02:00:00Z");
  ExpectSameInstant(east.Target(At("2026-06-22T13:59:00Z")), "2026-06-22T02:00:00Z");  // 23:59 solar on the 22nd
  ExpectSameInstant(east.Target(At("2026-06-22T14:01:00Z")), "2026-06-23T02:00:00Z");  // 00:01 on the 23rd
  // 120° west, UTC − 8 h: 03:00Z on the 21st is 19:00 on the 20th.
  TimeSlider west(-120.0);
  west.SetUtcMinutes(20 * 60);
  ExpectSameInstant(west.Target(At("2026-06-21T03:00:00Z")), "2026-06-20T20:00:00Z");
}

TEST(TimeSliderTest, FractionOfTheBar) {
  TimeSlider slider(15.0);  // solar time UTC + 1 h
  EXPECT_NEAR(slider.Fraction(At("2026-06-21T05:00:00Z")), 0.25, 1e-9);
  EXPECT_NEAR(slider.Fraction(At("2026-06-21T23:00:00Z")), 0.0, 1e-9);
  ExpectSameInstant(slider.AtFraction(At("2026-06-21T09:00:00Z"), 0.5), "2026-06-21T11:00:00Z");
  // A click at the middle of the bar is solar noon; clicks keep to whole 5 minutes.
  slider.SetFraction(0.5);
  ExpectSameInstant(slider.Target(At("2026-06-21T09:00:00Z")), "2026-06-21T11:00:00Z");
  slider.SetFraction(0.5017);  // 722.4 min
  EXPECT_DOUBLE_EQ(*slider.solar_minutes(), 720.0);
  slider.SetFraction(1.7);
  EXPECT_DOUBLE_EQ(*slider.solar_minutes(), 1440.0);
  slider.SetFraction(-0.2);
  EXPECT_DOUBLE_EQ(*slider.solar_minutes(), 0.0);
}

TEST(TimeSliderTest, ArrowStepsStartAtTheFramesTime) {
  TimeSlider slider(0.0);
  const UtcTime frame = At("2026-06-21T09:12:00Z");
  slider.Step(15, frame);  // from off: 09:15 (the frame's time on the step), then a step
  ExpectSameInstant(slider.Target(frame), "2026-06-21T09:30:00Z");
  slider.Step(-60, frame);
  ExpectSameInstant(slider.Target(frame), "2026-06-21T08:30:00Z");
  for (int i = 0; i < 30; ++i) slider.Step(60, frame);
  EXPECT_DOUBLE_EQ(*slider.solar_minutes(), 1440.0);  // the day's end, not the next day
  for (int i = 0; i < 30; ++i) slider.Step(-60, frame);
  EXPECT_DOUBLE_EQ(*slider.solar_minutes(), 0.0);
}

TEST(TimeSliderTest, TimeOfDayParsing) {
  EXPECT_DOUBLE_EQ(ParseUtcTimeOfDay("18:30", "--relight-at"), 1110.0);
  EXPECT_DOUBLE_EQ(ParseUtcTimeOfDay("00:00Z", "--relight-at"), 0.0);
  EXPECT_DOUBLE_EQ(ParseUtcTimeOfDay("23:59", "--relight-at"), 1439.0);
  for (const char* bad : {"24:00", "18:60", "1:30", "18:3x", "", "-1:30", "18-30", "18:30:00"}) {
    try {
      ParseUtcTimeOfDay(bad, "--relight-at");
      ADD_FAILURE() << bad << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--relight-at: '"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace daylit::render
