#include "sunmodel/sunpos_batch.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <optional>

#include "base/error.h"
#include "sunmodel/solar_position.h"

namespace daylit::sunmodel {
namespace {

constexpr std::array<std::string_view, 3> kOutputColumns = {"zenith_deg", "apparent_zenith_deg",
                                                            "azimuth_deg"};

struct Columns {
  int utc, lat, lon, elev, delta_t, dut1, pressure, temp;
};

std::optional<double> OptionalNumber(const CsvTable& table, size_t row, int column,
                                     std::string_view name) {
  if (column < 0 || table.rows[row][static_cast<size_t>(column)].empty()) return std::nullopt;
  return ParseFiniteDouble(table.rows[row][static_cast<size_t>(column)],
                           fmt::format("{}: {}", table.Where(row), name));
}

double RequiredNumber(const CsvTable& table, size_t row, int column, std::string_view name) {
  const std::optional<double> value = OptionalNumber(table, row, column, name);
  if (!value) ThrowInputError("{}: {}: empty", table.Where(row), name);
  return *value;
}

SunPosition RowSun(const CsvTable& table, size_t row, const Columns& c) {
  const UtcTime utc = ParseUtcTime(table.rows[row][static_cast<size_t>(c.utc)],
                                   fmt::format("{}: utc", table.Where(row)));
  const GeoSite site{RequiredNumber(table, row, c.lat, "lat_deg"),
                     RequiredNumber(table, row, c.lon, "lon_deg"),
                     RequiredNumber(table, row, c.elev, "elev_m")};
  if (const std::string why = site.Check(); !why.empty()) {
    ThrowInputError("{}: {}", table.Where(row), why);
  }
  Atmosphere atmosphere = Atmosphere::Standard(site.elevation_m);
  if (auto p = OptionalNumber(table, row, c.pressure, "pressure_hpa")) atmosphere.pressure_hpa = *p;
  if (auto t = OptionalNumber(table, row, c.temp, "temp_c")) atmosphere.temperature_c = *t;
  if (const std::string why = atmosphere.Check(); !why.empty()) {
    ThrowInputError("{}: {}", table.Where(row), why);
  }
  EarthOrientation orientation;
  orientation.delta_t_s = OptionalNumber(table, row, c.delta_t, "delta_t_s");
  orientation.dut1_s = OptionalNumber(table, row, c.dut1, "dut1_s");
  return ComputeSunPosition(utc, site, atmosphere, orientation);
}

}  // namespace

std::string ComputeSunposCsv(const CsvTable& input) {
  const Columns c{input.RequireColumn("utc"),      input.RequireColumn("lat_deg"),
                  input.RequireColumn("lon_deg"),  input.RequireColumn("elev_m"),
                  input.Column("delta_t_s"),       input.Column("dut1_s"),
                  input.Column("pressure_hpa"),    input.Column("temp_c")};
  std::vector<size_t> carried;
  for (size_t i = 0; i < input.header.size(); ++i) {
    if (std::find(kOutputColumns.begin(), kOutputColumns.end(), input.header[i]) ==
        kOutputColumns.end()) {
      carried.push_back(i);
    }
  }
  fmt::memory_buffer out;
  for (const size_t i : carried) fmt::format_to(std::back_inserter(out), "{},", CsvField(input.header[i]));
  fmt::format_to(std::back_inserter(out), "{},{},{}\n", kOutputColumns[0], kOutputColumns[1],
                 kOutputColumns[2]);
  for (size_t row = 0; row < input.rows.size(); ++row) {
    const SunPosition sun = RowSun(input, row, c);
    for (const size_t i : carried) {
      fmt::format_to(std::back_inserter(out), "{},", CsvField(input.rows[row][i]));
    }
    fmt::format_to(std::back_inserter(out), "{:.7f},{:.7f},{:.7f}\n", sun.zenith_deg,
                   sun.apparent_zenith_deg, sun.azimuth_deg);
  }
  return fmt::to_string(out);
}

}  // namespace daylit::sunmodel
