// daylit relight-env: the environment map of one frame, relit with the lighting daylit estimates
// for that frame (docs/relight.md).
#include <filesystem>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "apps/daylit/commands.h"
#include "bake/bake.h"
#include "base/error.h"
#include "base/log.h"
#include "estimation/frame_estimator.h"
#include "pipeline/frame_fits.h"
#include "relight/env_relight.h"
#include "scene/scene.h"

namespace daylit::app {
namespace {

struct RelightEnvOptions {
  std::string recording;
  std::string cache;
  int frame = 0;
  std::string out = "env.exr";
};

void RunRelightEnv(const RelightEnvOptions& o) {
  if (std::filesystem::path(o.out).extension() != ".exr") {
    ThrowInputError("--out: {} must end in .exr (its preview is written beside it as .png)", o.out);
  }
  const scene::Scene scene = scene::LoadScene(o.recording);
  {
    std::filesystem::path preview = o.out, strip = o.out;
    preview.replace_extension(".png");
    strip.replace_extension();
    strip += "_vs_truth.png";
    RefuseInputsAsOutputs(scene, {{"--out", o.out}, {"--out's preview", preview}, {"--out's comparison", strip}});
  }
  if (!scene.envmap) ThrowInputError("{}: envmap: needed to relight it", scene.file.string());
  const size_t position = scene::FramePosition(scene, o.frame, "--frame");
  bool loaded = false;
  const bake::SceneBake baked = bake::BakeOrLoad(scene, bake::BakeOptions{}, bake::CacheDir(scene, o.cache), &loaded);
  const scene::RayCaster caster(scene.model);
  const pipeline::FrameFit fit = pipeline::FitRecordingFrame(scene, baked, caster, position);
  Log().info("frame {}: E_sun ({:.3g}, {:.3g}, {:.3g}), E_sky ({:.3g}, {:.3g}, {:.3g}), overcast share {:.2f}, "
             "confidence {:.2f}",
             o.frame, fit.fit.light.sun_rgb.x, fit.fit.light.sun_rgb.y, fit.fit.light.sun_rgb.z, fit.fit.light.sky_rgb.x,
             fit.fit.light.sky_rgb.y, fit.fit.light.sky_rgb.z, fit.fit.overcast_share, fit.fit.confidence);
  relight::EnvRelighter relighter(baked, glm::vec3(scene.envmap->position), caster);
  relighter.SetSun(fit.sun_dir);
  std::vector<glm::vec3> radiance;
  relighter.Relight(fit.fit.light, fit.fit.overcast_share, &radiance);
  relight::WriteEnvMap(o.out, relighter.width(), relighter.height(), radiance);
  Log().info("wrote {} and its preview", o.out);
  // Against the path tracer's map of the same frame, when the recording has one.
  if (!scene.groundtruth.composites) return;
  const std::filesystem::path truth_file = *scene.groundtruth.composites / "envmaps" / fmt::format("{:06d}.exr", o.frame);
  if (!std::filesystem::is_regular_file(truth_file)) return;
  const HdrImage truth = scene::ReadHdrImage(truth_file);
  if (truth.width != relighter.width() || truth.height != relighter.height()) {
    ThrowInputError("{}: {}x{} does not match the env map's {}x{}", truth_file.string(), truth.width, truth.height,
                    relighter.width(), relighter.height());
  }
  const relight::EnvComparison cmp = relight::CompareEnvMaps(baked.env, radiance, truth);
  std::filesystem::path png = o.out;
  png.replace_extension();
  png += "_vs_truth.png";
  relight::WriteEnvComparison(png, baked.env, radiance, truth);
  fmt::print("against {}: mean relative error {:.1f}% over {} surface texels; sky DHI {:.3g} vs {:.3g} ({:+.1f}%)\n",
             truth_file.string(), 100 * cmp.surface_error, cmp.surface_texels, cmp.sky_dhi, cmp.true_sky_dhi,
             100 * (cmp.sky_dhi / cmp.true_sky_dhi - 1.0));
  Log().info("wrote {} (truth | daylit | difference)", png.string());
}

}  // namespace

void AddRelightEnvCommand(CLI::App& app) {
  auto options = std::make_shared<RelightEnvOptions>();
  CLI::App* cmd = app.add_subcommand("relight-env", "The scene's environment map relit with one frame's estimated light");
  cmd->footer("Fits the frame's sun and sky (no temporal filter), relights every texel (model surfaces by the\n"
              "estimation's transfer model, sky by the captured sky's shape), and writes a float EXR plus a PNG\n"
              "preview. The sun is not in the map. With a ground-truth map for the frame, also compares.");
  cmd->add_option("recording", options->recording, "Recording folder or its scene.json")->required();
  cmd->add_option("--frame", options->frame, "Frame number, as in frames.csv")->required();
  cmd->add_option("--cache", options->cache, "Bake cache folder (as for daylit bake)");
  cmd->add_option("--out", options->out, "Output EXR (default env.exr; the preview gets .png)");
  cmd->callback([options] { RunRelightEnv(*options); });
}

}  // namespace daylit::app
