#include "sunmodel/solar_position.h"

#include <erfa.h>
#include <erfam.h>

#include <cmath>

#include <fmt/format.h>

namespace daylit::sunmodel {
namespace {

constexpr double kDegPerRad = 180.0 / ERFA_DPI;

std::string OutOfRange(const char* field, double value, double lo, double hi) {
  if (!std::isfinite(value)) return fmt::format("{}: not a finite number", field);
  if (value < lo || value > hi) return fmt::format("{}: {} is outside [{}, {}]", field, value, lo, hi);
  return {};
}

}  // namespace

std::string GeoSite::Check() const {
  for (std::string why : {OutOfRange("latitude_deg", latitude_deg, -90.0, 90.0),
                          OutOfRange("longitude_deg", longitude_deg, -180.0, 180.0),
                          OutOfRange("elevation_m", elevation_m, -1000.0, 20000.0)}) {
    if (!why.empty()) return why;
  }
  return {};
}

Atmosphere Atmosphere::Standard(double elevation_m) {
  const double h = std::max(elevation_m, -1000.0);
  return Atmosphere{1013.25 * std::pow(1.0 - 2.25577e-5 * h, 5.25588), 15.0 - 0.0065 * h};
}

std::string Atmosphere::Check() const {
  std::string why = OutOfRange("pressure_hpa", pressure_hpa, 0.0, 1200.0);
  return why.empty() ? OutOfRange("temp_c", temperature_c, -90.0, 60.0) : why;
}

double RefractionDeg(double e0, const Atmosphere& atmosphere) {
  constexpr double kSunRadiusDeg = 0.26667;
  constexpr double kHorizonRefractionDeg = 0.5667;
  if (atmosphere.pressure_hpa <= 0.0 || e0 < -(kSunRadiusDeg + kHorizonRefractionDeg)) return 0.0;
  const double arg_deg = e0 + 10.3 / (e0 + 5.11);
  return (atmosphere.pressure_hpa / 1010.0) * (283.0 / (273.0 + atmosphere.temperature_c)) * 1.02 /
         (60.0 * std::tan(arg_deg / kDegPerRad));
}

SunPosition ComputeSunPosition(const UtcTime& utc, const GeoSite& site,
                               const Atmosphere& atmosphere, const EarthOrientation& orientation) {
  SunPosition sun;
  sun.time = ResolveTimeScales(utc, orientation);
  const TimeScales& ts = sun.time;

  // Earth's heliocentric and barycentric position/velocity (TDB ≈ TT to 2 ms).
  double earth_helio[2][3], earth_bary[2][3];
  eraEpv00(ts.tt_jd1, ts.tt_jd2, earth_helio, earth_bary);
  // CIP X, Y and CIO locator s from IAU 2000B nutation: within 1 mas of 2000A, at half the cost.
  double x = 0.0, y = 0.0, s = 0.0;
  eraXys00b(ts.tt_jd1, ts.tt_jd2, &x, &y, &s);
  const double era = eraEra00(ts.ut1_jd1, ts.ut1_jd2);
  const double sp = eraSp00(ts.tt_jd1, ts.tt_jd2);
  // Star-independent parameters for this observer; refraction constants 0 (we add our own).
  eraASTROM astrom;
  eraApco(ts.tt_jd1, ts.tt_jd2, earth_bary, earth_helio[0], x, y, s, era,
          site.longitude_deg / kDegPerRad, site.latitude_deg / kDegPerRad, site.elevation_m,
          0.0, 0.0, sp, 0.0, 0.0, &astrom);

  // Sun as seen from the observer (eh points Sun -> observer, so parallax is included), then
  // aberration (observer's barycentric velocity) and the bias-precession-nutation to CIRS.
  double to_sun[3] = {-astrom.eh[0], -astrom.eh[1], -astrom.eh[2]};
  double aberrated[3], cirs[3];
  eraAb(to_sun, astrom.v, astrom.em, astrom.bm1, aberrated);
  eraRxp(astrom.bpn, aberrated, cirs);
  double ri = 0.0, di = 0.0;
  eraC2s(cirs, &ri, &di);
  double aob = 0.0, zob = 0.0, hob = 0.0, dob = 0.0, rob = 0.0;
  eraAtioq(ri, di, &astrom, &aob, &zob, &hob, &dob, &rob);

  sun.zenith_deg = zob * kDegPerRad;
  sun.azimuth_deg = std::fmod(aob * kDegPerRad + 360.0, 360.0);
  sun.distance_au = astrom.em;
  sun.apparent_zenith_deg = sun.zenith_deg - RefractionDeg(90.0 - sun.zenith_deg, atmosphere);
  return sun;
}

}  // namespace daylit::sunmodel
