#include <chrono>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "apps/daylit/commands.h"
#include "base/atomic_file.h"
#include "base/csv.h"
#include "base/error.h"
#include "base/log.h"
#include "report/plot.h"
#include "scene/scene.h"
#include "sunmodel/geo_frame.h"
#include "sunmodel/solar_position.h"
#include "sunmodel/sunpos_batch.h"

namespace daylit::app {
namespace {

struct SunposOptions {
  std::string time;
  std::optional<double> lat, lon;
  double elev = 0.0;
  std::optional<double> pressure_hpa, temp_c, delta_t_s, dut1_s;
  std::string scene;
  bool frames = false;
  std::string csv_in;
  std::string out;
  std::string plot;
};

sunmodel::Atmosphere AtmosphereFor(const SunposOptions& o, double elevation_m) {
  sunmodel::Atmosphere atmosphere = sunmodel::Atmosphere::Standard(elevation_m);
  if (o.pressure_hpa) atmosphere.pressure_hpa = *o.pressure_hpa;
  if (o.temp_c) atmosphere.temperature_c = *o.temp_c;
  if (const std::string why = atmosphere.Check(); !why.empty()) ThrowInputError("--{}", why);
  return atmosphere;
}

void WriteOrPrint(const std::string& out, const std::string& text) {
  if (out.empty()) {
    fmt::print("{}", text);
  } else {
    WriteFileAtomically(out, text);
    Log().info("wrote {}", out);
  }
}

void RunBatch(const SunposOptions& o) {
  const CsvTable input = ReadCsvFile(o.csv_in);
  const auto start = std::chrono::steady_clock::now();
  const std::string output = sunmodel::ComputeSunposCsv(input);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  WriteOrPrint(o.out, output);
  Log().info("{} positions in {:.3f} s ({:.0f}/s)", input.rows.size(), seconds,
             static_cast<double>(input.rows.size()) / std::max(seconds, 1e-9));
}

// Elevation and azimuth over the recording's time span (every 5 min, a line) with the frames
// as dots, against hours (UTC) of the first frame's day.
void PlotSunPath(const scene::Scene& scene, const sunmodel::Atmosphere& atmosphere, const SunposOptions& o,
                 const std::string& path) {
  const std::vector<capture::FrameTime>& frames = scene.frame_times->frames;
  const UtcTime day_start{frames.front().utc.year, frames.front().utc.month, frames.front().utc.day, 0, 0, 0.0};
  const auto sun_at = [&](const UtcTime& t) {
    return sunmodel::ComputeSunPosition(t, scene.location, atmosphere, {o.delta_t_s, o.dut1_s});
  };
  report::Series path_elevation{"sun", {}, {}, report::SeriesColor(1), false, false};
  report::Series path_azimuth{"sun", {}, {}, report::SeriesColor(0), false, false};
  const double span_s = scene.frame_times->SpanSeconds();
  for (double t = 0.0; t <= span_s + 1e-9; t += std::min(300.0, std::max(span_s, 1.0) / 2.0)) {
    // POSIX steps: a leap second inside the span moves the line's points by 1 s, not the dots.
    const UtcTime at = UtcFromUnixSeconds(UnixSeconds(frames.front().utc) + t);
    const sunmodel::SunPosition sun = sun_at(at);
    path_elevation.x.push_back(at.SecondsSince(day_start) / 3600.0);
    path_elevation.y.push_back(sun.ApparentElevationDeg());
    path_azimuth.x.push_back(path_elevation.x.back());
    path_azimuth.y.push_back(sun.azimuth_deg);
  }
  report::Series frame_elevation{"frames", {}, {}, {40, 40, 40}, false, true};
  report::Series frame_azimuth = frame_elevation;
  for (const capture::FrameTime& f : frames) {
    const sunmodel::SunPosition sun = sun_at(f.utc);
    frame_elevation.x.push_back(f.utc.SecondsSince(day_start) / 3600.0);
    frame_elevation.y.push_back(sun.ApparentElevationDeg());
    frame_azimuth.x.push_back(frame_elevation.x.back());
    frame_azimuth.y.push_back(sun.azimuth_deg);
  }
  const std::string date = FormatUtcTime(day_start, 0).substr(0, 10);
  report::LinePlot top({fmt::format("Sun over {} ({} frames)", scene.name, frames.size()), "",
                        "apparent elevation, deg", 1200, 320, true});
  top.Add(std::move(path_elevation));
  top.Add(std::move(frame_elevation));
  report::LinePlot bottom({"", fmt::format("hours UTC on {}", date), "azimuth east of north, deg", 1200, 320, false});
  bottom.Add(std::move(path_azimuth));
  bottom.Add(std::move(frame_azimuth));
  report::WritePng(path, {top.Render(), bottom.Render()});
}

void RunFrames(const SunposOptions& o, const scene::Scene& scene) {
  if (!scene.frame_times) ThrowInputError("{}: frames: a live device has no timestamps", scene.file.string());
  const sunmodel::SceneGeoFrame frame = scene.GeoFrame();
  const sunmodel::Atmosphere atmosphere = AtmosphereFor(o, scene.location.elevation_m);
  fmt::memory_buffer out;
  fmt::format_to(std::back_inserter(out),
                 "frame,time_utc,zenith_deg,apparent_zenith_deg,azimuth_deg,elevation_deg,"
                 "sun_x,sun_y,sun_z\n");
  for (const capture::FrameTime& f : scene.frame_times->frames) {
    const sunmodel::SunPosition sun =
        sunmodel::ComputeSunPosition(f.utc, scene.location, atmosphere, {o.delta_t_s, o.dut1_s});
    const glm::dvec3 d = frame.DirectionInScene(sun.azimuth_deg, sun.apparent_zenith_deg);
    fmt::format_to(std::back_inserter(out), "{},{},{:.6f},{:.6f},{:.6f},{:.6f},{:.7f},{:.7f},{:.7f}\n",
                   f.index, FormatUtcTime(f.utc), sun.zenith_deg, sun.apparent_zenith_deg,
                   sun.azimuth_deg, sun.ApparentElevationDeg(), d.x, d.y, d.z);
  }
  WriteOrPrint(o.out, fmt::to_string(out));
  if (!o.plot.empty()) {
    PlotSunPath(scene, atmosphere, o, o.plot);
    Log().info("wrote {}", o.plot);
  }
}

void RunSingle(const SunposOptions& o, const std::optional<scene::Scene>& scene) {
  const UtcTime utc = ParseUtcTime(o.time, "--time");
  sunmodel::GeoSite site;
  if (scene) {
    site = scene->location;
  } else {
    site = {*o.lat, *o.lon, o.elev};
    if (const std::string why = site.Check(); !why.empty()) ThrowInputError("--{}", why);
  }
  const sunmodel::Atmosphere atmosphere = AtmosphereFor(o, site.elevation_m);
  const sunmodel::SunPosition sun =
      sunmodel::ComputeSunPosition(utc, site, atmosphere, {o.delta_t_s, o.dut1_s});
  std::string text = fmt::format(
      "time_utc             {}\n"
      "site                 {:.6f} N, {:.6f} E, {:.1f} m\n"
      "atmosphere           {:.1f} hPa, {:.1f} C\n"
      "zenith_deg           {:.6f}  (geometric, topocentric)\n"
      "apparent_zenith_deg  {:.6f}  (with refraction)\n"
      "elevation_deg        {:.6f}  (apparent)\n"
      "azimuth_deg          {:.6f}  (east of north)\n"
      "delta_t_s            {:.3f}  ({}; UT1 uncertainty {:.1f} s = {:.4f} deg)\n"
      "above_horizon        {}\n",
      FormatUtcTime(utc), site.latitude_deg, site.longitude_deg, site.elevation_m,
      atmosphere.pressure_hpa, atmosphere.temperature_c, sun.zenith_deg, sun.apparent_zenith_deg,
      sun.ApparentElevationDeg(), sun.azimuth_deg, sun.time.delta_t_s,
      sunmodel::DeltaTSourceName(sun.time.source), sun.time.ut1_uncertainty_s,
      sun.time.ut1_uncertainty_s * 360.0 / 86400.0, sun.AboveHorizon() ? "yes" : "no (night)");
  if (scene) {
    const glm::dvec3 d = scene->GeoFrame().DirectionInScene(sun.azimuth_deg, sun.apparent_zenith_deg);
    text += fmt::format("sun_in_scene         {:.7f} {:.7f} {:.7f}  (unit vector to the sun; +Y at "
                        "compass {:.2f} deg)\n",
                        d.x, d.y, d.z, scene->north_azimuth_deg);
  }
  fmt::print("{}", text);
}

}  // namespace

void AddSunposCommand(CLI::App& app) {
  auto options = std::make_shared<SunposOptions>();
  CLI::App* cmd = app.add_subcommand(
      "sunpos", "Solar position (topocentric zenith, azimuth east of north, scene vector)");
  cmd->footer(
      "Examples:\n"
      "  daylit sunpos --time 2026-06-21T10:00:00Z --lat 57.0488 --lon 9.9217\n"
      "  daylit sunpos --time 2026-06-21T10:00:00Z --scene recordings/courtyard-a\n"
      "  daylit sunpos --scene recordings/courtyard-a --frames --out sun.csv\n"
      "  daylit sunpos --csv in.csv --out out.csv   (columns utc,lat_deg,lon_deg,elev_m[,delta_t_s,\n"
      "                                             dut1_s,pressure_hpa,temp_c]; others carried)");
  auto* time = cmd->add_option("--time", options->time, "UTC instant, ISO 8601 with Z or an offset");
  auto* lat = cmd->add_option("--lat", options->lat, "Latitude, degrees north (WGS84)");
  auto* lon = cmd->add_option("--lon", options->lon, "Longitude, degrees east");
  cmd->add_option("--elev", options->elev, "Height above the ellipsoid, m (default 0)");
  cmd->add_option("--pressure", options->pressure_hpa, "Pressure, hPa (default: standard atmosphere; 0 = no refraction)");
  cmd->add_option("--temp", options->temp_c, "Temperature, C (default: standard atmosphere)");
  cmd->add_option("--delta-t", options->delta_t_s, "TT - UT1, s (default: leap-second table or model)");
  cmd->add_option("--dut1", options->dut1_s, "UT1 - UTC, s (default 0)");
  auto* scene = cmd->add_option("--scene", options->scene, "scene.json or recording folder: location and north from it");
  auto* frames = cmd->add_flag("--frames", options->frames, "One CSV row per frame of the recording (needs --scene)");
  auto* csv = cmd->add_option("--csv", options->csv_in, "Batch: input CSV file");
  cmd->add_option("--out", options->out, "Output file for --csv or --frames (default: stdout)");
  auto* plot = cmd->add_option("--plot", options->plot, "With --frames: also write the sun's path as a PNG plot");
  plot->needs(frames);
  lat->excludes(scene);
  lon->excludes(scene);
  csv->excludes(time)->excludes(lat)->excludes(lon)->excludes(scene)->excludes(frames);
  frames->needs(scene)->excludes(time);
  cmd->callback([options] {
    const SunposOptions& o = *options;
    if (const std::string why = sunmodel::EarthOrientation{o.delta_t_s, o.dut1_s}.Check("--delta-t", "--dut1"); !why.empty()) {
      ThrowInputError("{}", why);
    }
    RefuseSharedOutputs({{"--out", o.out}, {"--plot", o.plot}});
    if (!o.csv_in.empty()) {
      RefuseInputsAsOutputs({o.csv_in}, {}, {{"--out", o.out}});
      return RunBatch(o);
    }
    std::optional<scene::Scene> loaded;
    if (!o.scene.empty()) {
      loaded = scene::LoadScene(o.scene);
      RefuseInputsAsOutputs(*loaded, {{"--out", o.out}, {"--plot", o.plot}});
    }
    if (o.frames) return RunFrames(o, *loaded);
    if (o.time.empty()) ThrowInputError("--time is required (or use --csv, or --scene with --frames)");
    if (!loaded && (!o.lat || !o.lon)) ThrowInputError("--lat and --lon are required without --scene");
    RunSingle(o, loaded);
  });
}

}  // namespace daylit::app
