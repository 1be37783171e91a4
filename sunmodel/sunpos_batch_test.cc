#include "sunmodel/sunpos_batch.h"

#include <gtest/gtest.h>

#include "base/error.h"

namespace daylit::sunmodel {
namespace {

TEST(SunposBatchTest, ColumnsInAnyOrderAndUnknownOnesCarriedThrough) {
  const std::string out = ComputeSunposCsv(ParseCsv(
      "site,elev_m,utc,lon_deg,lat_deg,delta_t_s,pressure_hpa,temp_c,dut1_s\n"
      "\"Golden, CO\",1830.14,2003-10-17T19:30:30Z,-105.1786,39.742476,67,820,11,0\n",
      "in.csv"));
  const CsvTable table = ParseCsv(out, "out.csv");
  ASSERT_EQ(table.rows.size(), 1u);
  EXPECT_EQ(table.header.front(), "site");
  EXPECT_EQ(table.rows[0][0], "Golden, CO");
  const auto value = [&](const char* name) {
    return ParseFiniteDouble(table.rows[0][static_cast<size_t>(table.RequireColumn(name))], name);
  };
  EXPECT_NEAR(value("zenith_deg"), 50.127954, 1e-3);
  EXPECT_NEAR(value("apparent_zenith_deg"), 50.111622, 1e-3);
  EXPECT_NEAR(value("azimuth_deg"), 194.340241, 1e-3);
}

TEST(SunposBatchTest, OptionalColumnsMayBeAbsentOrEmptyAndOutputsAreReplaced) {
  const std::string out = ComputeSunposCsv(ParseCsv(
      "utc,lat_deg,lon_deg,elev_m,zenith_deg,delta_t_s\n"
      "2026-06-21T11:00:00Z,57.0488,9.9217,10,999,\n",
      "in.csv"));
  const CsvTable table = ParseCsv(out, "out.csv");
  EXPECT_EQ(table.header.size(), 8u);  // 5 carried + 3 computed, the stale zenith dropped
  const double zen = ParseFiniteDouble(table.rows[0][static_cast<size_t>(table.RequireColumn("zenith_deg"))], "z");
  EXPECT_NEAR(zen, 90.0 - 56.4, 0.5);  // Aalborg, summer solstice, 13:00 local: ~56° high
}

TEST(SunposBatchTest, BadRowsNameFileLineAndColumn) {
  const auto error_of = [](const std::string& csv) {
    try {
      ComputeSunposCsv(ParseCsv(csv, "in.csv"));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error_of("utc,lat_deg,lon_deg,elev_m\n2026-06-21T11:00:00Z,123,9,0\n"),
            "in.csv:2: latitude_deg: 123 is outside [-90, 90]");
  EXPECT_EQ(error_of("utc,lat_deg,lon_deg,elev_m\n2026-06-21T11:00:00,57,9,0\n"),
            "in.csv:2: utc: time has no zone: append Z for UTC (or an offset such as +02:00) "
            "('2026-06-21T11:00:00')");
  EXPECT_EQ(error_of("utc,lat_deg,lon_deg,elev_m\n2026-06-21T11:00:00Z,57,abc,0\n"),
            "in.csv:2: lon_deg: 'abc' is not a finite number");
  EXPECT_EQ(error_of("utc,lat_deg,elev_m\n2026-06-21T11:00:00Z,57,0\n"),
            "in.csv: missing column 'lon_deg'");
}

}  // namespace
}  // namespace daylit::sunmodel
