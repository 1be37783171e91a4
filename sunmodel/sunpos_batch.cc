#include "sunmodel/sunpos_batch.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <numeric>
#include <vector>
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

// Error locations are formatted only when a value is bad: this runs for every field of every row.
std::optional<double> OptionalNumber(const CsvTable& table, size_t row, int column,
                                     std::string_view name) {
  if (column < 0) return std::nullopt;
  const std::string& text = table.rows[row][static_cast<size_t>(column)];
  if (text.empty()) return std::nullopt;
  double value = 0.0;
  if (!TryParseFiniteDouble(text, &value)) {
    ThrowInputError("{}: {}: '{}' is not a finite number", table.Where(row), name, text);
  }
  return value;
}

double RequiredNumber(const CsvTable& table, size_t row, int column, std::string_view name) {
  const std::optional<double> value = OptionalNumber(table, row, column, name);
  if (!value) ThrowInputError("{}: {}: empty", table.Where(row), name);
  return *value;
}

struct RowInput {
  UtcTime utc;
  GeoSite site;
  Atmosphere atmosphere;
  EarthOrientation orientation;
};

RowInput ParseRow(const CsvTable& table, size_t row, const Columns& c) {
  RowInput in;
  const std::string& utc_text = table.rows[row][static_cast<size_t>(c.utc)];
  std::string parse_error;
  if (!TryParseUtcTime(utc_text, &in.utc, &parse_error)) {
    ThrowInputError("{}: utc: {} ('{}')", table.Where(row), parse_error, utc_text);
  }
  in.site = {RequiredNumber(table, row, c.lat, "lat_deg"), RequiredNumber(table, row, c.lon, "lon_deg"),
             RequiredNumber(table, row, c.elev, "elev_m")};
  if (const std::string why = in.site.Check(); !why.empty()) {
    ThrowInputError("{}: {}", table.Where(row), why);
  }
  const std::optional<double> pressure = OptionalNumber(table, row, c.pressure, "pressure_hpa");
  const std::optional<double> temperature = OptionalNumber(table, row, c.temp, "temp_c");
  // The standard atmosphere (two pow calls) only where a value is missing.
  in.atmosphere = {pressure.value_or(0.0), temperature.value_or(0.0)};
  if (!pressure || !temperature) {
    const Atmosphere standard = Atmosphere::Standard(in.site.elevation_m);
    in.atmosphere = {pressure.value_or(standard.pressure_hpa),
                     temperature.value_or(standard.temperature_c)};
  }
  if (const std::string why = in.atmosphere.Check(); !why.empty()) {
    ThrowInputError("{}: {}", table.Where(row), why);
  }
  in.orientation.delta_t_s = OptionalNumber(table, row, c.delta_t, "delta_t_s");
  in.orientation.dut1_s = OptionalNumber(table, row, c.dut1, "dut1_s");
  if (const std::string why = in.orientation.Check(); !why.empty()) ThrowInputError("{}: {}", table.Where(row), why);
  return in;
}

// Positions of all rows, computed in time order: ERFA's series evaluate ~1500 sin/cos per call,
// and glibc's sincos branches on the size of its argument, so rows in random time order
// mispredict those branches and run ~1.5x slower than the same rows sorted
// (docs/sunmodel.md, "Speed").
std::vector<SunPosition> ComputeInTimeOrder(const std::vector<RowInput>& inputs) {
  std::vector<size_t> order(inputs.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return inputs[a].utc.SecondsSince(inputs[b].utc) < 0.0;
  });
  std::vector<SunPosition> out(inputs.size());
  for (const size_t i : order) {
    out[i] = ComputeSunPosition(inputs[i].utc, inputs[i].site, inputs[i].atmosphere, inputs[i].orientation);
  }
  return out;
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
  std::vector<RowInput> inputs;
  inputs.reserve(input.rows.size());
  for (size_t row = 0; row < input.rows.size(); ++row) inputs.push_back(ParseRow(input, row, c));
  const std::vector<SunPosition> suns = ComputeInTimeOrder(inputs);
  for (size_t row = 0; row < input.rows.size(); ++row) {
    const SunPosition& sun = suns[row];
    for (const size_t i : carried) {
      fmt::format_to(std::back_inserter(out), "{},", CsvField(input.rows[row][i]));
    }
    fmt::format_to(std::back_inserter(out), "{:.7f},{:.7f},{:.7f}\n", sun.zenith_deg,
                   sun.apparent_zenith_deg, sun.azimuth_deg);
  }
  return fmt::to_string(out);
}

}  // namespace daylit::sunmodel
