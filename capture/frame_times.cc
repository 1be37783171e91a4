#include "capture/frame_times.h"

#include "base/csv.h"
#include "base/error.h"

namespace daylit::capture {

double FrameTimes::SpanSeconds() const {
  if (frames.size() < 2) return 0.0;
  return frames.back().utc.SecondsSince(frames.front().utc);
}

double FrameTimes::ExposureOf(size_t i, double fallback) const {
  return frames.at(i).exposure.value_or(fallback);
}

FrameTimes LoadFrameTimes(const std::filesystem::path& csv) {
  const CsvTable table = ReadCsvFile(csv);
  const size_t c_frame = static_cast<size_t>(table.RequireColumn("frame"));
  const size_t c_time = static_cast<size_t>(table.RequireColumn("time_utc"));
  const int c_exposure = table.Column("exposure");
  FrameTimes out;
  out.file = csv;
  out.frames.reserve(table.rows.size());
  for (size_t r = 0; r < table.rows.size(); ++r) {
    const auto& row = table.rows[r];
    const std::string where = table.Where(r);
    FrameTime f;
    const double index = ParseFiniteDouble(row[c_frame], where + ": frame");
    if (index != static_cast<double>(r)) {
      ThrowInputError("{}: frame: expected frame {} (frames are numbered from 0, in order), got {}",
                      where, r, row[c_frame]);
    }
    f.index = static_cast<int>(r);
    f.utc = ParseUtcTime(row[c_time], where + ": time_utc");
    if (r > 0 && f.utc.SecondsSince(out.frames.back().utc) < 0.0) {
      ThrowInputError("{}: time_utc: goes back in time ({})", where, row[c_time]);
    }
    if (c_exposure >= 0 && !row[static_cast<size_t>(c_exposure)].empty()) {
      const double k = ParseFiniteDouble(row[static_cast<size_t>(c_exposure)], where + ": exposure");
      if (k <= 0.0) ThrowInputError("{}: exposure: must be > 0 (got {})", where, k);
      f.exposure = k;
    }
    out.frames.push_back(f);
  }
  if (out.frames.empty()) ThrowInputError("{}: no frames", csv.string());
  return out;
}

}  // namespace daylit::capture
