#include <string>
#include <vector>

#include <fmt/format.h>

#include "apps/daylit/commands.h"
#include "apps/daylit/shadow_check.h"
#include "bake/bake.h"
#include "calibrate/shadow_calibration.h"
#include "scene/raycaster.h"
#include "base/csv.h"
#include "base/error.h"
#include "base/log.h"
#include "capture/frame_times.h"
#include "evaluation/lighting_truth.h"
#include "capture/video_probe.h"
#include "scene/envmap_probe.h"
#include "scene/scene.h"
#include "sunmodel/solar_position.h"

namespace daylit::app {
namespace {

namespace fs = std::filesystem;

std::string Relative(const scene::Scene& scene, const fs::path& path) {
  return path.lexically_relative(scene.folder).string();
}

std::string Duration(double seconds) {
  const int h = static_cast<int>(seconds / 3600.0);
  const int m = static_cast<int>((seconds - h * 3600.0) / 60.0);
  return fmt::format("{} h {:02d} min {:04.1f} s", h, m, seconds - h * 3600.0 - m * 60.0);
}

std::string SunLine(const scene::Scene& scene, const UtcTime& utc) {
  const scene::SceneSun at = scene::SunAt(scene, utc);
  const sunmodel::SunPosition& sun = at.position;
  const glm::dvec3& d = at.dir;
  return fmt::format("{}  elevation {:7.3f}  azimuth {:7.3f}  scene ({:+.4f}, {:+.4f}, {:+.4f}){}",
                     FormatUtcTime(utc, 1), sun.ApparentElevationDeg(), sun.azimuth_deg, d.x, d.y,
                     d.z, sun.AboveHorizon() ? "" : "  below the horizon");
}

void PrintModel(const scene::Scene& scene) {
  const scene::SceneModel& m = scene.model;
  fmt::print("model        {}: {} vertices, {} triangles, {} surfaces\n", Relative(scene, m.file),
             m.vertices.size(), m.triangles.size(), m.surface_names.size());
  std::vector<size_t> triangles(m.surface_names.size(), 0);
  for (const scene::Triangle& t : m.triangles) ++triangles[t.surface];
  const std::vector<double> areas = m.SurfaceAreas();
  fmt::print("  {:<22} {:>9} {:>12}  diffuse\n", "surface", "triangles", "area_m2");
  for (size_t i = 0; i < m.surface_names.size(); ++i) {
    const bool diffuse = std::find(scene.diffuse_surfaces.begin(), scene.diffuse_surfaces.end(),
                                   static_cast<int>(i)) != scene.diffuse_surfaces.end();
    fmt::print("  {:<22} {:>9} {:>12.1f}  {}\n", m.surface_names[i], triangles[i], areas[i],
               diffuse ? "yes" : "-");
  }
  if (scene.diffuse_mask) fmt::print("  diffuse mask over the env map: {}\n", Relative(scene, *scene.diffuse_mask));
}

void PrintCamera(const scene::Scene& scene) {
  const scene::CameraIntrinsics& k = scene.intrinsics;
  fmt::print("camera       {}x{}, fx {:.1f} fy {:.1f}, cx {:.1f} cy {:.1f}, {}, response {}, exposure {:.6g}\n",
             k.width, k.height, k.fx, k.fy, k.cx, k.cy,
             k.HasDistortion() ? fmt::format("distortion [{}]", fmt::join(k.distortion, ", "))
                               : std::string("no distortion"),
             scene.response.Describe(), scene.exposure);
  const scene::CameraModel camera = scene.Camera();
  const glm::dvec3 c = camera.CenterInWorld();
  const sunmodel::GeoSite at = scene.GeoFrame().GeodeticOf(c);
  double azimuth = 0.0, zenith = 0.0;
  scene.GeoFrame().AzimuthZenithOf(glm::transpose(camera.cam_from_world().rotation)[2], &azimuth, &zenith);
  fmt::print("             centre ({:.3f}, {:.3f}, {:.3f}) m = {:.7f} N {:.7f} E {:.2f} m; looks toward "
             "azimuth {:.1f}, {:.1f} deg below the horizon\n",
             c.x, c.y, c.z, at.latitude_deg, at.longitude_deg, at.elevation_m, azimuth, zenith - 90.0);
  if (scene.pose_fit) {
    fmt::print("             pose solved from {} correspondences: reprojection rms {:.3f} px, max {:.3f} px\n",
               scene.pose_fit->count, scene.pose_fit->rms_reprojection_px, scene.pose_fit->max_reprojection_px);
  }
}

// Prints the frames block; returns problems found.
std::vector<std::string> PrintFrames(const scene::Scene& scene) {
  std::vector<std::string> problems;
  const scene::FramesSpec& f = scene.frames;
  if (f.kind == scene::FrameSourceKind::kDevice) {
    fmt::print("frames       live camera {} at {} fps\n", f.device, f.fps);
    if (f.clock_offset_s != 0.0) fmt::print("             its clock {:+.1f} s from UTC (frames.clock_offset_s)\n", -f.clock_offset_s);
    return problems;
  }
  if (f.clock_offset_s != 0.0) {
    fmt::print("clock        frames.csv's times {:+.1f} s (frames.clock_offset_s): the times below are UTC\n", f.clock_offset_s);
  }
  const capture::FrameTimes& times = *scene.frame_times;
  const size_t n = times.frames.size();
  if (f.kind == scene::FrameSourceKind::kVideo) {
    const capture::VideoInfo video = capture::ProbeVideo(f.video);
    fmt::print("frames       {}: {} {}x{}, {:.3g} fps, {} frames in the container\n", Relative(scene, f.video),
               video.codec, video.width, video.height, video.fps, video.frame_count);
    if (video.width != scene.intrinsics.width || video.height != scene.intrinsics.height) {
      ThrowInputError("{}: frames.video: {} is {}x{} but camera is {}x{}", scene.file.string(),
                      Relative(scene, f.video), video.width, video.height, scene.intrinsics.width,
                      scene.intrinsics.height);
    }
    if (static_cast<size_t>(video.frame_count) != n) {
      problems.push_back(fmt::format("{} holds {} frames but {} lists {}", Relative(scene, f.video),
                                     video.frame_count, Relative(scene, times.file), n));
    }
  } else {
    size_t missing = 0;
    for (size_t i = 0; i < n; ++i) missing += fs::is_regular_file(f.ImagePath(static_cast<int>(i))) ? 0 : 1;
    fmt::print("frames       images {}: {} of {} present\n", Relative(scene, f.image_pattern), n - missing, n);
    if (missing > 0) problems.push_back(fmt::format("{} frame images missing", missing));
  }
  size_t bursts = 1;
  for (size_t i = 1; i < n; ++i) bursts += capture::StartsBurst(times.frames[i - 1].utc, times.frames[i].utc);
  fmt::print("             {}: {} frames, {} -> {} (span {}), {} burst{}\n", Relative(scene, times.file), n,
             FormatUtcTime(times.frames.front().utc), FormatUtcTime(times.frames.back().utc),
             Duration(times.SpanSeconds()), bursts, bursts == 1 ? "" : "s");
  // The sun path: first frame of each burst, and the last frame.
  fmt::print("sun          frame {:>5}  {}\n", 0, SunLine(scene, times.frames.front().utc));
  for (size_t i = 1; i < n; ++i) {
    if (capture::StartsBurst(times.frames[i - 1].utc, times.frames[i].utc)) {
      fmt::print("             frame {:>5}  {}\n", i, SunLine(scene, times.frames[i].utc));
    }
  }
  fmt::print("             frame {:>5}  {}\n", n - 1, SunLine(scene, times.frames.back().utc));
  return problems;
}

void PrintEnvMap(const scene::Scene& scene, std::vector<std::string>* missing) {
  if (!scene.envmap) {
    missing->push_back("envmap (needed by bake, relit env maps and the irradiance volume)");
    return;
  }
  const scene::EnvMapSpec& e = *scene.envmap;
  const scene::EnvMapHeader header = scene::ProbeEnvMap(e.file);
  fmt::print("envmap       {}: {} {}x{} {}, captured at ({:.2f}, {:.2f}, {:.2f}) m, {}\n",
             Relative(scene, e.file), header.format, header.width, header.height, header.channels,
             e.position.x, e.position.y, e.position.z, FormatUtcTime(e.time_utc, 0));
  if (header.width != 2 * header.height) {
    Log().warn("{}: envmap.file: {}x{} is not a 2:1 latitude-longitude map", scene.file.string(),
               header.width, header.height);
  }
  fmt::print("             sun at capture: {}\n", SunLine(scene, e.time_utc));
  if (e.sun_irradiance_rgb) {
    fmt::print("             sun_irradiance_rgb ({:.4g}, {:.4g}, {:.4g})\n", e.sun_irradiance_rgb->x,
               e.sun_irradiance_rgb->y, e.sun_irradiance_rgb->z);
  }
}

void PrintObjectsAndVolume(const scene::Scene& scene, std::vector<std::string>* missing) {
  fmt::print("objects      {}\n", scene.objects.size());
  for (const scene::VirtualObject& o : scene.objects) {
    const std::string what = o.kind == scene::MeshKind::kSphere ? fmt::format("builtin:sphere r {:.3g} m", o.radius)
                             : o.kind == scene::MeshKind::kBox
                                 ? fmt::format("builtin:box {:.3g} x {:.3g} x {:.3g} m", o.size.x, o.size.y, o.size.z)
                                 : Relative(scene, o.file);
    fmt::print("  {} at ({:.2f}, {:.2f}, {:.2f}){}\n", what, o.position.x, o.position.y, o.position.z,
               o.albedo ? fmt::format(", albedo ({:.2f}, {:.2f}, {:.2f})", o.albedo->x, o.albedo->y, o.albedo->z)
                        : std::string());
  }
  if (scene.objects.empty()) missing->push_back("objects (nothing to insert)");
  if (scene.volume) {
    const scene::VolumeSpec& v = *scene.volume;
    fmt::print("volume       ({:.2f}, {:.2f}, {:.2f}) .. ({:.2f}, {:.2f}, {:.2f}) m, {}x{}x{} probes{}\n", v.min.x,
               v.min.y, v.min.z, v.max.x, v.max.y, v.max.z, v.resolution.x, v.resolution.y, v.resolution.z,
               v.defaulted ? " (default: around the objects)" : "");
  }
}

void PrintGroundTruth(const scene::Scene& scene, std::vector<std::string>* missing) {
  const scene::GroundTruthSpec& g = scene.groundtruth;
  if (!g.lighting && !g.composites) {
    missing->push_back("groundtruth (no error figures)");
    return;
  }
  if (g.lighting) {
    const CsvTable table = ReadCsvFile(*g.lighting);
    for (const char* column : {"frame", "sun_r", "sun_g", "sun_b", "sky_r", "sky_g", "sky_b"}) table.RequireColumn(column);
    fmt::print("groundtruth  lighting {}: {} rows\n", Relative(scene, *g.lighting), table.rows.size());
  }
  if (g.composites) {
    const fs::path with = *g.composites / "with_objects";
    size_t count = 0;
    if (fs::is_directory(with)) {
      for (const auto& entry : fs::directory_iterator(with)) count += entry.path().extension() == ".exr";
    }
    fmt::print("             composites {}: {} frames with objects\n", Relative(scene, *g.composites), count);
  }
}

// The frames' shadows against the model's, where the cache holds a current bake (the check needs
// its G-buffer and albedo); said as a line, a disagreement also as a problem.
void PrintShadowCheck(const scene::Scene& scene, const std::string& cache, std::vector<std::string>* problems) {
  if (!scene.frame_times) return;
  const fs::path dir = bake::CacheDir(scene, cache);
  const std::optional<bake::SceneBake> baked = bake::LoadBake(dir, bake::BakeHash(scene, bake::BakeOptions{}));
  if (!baked) {
    fmt::print("shadows      not checked: no current bake in {} (daylit bake makes one)\n", dir.string());
    return;
  }
  const scene::RayCaster caster(scene.model);
  const calibrate::ShadowObservations observed = calibrate::ObserveShadows(scene, *baked, caster);
  const std::optional<calibrate::ShadowCheck> check = CheckShadowsAndSay(scene, *baked, caster, observed, nullptr);
  if (!check) {
    fmt::print("shadows      not checked: no burst shows the sun clearly on the model\n");
  } else if (!check->ModelMatchesFootage()) {
    fmt::print("shadows      do not match the model's at any north within {:.0f} deg (the frames' sun explains {:.2f} of the "
               "agreement, at most {:.2f}): the model, the camera pose, north or the place may not be this footage's\n",
               calibrate::kShadowCheckNorthRangeDeg, check->SunSkill(), kShadowCheckMinSunSkill);
    problems->push_back(fmt::format("the frames' shadows do not match the model's (sun skill {:.2f}): a wrong model, pose, "
                                    "north or place",
                                    check->SunSkill()));
  } else if (std::abs(check->north_offset_deg) > kShadowCheckNorthDeg) {
    fmt::print("shadows      off: where the model's would fall with north {:+.2f} deg off; run daylit calibrate-scene\n",
               check->north_offset_deg);
    problems->push_back(fmt::format("the frames' shadows disagree with the model's by {:+.2f} deg of north", check->north_offset_deg));
  } else {
    fmt::print("shadows      agree with the model's: the best north is {:+.2f} deg from the scene's ({} bursts; the frames' "
               "sun explains {:.2f} of the agreement)\n",
               check->north_offset_deg, observed.bursts.size(), check->SunSkill());
  }
}

void RunInfo(const std::string& recording, const std::string& cache, bool check_shadows) {
  const scene::Scene scene = scene::LoadScene(recording);
  fmt::print("recording    {} ({}, {})\n", scene.name, scene.file.string(), scene::kRecordingFormat);
  fmt::print("location     {:.6f} N, {:.6f} E, {:.1f} m; scene +Y at compass {:.2f} deg\n",
             scene.location.latitude_deg, scene.location.longitude_deg, scene.location.elevation_m,
             scene.north_azimuth_deg);
  PrintModel(scene);
  PrintCamera(scene);
  std::vector<std::string> missing;
  PrintEnvMap(scene, &missing);
  std::vector<std::string> problems = PrintFrames(scene);
  if (check_shadows) PrintShadowCheck(scene, cache, &problems);
  PrintObjectsAndVolume(scene, &missing);
  PrintGroundTruth(scene, &missing);
  fmt::print("missing      {}\n", missing.empty() ? std::string("nothing") : fmt::format("{}", fmt::join(missing, "; ")));
  for (const std::string& p : problems) Log().warn("{}: {}", scene.file.string(), p);
  fmt::print("status       {}\n", problems.empty() ? "ok" : fmt::format("ok with {} warning(s)", problems.size()));
}

}  // namespace

void AddInfoCommand(CLI::App& app) {
  struct Options {
    std::string recording, cache;
    bool no_shadows = false;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("info", "Validate a recording and summarise it (frames, time span, sun path, surfaces)");
  cmd->footer("Where the cache holds a current bake, the frames' shadows are checked against the model's (north and\n"
              "clock): a disagreement beyond 0.5 deg of north is a warning that suggests daylit calibrate-scene.");
  cmd->add_option("recording", o->recording, "Recording folder or its scene.json")->required();
  cmd->add_option("--cache", o->cache, "Bake cache folder (as for daylit bake)");
  cmd->add_flag("--no-shadow-check", o->no_shadows, "Skip the shadow check (it reads every frame)");
  cmd->callback([o] { RunInfo(o->recording, o->cache, !o->no_shadows); });
}

}  // namespace daylit::app
