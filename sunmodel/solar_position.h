// Topocentric position of the Sun for a UTC instant and a WGS84 site, from ERFA (the IAU SOFA
// line: IAU 2006 precession with IAU 2000B nutation, VSOP2000-fitted Earth ephemeris eraEpv00,
// annual + diurnal aberration, topocentric parallax). Refraction is the Bennett / Saemundsson
// formula as published in the NREL SPA (Reda & Andreas 2004, eq. 42).
#pragma once

#include <string>

#include "base/utc_time.h"
#include "sunmodel/time_scales.h"

namespace daylit::sunmodel {

struct GeoSite {
  double latitude_deg = 0.0;   // WGS84 geodetic latitude, north positive, [-90, 90]
  double longitude_deg = 0.0;  // east positive, [-180, 180]
  double elevation_m = 0.0;    // height above the WGS84 ellipsoid, [-1000, 20000]

  // Empty when valid; otherwise the reason, naming the field ("latitude_deg: 123 is outside
  // [-90, 90]").
  std::string Check() const;
};

struct Atmosphere {
  double pressure_hpa = 1013.25;  // station pressure; 0 turns refraction off
  double temperature_c = 15.0;    // air temperature at the site

  // ICAO standard atmosphere at `elevation_m` (barometric formula, 6.5 K/km lapse rate).
  static Atmosphere Standard(double elevation_m);
  std::string Check() const;  // pressure in [0, 1200] hPa, temperature in [-90, 60] °C
};

struct SunPosition {
  double zenith_deg = 0.0;           // geometric topocentric zenith angle of the Sun's centre
  double apparent_zenith_deg = 0.0;  // with atmospheric refraction
  double azimuth_deg = 0.0;          // east of north, [0, 360)
  double distance_au = 0.0;          // observer to Sun
  TimeScales time;                   // the UT1/TT actually used

  double ApparentElevationDeg() const { return 90.0 - apparent_zenith_deg; }
  // True while any part of the disc is above the horizon (apparent elevation > −0.8333°).
  bool AboveHorizon() const { return ApparentElevationDeg() > -0.8333; }
};

// Sun position for `utc` at `site`. Pure; never fails for inputs whose Check() is empty.
SunPosition ComputeSunPosition(const UtcTime& utc, const GeoSite& site,
                               const Atmosphere& atmosphere, const EarthOrientation& orientation);

// Refraction (degrees, to add to the elevation) for a geometric elevation, SPA eq. 42:
// Δe = P/1010 · 283/(273+T) · 1.02 / (60 · tan(e0 + 10.3/(e0 + 5.11))), applied while
// e0 ≥ −(0.26667° + 0.5667°) (the SPA's sun radius + horizon refraction); 0 below.
double RefractionDeg(double geometric_elevation_deg, const Atmosphere& atmosphere);

}  // namespace daylit::sunmodel
