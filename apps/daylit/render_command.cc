// daylit render: one frame with the virtual objects, lit and shadowed like the real scene
// (docs/render.md). PNG is encoded like the video; EXR is the linear composite in radiance units.
#include <filesystem>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "apps/daylit/commands.h"
#include "bake/bake.h"
#include "base/error.h"
#include "base/log.h"
#include "capture/response.h"
#include "estimation/frame_estimator.h"
#include "evaluation/composite_truth.h"
#include "pipeline/frame_fits.h"
#include "render/frame_renderer.h"
#include "render/gl_context.h"
#include "report/plot.h"
#include "scene/hdr_image.h"
#include "scene/scene.h"

namespace daylit::app {
namespace {

namespace fs = std::filesystem;

struct RenderOptions {
  std::string recording;
  std::string cache;
  int frame = 0;
  std::string out = "frame.png";
  std::string lighting = "volume";
};

// F_vs_truth.png beside --out F.png (or F.exr): the truth | daylit | difference strip.
fs::path ComparisonPath(const fs::path& out) {
  fs::path strip = out;
  strip.replace_extension();
  strip += "_vs_truth.png";
  return strip;
}

void RunRender(const RenderOptions& o) {
  const fs::path out(o.out);
  const std::string ext = out.extension().string();
  if (ext != ".png" && ext != ".exr") ThrowInputError("--out: {} must end in .png or .exr", o.out);
  RequireWritable("--out", out);
  const scene::Scene scene = scene::LoadScene(o.recording);
  RefuseInputsAsOutputs(scene, {{"--out", out}, {"--out's comparison with the truth", ComparisonPath(out)}});
  const size_t position = scene::FramePosition(scene, o.frame, "--frame");
  render::FrameRendererOptions options;
  options.lights = render::ParseLighting(o.lighting, "--lighting");
  RequireValid("render options", options.Check());
  std::string why;
  const auto gl = render::HeadlessGlContext::Create(&why);
  if (gl == nullptr) ThrowSystemError("OpenGL: {}", why);
  bool loaded = false;
  const bake::SceneBake baked = bake::BakeOrLoad(scene, bake::BakeOptions{}, bake::CacheDir(scene, o.cache), &loaded);
  const scene::RayCaster caster(scene.model);
  const pipeline::FrameFit fit = pipeline::FitRecordingFrame(scene, baked, caster, position);
  render::FrameRenderer renderer(scene, baked, caster, options);
  std::vector<float> composite;
  renderer.Render(fit.frame, fit.fit.light, fit.fit.overcast_share, fit.sun_dir, &composite);
  const int w = renderer.width(), h = renderer.height();
  if (ext == ".exr") {
    scene::WriteRgbExr(out, w, h, composite.data());
  } else {
    report::WritePng(out, {capture::EncodeToBgr8(composite.data(), w, h, fit.frame.exposure, &scene.response)});
  }
  if (const lightfit::EnvLights* lights = renderer.env_lights()) {
    Log().info("the objects lit by the sun and {} lights fitted to the relit env map ({:.1f}% off its irradiance)",
               lights->count(), 100 * lights->error());
  }
  Log().info("frame {}: E_sun ({:.3g}, {:.3g}, {:.3g}), E_sky ({:.3g}, {:.3g}, {:.3g}); wrote {}", o.frame,
             fit.fit.light.sun_rgb.x, fit.fit.light.sun_rgb.y, fit.fit.light.sun_rgb.z, fit.fit.light.sky_rgb.x,
             fit.fit.light.sky_rgb.y, fit.fit.light.sky_rgb.z, o.out);
  // Against the path tracer's frame with the objects, when the recording has it.
  const std::optional<evaluation::TruthFrame> truth = evaluation::ReadTruthFrame(scene, o.frame);
  if (!truth) return;
  std::vector<float> linear;
  renderer.Linearize(fit.frame, &linear);
  const evaluation::CompositeFidelity f = evaluation::CompareComposite(composite, linear, truth->with, truth->without, truth->mask);
  const fs::path strip = ComparisonPath(out);
  evaluation::WriteCompositeStrip(strip, w, h, truth->with, composite, fit.frame.exposure, scene.response);
  fmt::print("against {}: objects {:.1f}% over {} pixels, their shadows {:.1f}% over {} pixels (the frame itself "
             "{:.1f}% off the truth there)\n",
             truth->with_file.string(), 100 * f.object_error, f.object_pixels, 100 * f.shadow_error, f.shadow_pixels,
             100 * f.frame_shadow_error);
  Log().info("wrote {} (truth | daylit | difference ×4)", strip.string());
}

}  // namespace

void AddLightingOption(CLI::App* cmd, std::string* lighting) {
  cmd->add_option("--lighting", *lighting,
                  "The objects' light besides the sun: volume (the irradiance volume, the default) or lights:N, "
                  "N directional lights (1 to 16) fitted to the relit env map, each casting shadows");
}

void AddRenderCommand(CLI::App& app) {
  auto options = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand("render", "One frame with the scene's virtual objects, lit and shadowed like it");
  cmd->footer("Fits the frame's light, relights, and composites the objects with OpenGL (EGL, no display needed).\n"
              "A .png is encoded like the video; an .exr is the linear composite in radiance units (frame\n"
              "linearised, exposure divided out). With the recording's ground truth, also compares.");
  cmd->add_option("recording", options->recording, "Recording folder or its scene.json")->required();
  cmd->add_option("--frame", options->frame, "Frame number, as in frames.csv")->required();
  cmd->add_option("--cache", options->cache, "Bake cache folder (as for daylit bake)");
  cmd->add_option("--out", options->out, "Output .png or .exr (default frame.png)");
  AddLightingOption(cmd, &options->lighting);
  cmd->callback([options] { RunRender(*options); });
}

}  // namespace daylit::app
