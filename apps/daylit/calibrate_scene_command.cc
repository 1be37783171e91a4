// daylit calibrate-scene: the model's north and the camera's clock from where the frames' shadows
// fall (calibrate/shadow_calibration.h, docs/calibrate.md), written as a corrected scene.json.
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "apps/daylit/commands.h"
#include "bake/bake.h"
#include "base/atomic_file.h"
#include "base/error.h"
#include "base/csv.h"
#include "base/log.h"
#include "calibrate/shadow_calibration.h"
#include "scene/raycaster.h"
#include "scene/scene.h"

namespace daylit::app {
namespace {

namespace fs = std::filesystem;

struct CalibrateSceneOptions {
  std::string recording;
  std::string cache;
  std::string out;
  std::string what = "north,clock";
  std::string figures;
  double north_range_deg = 10.0;
  double clock_range_min = 30.0;
  int frames = 0;
};

// The JSON pointers of scene.json's fields that name files or folders (recording-format.md).
std::vector<nlohmann::json::json_pointer> PathFields(const nlohmann::ordered_json& root) {
  std::vector<std::string> pointers = {"/model/file",    "/diffuse_mask",       "/camera/response/curve", "/envmap/file",
                                       "/frames/video",  "/frames/images",      "/frames/timestamps",     "/groundtruth/lighting",
                                       "/groundtruth/composites"};
  if (root.contains("objects") && root["objects"].is_array()) {
    for (size_t i = 0; i < root["objects"].size(); ++i) {
      const auto& mesh = root["objects"][i].value("mesh", std::string());
      if (mesh.rfind("builtin:", 0) != 0) pointers.push_back(fmt::format("/objects/{}/mesh", i));
    }
  }
  std::vector<nlohmann::json::json_pointer> out;
  for (const std::string& p : pointers) {
    const nlohmann::json::json_pointer ptr(p);
    if (root.contains(ptr) && root.at(ptr).is_string()) out.push_back(ptr);
  }
  return out;
}

// scene.json with the fitted values, its file paths made to resolve from `out`'s folder.
std::string CorrectedSceneJson(const scene::Scene& scene, const calibrate::FitResult& fit, const fs::path& out) {
  nlohmann::ordered_json root = nlohmann::ordered_json::parse(ReadTextFile(scene.file));
  if (fit.north_fitted) root["north_azimuth_deg"] = std::round((scene.north_azimuth_deg + fit.north_offset_deg) * 1e4) / 1e4;
  if (fit.clock_fitted) root["frames"]["clock_offset_s"] = std::round((scene.frames.clock_offset_s + fit.clock_offset_s) * 10.0) / 10.0;
  if (fit.pose_fitted) {
    const scene::RigidPose pose = calibrate::RotatedPose(scene.cam_from_world, fit.rotation_deg);
    nlohmann::ordered_json rotation = nlohmann::ordered_json::array();
    for (int r = 0; r < 3; ++r) {
      rotation.push_back({std::round(pose.rotation[0][r] * 1e9) / 1e9, std::round(pose.rotation[1][r] * 1e9) / 1e9,
                          std::round(pose.rotation[2][r] * 1e9) / 1e9});
    }
    root["camera"]["world_to_camera"] = {{"rotation", rotation},
                                         {"translation", {pose.translation.x, pose.translation.y, pose.translation.z}}};
    if (root["camera"].contains("correspondences")) {
      root["camera"].erase("correspondences");
      Log().info("the refined pose replaces camera.correspondences with camera.world_to_camera");
    }
  }
  const fs::path from = fs::weakly_canonical(out).parent_path(), to = fs::weakly_canonical(scene.folder);
  if (from != to) {
    for (const auto& ptr : PathFields(root)) {
      const std::string value = root.at(ptr).get<std::string>();
      if (fs::path(value).is_absolute()) continue;
      root[ptr] = (to / value).lexically_normal().lexically_relative(from).generic_string();
    }
  }
  return root.dump(2) + "\n";
}

void RunCalibrateSceneCommand(const CalibrateSceneOptions& o) {
  bool north = false, clock = false, pose = false;
  std::stringstream what(o.what);
  for (std::string item; std::getline(what, item, ',');) {
    if (item == "north") {
      north = true;
    } else if (item == "clock") {
      clock = true;
    } else if (item == "pose") {
      pose = true;
    } else {
      ThrowInputError("--what: '{}' is not one of north, clock, pose", item);
    }
  }
  if (!north && !clock) ThrowInputError("--what: give north, clock or both");
  const fs::path out = o.out;
  RequireWritable("--out", out), RequireWritable("--figures", o.figures);
  const scene::Scene scene = scene::LoadScene(o.recording);
  {
    // --out may be the scene.json itself (an in-place edit that keeps the old one), nothing else
    // the recording reads.
    scene::SceneInputs inputs = scene::InputsOf(scene);
    std::error_code ec;
    if (fs::exists(out, ec) && fs::equivalent(out, scene.file, ec)) inputs.files.erase(inputs.files.begin());
    RefuseInputsAsOutputs(inputs.files, inputs.folders, {{"--out", out}, {"--figures", o.figures}});
  }
  const fs::path dir = bake::CacheDir(scene, o.cache);
  bool loaded = false;
  const bake::SceneBake baked = bake::BakeOrLoad(scene, bake::BakeOptions{}, dir, &loaded);
  Log().info("{} the bake: {}", loaded ? "loaded" : "made", dir.string());
  const scene::RayCaster caster(scene.model);

  if (north) {
    const std::string beyond = calibrate::EnvMapSunBeyondRange(scene, baked, o.north_range_deg);
    if (!beyond.empty()) {
      ThrowInputError("{}: {}; widen --north-range or correct it by hand; the scene is left as it was", scene.file.string(), beyond);
    }
  }
  const auto start = std::chrono::steady_clock::now();
  const calibrate::ShadowObservations observed = calibrate::ObserveShadows(scene, baked, caster, {.max_frames = o.frames, .silhouette_margin_px = pose ? 8 : 0});
  calibrate::FitOptions options;
  options.north = north, options.clock = clock, options.pose = pose;
  options.north_range_deg = o.north_range_deg, options.clock_range_s = 60.0 * o.clock_range_min;
  const calibrate::FitResult fit = calibrate::Calibrate(scene, baked, caster, observed, options);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  fmt::print("{} of {} bursts show the sun on the model: {} clear frames, {} pixels compared, {} of them on shadow edges\n",
             fit.bursts, observed.bursts_seen, fit.frames, fit.pixels, fit.edge_pixels);
  if (fit.north_fitted) {
    fmt::print("  north_azimuth_deg     {:9.3f} -> {:9.3f}   ({:+.3f} ± {:.3f} deg)\n", scene.north_azimuth_deg,
               scene.north_azimuth_deg + fit.north_offset_deg, fit.north_offset_deg, fit.north_sigma_deg);
  }
  if (fit.clock_fitted) {
    fmt::print("  frames.clock_offset_s {:9.1f} -> {:9.1f}   ({:+.1f} ± {:.1f} s)\n", scene.frames.clock_offset_s,
               scene.frames.clock_offset_s + fit.clock_offset_s, fit.clock_offset_s, fit.clock_sigma_s);
  }
  if (fit.pose_fitted) {
    fmt::print("  camera rotation       ({:+.3f}, {:+.3f}, {:+.3f}) deg about its x, y, z (± {:.3f}, {:.3f}, {:.3f}): {:.3f} deg\n",
               fit.rotation_deg.x, fit.rotation_deg.y, fit.rotation_deg.z, fit.rotation_sigma_deg.x, fit.rotation_sigma_deg.y,
               fit.rotation_sigma_deg.z, glm::length(fit.rotation_deg));
  }
  fmt::print("  edge pixels on the wrong side of the frames' shadows: {:.1f}% before, {:.1f}% after ({:.1f} s)\n",
             100.0 * fit.disagree_before, 100.0 * fit.disagree_after, seconds);
  if (!fit.note.empty()) fmt::print("  note: {}\n", fit.note);

  if (!o.figures.empty()) {
    nlohmann::json f = {{"north_fitted", fit.north_fitted},   {"clock_fitted", fit.clock_fitted},
                        {"north_offset_deg", fit.north_offset_deg}, {"clock_offset_s", fit.clock_offset_s},
                        {"north_sigma_deg", fit.north_sigma_deg},   {"clock_sigma_s", fit.clock_sigma_s},
                        {"bursts", fit.bursts},                     {"frames", fit.frames},
                        {"pixels", fit.pixels},                     {"edge_pixels", fit.edge_pixels},
                        {"disagree_before", fit.disagree_before},   {"disagree_after", fit.disagree_after},
                        {"at_range_edge", fit.at_range_edge},       {"seconds", seconds},
                        {"pose_fitted", fit.pose_fitted},
                        {"rotation_deg", {fit.rotation_deg.x, fit.rotation_deg.y, fit.rotation_deg.z}},
                        {"rotation_sigma_deg", {fit.rotation_sigma_deg.x, fit.rotation_sigma_deg.y, fit.rotation_sigma_deg.z}}};
    WriteFileAtomically(o.figures, f.dump(2) + "\n");
  }
  if (fit.at_range_edge) {
    ThrowInputError("{}: the shadows agree best at the edge of the search range (north {:+.1f} deg, clock {:+.0f} s): the "
                    "error may be larger than the range; widen it (--north-range, --clock-range) or check north_azimuth_deg, "
                    "location and the frames' times; the scene is left as it was",
                    scene.file.string(), fit.north_offset_deg, fit.clock_offset_s);
  }
  const std::string json = CorrectedSceneJson(scene, fit, out);
  if (fs::exists(out) && fs::equivalent(out, scene.file)) {
    // Every earlier version kept: scene.json.bak, then .bak.1, .bak.2, ...
    fs::path backup = fs::path(scene.file).concat(".bak");
    for (int n = 1; fs::exists(backup) || fs::is_symlink(backup); ++n) backup = fs::path(scene.file).concat(fmt::format(".bak.{}", n));
    fs::copy_file(scene.file, backup);
    Log().info("kept the old scene as {}", backup.string());
  }
  WriteFileAtomically(out, json);
  if (fs::weakly_canonical(out).parent_path() != fs::weakly_canonical(scene.folder)) {
    Log().info("{} names the recording's files from its own folder: load it with daylit --allow-outside-paths",
               out.string());
  }
  fmt::print("wrote {}\n", out.string());
}

}  // namespace

void AddCalibrateSceneCommand(CLI::App& app) {
  auto options = std::make_shared<CalibrateSceneOptions>();
  CLI::App* cmd = app.add_subcommand("calibrate-scene",
                                     "Measure the model's north and the camera's clock from the frames' shadows; "
                                     "write a corrected scene.json");
  cmd->footer("Bakes first when the cache is missing or stale. --out RECORDING/scene.json replaces the scene in place\n"
              "and keeps the old one as scene.json.bak. Exit 2 when no burst shows the sun on the model, or when the\n"
              "best agreement lies on the search range's edge (the scene is then left untouched).");
  cmd->add_option("recording", options->recording, "Recording folder or its scene.json")->required();
  cmd->add_option("--cache", options->cache, "Bake cache folder (as for daylit bake)");
  cmd->add_option("--out", options->out, "The corrected scene.json")->required();
  cmd->add_option("--what", options->what, "What to fit, comma-separated: north, clock, pose (a small camera rotation); default north,clock");
  cmd->add_option("--north-range", options->north_range_deg, "Degrees searched either side of the scene's north (default 10)")
      ->check(CLI::Range(0.5, 45.0));
  cmd->add_option("--clock-range", options->clock_range_min, "Minutes searched either side of the frames' clock (default 30)")
      ->check(CLI::Range(1.0, 180.0));
  cmd->add_option("--figures", options->figures, "The fit's figures as JSON");
  cmd->add_option("--frames", options->frames, "Read only the first N frames")->check(FrameCount());
  cmd->callback([options] { RunCalibrateSceneCommand(*options); });
}

}  // namespace daylit::app
