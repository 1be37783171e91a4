// `daylit sunpos --csv`: the sun for every row of a CSV file, a stable interface.
#pragma once

#include <string>

#include "base/csv.h"

namespace daylit::sunmodel {

// Input columns (any order, header required): utc (ISO 8601 with zone), lat_deg, lon_deg,
// elev_m; optional delta_t_s (TT − UT1), dut1_s (UT1 − UTC), pressure_hpa, temp_c (empty cell =
// not given: ΔT from time_scales.h, ICAO standard atmosphere at elev_m). Any other column is
// carried through. Returns the output CSV text: the input columns in their order, then
// zenith_deg (geometric topocentric), apparent_zenith_deg (refracted) and azimuth_deg (east of
// north); input columns with those three names are replaced. Throws InputError naming the file,
// line and column of the first bad value; nothing is returned then.
std::string ComputeSunposCsv(const CsvTable& input);

}  // namespace daylit::sunmodel
