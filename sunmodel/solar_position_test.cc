#include "sunmodel/solar_position.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "base/csv.h"

namespace daylit::sunmodel {
namespace {

// The bar: within 0.001° of every published row with the sun above the horizon (SPA
// itself claims ±0.0003°). Rows published more coarsely (USNO, 0.1°) keep their own tolerance.
constexpr double kBarDeg = 1e-3;

double AngleDiffDeg(double a, double b) { return std::remainder(a - b, 360.0); }

// Inverts SPA eq. 42 by fixed-point iteration: the geometric elevation whose refracted
// elevation is `apparent_deg`.
double GeometricElevationOf(double apparent_deg, const Atmosphere& atmosphere) {
  double e0 = apparent_deg;
  for (int i = 0; i < 50; ++i) e0 = apparent_deg - RefractionDeg(e0, atmosphere);
  return e0;
}

struct RowCheck {
  int rows = 0;
  double worst_zenith_deg = 0.0;
  double worst_azimuth_deg = 0.0;
};

TEST(SolarPositionTest, MatchesEveryPublishedReferenceRow) {
  const CsvTable table =
      ReadCsvFile(DAYLIT_SOURCE_DIR "/sunmodel/testdata/reference_published.csv");
  const int c_utc = table.RequireColumn("utc_iso8601");
  const int c_zen = table.RequireColumn("zenith_deg");
  const int c_az = table.RequireColumn("azimuth_deg_east_of_north");
  RowCheck check;
  for (size_t r = 0; r < table.rows.size(); ++r) {
    const auto& row = table.rows[r];
    const auto number = [&](const char* name, double fallback) {
      const std::string& text = row[static_cast<size_t>(table.RequireColumn(name))];
      return text.empty() ? fallback : ParseFiniteDouble(text, table.Where(r));
    };
    const GeoSite site{number("lat_deg", 0), number("lon_deg", 0), number("elev_m", 0)};
    Atmosphere atmosphere = Atmosphere::Standard(site.elevation_m);
    atmosphere.pressure_hpa = number("pressure_hpa", atmosphere.pressure_hpa);
    atmosphere.temperature_c = number("temp_c", atmosphere.temperature_c);
    EarthOrientation orientation;
    if (!row[static_cast<size_t>(table.RequireColumn("delta_t_s"))].empty()) {
      orientation.delta_t_s = number("delta_t_s", 0);
    }
    orientation.dut1_s = 0.0;  // every source sets UT1 = UTC
    const double tolerance = std::max(kBarDeg, number("tolerance_deg", 0));
    const SunPosition sun = ComputeSunPosition(ParseUtcTime(row[c_utc], table.Where(r)), site,
                                               atmosphere, orientation);
    const double ref_az = ParseFiniteDouble(row[c_az], table.Where(r));
    if (row[c_zen].empty()) {  // azimuth-only rows (sun below the horizon)
      EXPECT_NEAR(AngleDiffDeg(sun.azimuth_deg, ref_az), 0.0, tolerance) << table.Where(r);
      continue;
    }
    const double ref_zen = ParseFiniteDouble(row[c_zen], table.Where(r));
    if (ref_zen >= 90.0) continue;  // sun below the horizon: not a published-accuracy case
    ++check.rows;
    const double az_err = AngleDiffDeg(sun.azimuth_deg, ref_az) * std::sin(ref_zen * M_PI / 180);
    EXPECT_NEAR(az_err, 0.0, tolerance) << table.Where(r) << " azimuth";
    const bool at_bar = tolerance == kBarDeg;  // rows published to the bar or better
    if (at_bar) check.worst_azimuth_deg = std::max(check.worst_azimuth_deg, std::abs(az_err));
    // Geometric zenith: directly for geometric rows, else through the SPA's own refraction.
    const double ref_geometric =
        atmosphere.pressure_hpa == 0.0
            ? ref_zen
            : 90.0 - GeometricElevationOf(90.0 - ref_zen, atmosphere);
    EXPECT_NEAR(sun.zenith_deg, ref_geometric, tolerance) << table.Where(r) << " geometric zenith";
    if (at_bar) {
      check.worst_zenith_deg =
          std::max(check.worst_zenith_deg, std::abs(sun.zenith_deg - ref_geometric));
    }
    if (atmosphere.pressure_hpa > 0.0 && 90.0 - ref_zen > 5.0) {
      EXPECT_NEAR(sun.apparent_zenith_deg, ref_zen, tolerance) << table.Where(r) << " apparent";
    }
  }
  EXPECT_GT(check.rows, 260);  // 4 SPA/pvlib rows + 260 bulk spa.c rows + Tucson
  std::printf("checked %d rows; at the 0.001 deg bar: worst zenith %.2e deg, worst azimuth*sin(z) %.2e deg\n",
              check.rows, check.worst_zenith_deg, check.worst_azimuth_deg);
}

TEST(SolarPositionTest, DeltaTMovesTheSunByTheEarthsRotation) {
  // pvlib's ΔT sensitivity pair: 67 s of ΔT moves the azimuth by 0.00044° here; we must
  // reproduce the shift itself, not only land within the bar.
  const GeoSite site{40.0, -80.0, 0.0};
  const UtcTime t = ParseUtcTime("2019-01-01T00:00:00Z", "t");
  const Atmosphere atm{1013.25, 12.0};
  const double az67 = ComputeSunPosition(t, site, atm, {67.0, 0.0}).azimuth_deg;
  const double az0 = ComputeSunPosition(t, site, atm, {0.0, 0.0}).azimuth_deg;
  EXPECT_NEAR(az0 - az67, 257.2701359 - 257.26969492, 2e-5);
}

TEST(SolarPositionTest, RefractionFollowsSpaEquation42) {
  // SPA Table A5.1: e0 = 39.872046°, Δe = 0.016332° at 820 hPa, 11 °C.
  EXPECT_NEAR(RefractionDeg(39.872046, {820.0, 11.0}), 0.016332, 1e-6);
  EXPECT_EQ(RefractionDeg(30.0, {0.0, 11.0}), 0.0);
  EXPECT_EQ(RefractionDeg(-2.0, {1013.25, 10.0}), 0.0);  // below the SPA's cut-off
  EXPECT_GT(RefractionDeg(0.0, {1013.25, 10.0}), 0.45);  // about half a degree at the horizon
}

TEST(SolarPositionTest, NightAndPolarCasesAreNormalAnswers) {
  const Atmosphere atm = Atmosphere::Standard(0.0);
  // Midnight in Aalborg in December: sun far below the horizon, still a valid position.
  const SunPosition night = ComputeSunPosition(ParseUtcTime("2026-12-21T23:00:00Z", "t"),
                                               {57.0488, 9.9217, 10.0}, atm, {});
  EXPECT_GT(night.zenith_deg, 120.0);
  EXPECT_FALSE(night.AboveHorizon());
  // Midnight sun at Longyearbyen on the June solstice: above the horizon at local midnight.
  const SunPosition midnight_sun = ComputeSunPosition(ParseUtcTime("2026-06-21T22:57:00Z", "t"),
                                                      {78.22, 15.65, 0.0}, atm, {});
  EXPECT_TRUE(midnight_sun.AboveHorizon());
  // Local solar midnight (24 h − 15.65°/15 h): the sun stands due north, 78.22 − 90 + 23.44 ≈
  // 11.7° high.
  EXPECT_NEAR(std::remainder(midnight_sun.azimuth_deg, 360.0), 0.0, 2.0);
  EXPECT_NEAR(midnight_sun.ApparentElevationDeg(), 11.7, 0.5);
}

TEST(SolarPositionTest, DistanceAndDeclinationStayPhysicalOverTwoCenturies) {
  // Any time 1900–2100, any place: the Sun stays 0.983–1.017 au away, and its zenith at
  // noon-ish never beats |latitude − declination| with |declination| ≤ 23.45°.
  std::mt19937 rng(2026);
  std::uniform_real_distribution<double> lat(-90, 90), lon(-180, 180), day(0, 200 * 365.25);
  const int64_t day0 = DaysFromCivil(1900, 1, 1);
  for (int i = 0; i < 2000; ++i) {
    const double d = day(rng);
    UtcTime t;
    CivilFromDays(day0 + static_cast<int64_t>(d), &t.year, &t.month, &t.day);
    const double hours = (d - std::floor(d)) * 24.0;
    t.hour = static_cast<int>(hours);
    t.minute = static_cast<int>((hours - t.hour) * 60.0);
    const GeoSite site{lat(rng), lon(rng), 0.0};
    const SunPosition sun = ComputeSunPosition(t, site, Atmosphere::Standard(0), {});
    ASSERT_GT(sun.distance_au, 0.983);
    ASSERT_LT(sun.distance_au, 1.0171);
    ASSERT_GE(sun.zenith_deg, std::abs(site.latitude_deg) - 23.45 - 1e-6);
    ASSERT_TRUE(sun.azimuth_deg >= 0.0 && sun.azimuth_deg < 360.0);
  }
}

TEST(SolarPositionTest, SiteAndAtmosphereChecksNameTheField) {
  EXPECT_EQ((GeoSite{123.0, 0.0, 0.0}.Check()), "latitude_deg: 123 is outside [-90, 90]");
  EXPECT_NE((GeoSite{0.0, NAN, 0.0}.Check()).find("longitude_deg"), std::string::npos);
  EXPECT_TRUE((GeoSite{57.0, 9.9, 10.0}.Check()).empty());
  EXPECT_NE((Atmosphere{-5.0, 10.0}.Check()).find("pressure_hpa"), std::string::npos);
  // pvlib atmosphere.alt2pres(2000 m) = 79495.54 Pa (SOURCES.md, row group 3).
  EXPECT_NEAR(Atmosphere::Standard(2000.0).pressure_hpa, 794.9554, 0.01);
}

}  // namespace
}  // namespace daylit::sunmodel
