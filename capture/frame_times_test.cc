#include "capture/frame_times.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "base/atomic_file.h"
#include "base/error.h"

namespace daylit::capture {
namespace {

namespace fs = std::filesystem;

fs::path WriteTemp(const std::string& name, const std::string& content) {
  const fs::path path = fs::temp_directory_path() / ("daylit_frame_times_" + name + ".csv");
  WriteFileAtomically(path, content);
  return path;
}

std::string ErrorOf(const std::string& content) {
  const fs::path path = WriteTemp("bad", content);
  try {
    LoadFrameTimes(path);
  } catch (const InputError& e) {
    std::string message = e.what();
    return message.substr(path.string().size());  // drop the temp folder
  }
  return "no error";
}

TEST(FrameTimesTest, BundledRecordingHas600FramesOverSixBursts) {
  const FrameTimes times = LoadFrameTimes(DAYLIT_SOURCE_DIR "/recordings/courtyard-a/frames.csv");
  ASSERT_EQ(times.frames.size(), 600u);
  EXPECT_EQ(FormatUtcTime(times.frames[0].utc), "2026-06-21T05:00:00.000Z");
  // Bursts at 07:00 .. 18:00 local (UTC+2): the span is 11 h plus the last burst's 9.9 s.
  EXPECT_NEAR(times.SpanSeconds(), 11 * 3600 + 9.9, 1e-3);
  EXPECT_NEAR(times.ExposureOf(0, 1.0), 0.198425, 1e-9);
}

// The one burst rule: a frame kBurstGapS (2 s) or more after the one before starts a burst, as
// does the first; a clock that steps back (a camera's clock set) does not. courtyard-a's six.
TEST(FrameTimesTest, AFrameTwoSecondsOrMoreAfterTheLastStartsABurst) {
  const UtcTime t = UtcFromUnixSeconds(1.8e9);
  EXPECT_TRUE(StartsBurst(std::optional<UtcTime>{}, t));
  EXPECT_FALSE(StartsBurst(t, UtcFromUnixSeconds(1.8e9 + 1.999)));
  EXPECT_TRUE(StartsBurst(t, UtcFromUnixSeconds(1.8e9 + 2.0)));
  EXPECT_TRUE(StartsBurst(std::optional<UtcTime>(t), UtcFromUnixSeconds(1.8e9 + 3600.0)));
  EXPECT_FALSE(StartsBurst(t, UtcFromUnixSeconds(1.8e9 - 10.0)));
  const FrameTimes times = LoadFrameTimes(DAYLIT_SOURCE_DIR "/recordings/courtyard-a/frames.csv");
  int bursts = 0;
  for (size_t i = 0; i < times.frames.size(); ++i) bursts += i == 0 || StartsBurst(times.frames[i - 1].utc, times.frames[i].utc);
  EXPECT_EQ(bursts, 6);
}

TEST(FrameTimesTest, OptionalExposureFallsBackToCamera) {
  const FrameTimes times = LoadFrameTimes(
      WriteTemp("ok", "frame,time_utc\n0,2026-06-21T05:00:00Z\n1,2026-06-21T05:00:00.1Z\n"));
  EXPECT_DOUBLE_EQ(times.ExposureOf(1, 0.25), 0.25);
  EXPECT_NEAR(times.SpanSeconds(), 0.1, 1e-9);
}

TEST(FrameTimesTest, ErrorsNameLineAndColumn) {
  EXPECT_EQ(ErrorOf("frame,time_utc\n0,2026-06-21T05:00:00\n"),
            ":2: time_utc: time has no zone: append Z for UTC (or an offset such as +02:00) "
            "('2026-06-21T05:00:00')");
  EXPECT_EQ(ErrorOf("frame,time_utc\n0,2026-06-21T05:00:00Z\n2,2026-06-21T05:00:01Z\n"),
            ":3: frame: expected frame 1 (frames are numbered from 0, in order), got 2");
  EXPECT_EQ(ErrorOf("frame,time_utc\n0,2026-06-21T05:00:01Z\n1,2026-06-21T05:00:00Z\n"),
            ":3: time_utc: goes back in time (2026-06-21T05:00:00Z)");
  EXPECT_EQ(ErrorOf("frame,time_utc,exposure\n0,2026-06-21T05:00:00Z,-1\n"),
            ":2: exposure: must be > 0 (got -1)");
  EXPECT_EQ(ErrorOf("frame,time\n0,2026-06-21T05:00:00Z\n"), ": missing column 'time_utc'");
  EXPECT_EQ(ErrorOf("frame,time_utc\n"), ": no frames");
}

}  // namespace
}  // namespace daylit::capture
