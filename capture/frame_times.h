// frames.csv of a recording: `frame,time_utc[,exposure]`, one row per frame, in order.
#pragma once

#include <filesystem>
#include <optional>
#include <vector>

#include "base/utc_time.h"

namespace daylit::capture {

// A recording may come in bursts (a time-lapse of short clips): frames this far apart or more
// start a new one. The estimate's per-burst table and the shadow calibration split alike.
constexpr double kBurstGapS = 2.0;

// The one rule every per-burst split uses (the report's table, info, the residuals, the split
// check, the shadow calibration, the sun's colour): a frame at `utc` starts a new burst when it is
// kBurstGapS or more after the frame before it, or when there was none.
inline bool StartsBurst(const UtcTime& previous, const UtcTime& utc) {
  return !(utc.SecondsSince(previous) < kBurstGapS);
}
inline bool StartsBurst(const std::optional<UtcTime>& previous, const UtcTime& utc) {
  return !previous || StartsBurst(*previous, utc);
}

struct FrameTime {
  int index = 0;
  UtcTime utc;
  std::optional<double> exposure;  // per-frame multiplier k (linear pixel = k · radiance)
};

struct FrameTimes {
  std::filesystem::path file;
  std::vector<FrameTime> frames;

  // Seconds from the first to the last frame (0 for fewer than 2 frames).
  double SpanSeconds() const;
  // Exposure of frame i: its own, else `fallback` (camera.exposure).
  double ExposureOf(size_t i, double fallback) const;
};

// Reads and validates frames.csv: frame indices 0, 1, 2, ... in order, times with a zone and
// never going backwards, exposures finite and > 0. Throws InputError naming file, line and column.
FrameTimes LoadFrameTimes(const std::filesystem::path& csv);

}  // namespace daylit::capture
