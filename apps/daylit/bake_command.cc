#include <chrono>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "apps/daylit/commands.h"
#include "bake/bake.h"
#include "base/log.h"
#include "scene/scene.h"

namespace daylit::app {
namespace {

struct BakeCommandOptions {
  std::string recording;
  std::string cache;
  bool print_albedo = false;
  bool force = false;
  bake::BakeOptions bake;
};

void RunBakeCommand(const BakeCommandOptions& o) {
  const scene::Scene scene = scene::LoadScene(o.recording);
  const std::filesystem::path dir = bake::CacheDir(scene, o.cache);
  const auto start = std::chrono::steady_clock::now();
  bool loaded = false;
  bake::SceneBake baked;
  if (o.force) {
    baked = bake::RunBake(scene, o.bake);
    bake::SaveBake(baked, scene, o.bake, dir);
  } else {
    baked = bake::BakeOrLoad(scene, o.bake, dir, &loaded);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  Log().info("{} {} in {:.2f} s: {}", loaded ? "loaded the cached bake" : "baked", scene.name, seconds, dir.string());
  if (!loaded) {
    const bake::CaptureSun& sun = baked.capture_sun;
    Log().info("capture sun: DNI used ({:.4g}, {:.4g}, {:.4g}), the map's disc gives ({:.4g}, {:.4g}, {:.4g}); brightest "
               "texel {:.2f} deg from the ephemeris sun",
               sun.dni_rgb.x, sun.dni_rgb.y, sun.dni_rgb.z, sun.dni_from_map_rgb.x, sun.dni_from_map_rgb.y,
               sun.dni_from_map_rgb.z, sun.brightest_offset_deg);
    Log().info("camera: {} of {} pixels on diffuse surfaces", baked.camera.DiffuseCount(),
               static_cast<size_t>(baked.camera.width) * baked.camera.height);
  }
  if (o.print_albedo) {
    fmt::print("{}", bake::AlbedoCsv(baked.albedo_table));
  } else {
    fmt::print("{}\n", dir.string());
  }
}

}  // namespace

void AddBakeCommand(CLI::App& app) {
  auto options = std::make_shared<BakeCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "bake", "Offline scene maps: env-map points/normals/V/albedo, camera G-buffer, irradiance-volume gather tables");
  cmd->footer("The cache is keyed by a hash of the inputs: an unchanged recording loads in well under a second.\n"
              "Prints the cache folder (or, with --print-albedo, albedo.csv: surface,r,g,b,pixels).");
  cmd->add_option("recording", options->recording, "Recording folder or its scene.json")->required();
  cmd->add_option("--cache", options->cache, "Cache folder (default: $XDG_CACHE_HOME/daylit/<scene name>)");
  cmd->add_flag("--print-albedo", options->print_albedo, "Print each surface's median albedo (CSV) to stdout");
  cmd->add_flag("--force", options->force, "Bake even when the cache is current");
  cmd->add_option("--rays", options->bake.rays.hemisphere_rays, "Hemisphere rays per point")->capture_default_str();
  cmd->add_option("--gather-directions", options->bake.gather_directions, "Directions per volume probe")->capture_default_str();
  cmd->callback([options] { RunBakeCommand(*options); });
}

}  // namespace daylit::app
