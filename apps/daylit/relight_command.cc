// daylit relight: the camera frames under another sun (seed 004, docs/relight.md): each frame,
// linear, times the ratio E_new / E_now of two irradiance maps from the camera's viewpoint; with
// --objects, the virtual objects drawn under the new light too.
#include <algorithm>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "apps/daylit/commands.h"
#include "bake/bake.h"
#include "base/error.h"
#include "base/log.h"
#include "capture/frame_source.h"
#include "capture/response.h"
#include "estimation/frame_estimator.h"
#include "evaluation/composite_truth.h"
#include "pipeline/frame_fits.h"
#include "pipeline/lighting_pipeline.h"
#include "pipeline/stages.h"
#include "pipeline/video_output.h"
#include "relight/new_light.h"
#include "relight/image_relight.h"
#include "render/frame_renderer.h"
#include "render/gl_context.h"
#include "render/image_relight_gl.h"
#include "report/plot.h"
#include "scene/hdr_image.h"
#include "scene/scene.h"
#include "sunmodel/solar_position.h"

namespace daylit::app {
namespace {

namespace fs = std::filesystem;

struct RelightOptions {
  std::string recording;
  std::string cache;
  std::string out;
  std::string at;
  std::optional<double> azimuth, elevation;
  std::optional<int> like_frame;
  std::optional<int> frame;
  std::string frames;
  std::vector<double> e_sun, e_sky;
  bool clear_sky = false;
  std::string sky = "keep";
  bool objects = false;
  bool gpu = false;
};

glm::dvec3 RgbOption(const std::vector<double>& v, const char* option) {
  if (v.size() != 3) ThrowInputError("{}: give R,G,B ({} values given)", option, v.size());
  for (const double x : v) {
    // 1e9: far beyond any sun in any camera's units, and its products stay finite in float.
    if (!std::isfinite(x) || x < 0.0 || x > 1e9) ThrowInputError("{}: {} is not an irradiance (finite, in [0, 1e9])", option, x);
  }
  return {v[0], v[1], v[2]};
}

// The relit frame's comparison with a real one (--like-frame), printed; the strip beside `out`.
// F_strip.png beside --out F.png (or F.exr): the original | relit | real strip of --like-frame.
fs::path StripPath(const fs::path& out) {
  fs::path strip = out;
  strip.replace_extension();
  strip += "_strip.png";
  return strip;
}

void CompareWithRealFrame(const scene::Scene& scene, const bake::SceneBake& baked, const relight::ImageRelighter& relighter,
                          const relight::RelightTarget& target, const pipeline::FrameFit& original, const std::vector<float>& relit,
                          const pipeline::FrameFit& real, const fs::path& out) {
  const capture::Linearizer linearizer(scene.response);
  std::vector<float> before, after;
  capture::LinearRadiance(original.frame, linearizer, &before);
  capture::LinearRadiance(real.frame, linearizer, &after);
  const relight::SceneLight light{target.sun_dir_in_scene, estimation::SplitLight(*target.light, target.overcast_share)};
  const double error = relight::DiffuseError(baked.camera, relit.data(), after.data());
  const std::vector<uint8_t> relit_layout = relight::ShadowLayout(baked.camera, relighter.terms().next, light, relit.data());
  const std::vector<uint8_t> real_layout = relight::ShadowLayout(baked.camera, relighter.terms().next, light, after.data());
  fmt::print("relit frame {} against frame {}: diffuse pixels {:.1f}% mean relative error; shadow layout IoU {:.3f}\n",
             original.row.frame, real.row.frame, 100 * error, relight::ShadowIoU(relit_layout, real_layout));
  if (const std::optional<evaluation::TruthFrame> truth = evaluation::ReadTruthFrame(scene, real.row.frame)) {
    fmt::print("  against the path tracer's noise-free frame {}: {:.1f}% (the real frame itself: {:.1f}%)\n",
               real.row.frame, 100 * relight::DiffuseError(baked.camera, relit.data(), truth->without.data()),
               100 * relight::DiffuseError(baked.camera, after.data(), truth->without.data()));
  }
  const fs::path strip = StripPath(out);
  const int w = baked.camera.width, h = baked.camera.height;
  report::WritePng(strip, {capture::EncodeToBgr8(before.data(), w, h, original.frame.exposure, &scene.response),
                           capture::EncodeToBgr8(relit.data(), w, h, real.frame.exposure, &scene.response),
                           capture::EncodeToBgr8(after.data(), w, h, real.frame.exposure, &scene.response)});
  Log().info("wrote {} (original | relit | real, the last two at the real frame's exposure)", strip.string());
}

// The output and the options that name the new sun and light, before anything is loaded.
void CheckRelightOptions(const RelightOptions& o) {
  const fs::path out(o.out);
  if (o.frame) {
    const std::string ext = out.extension().string();
    if (ext != ".png" && ext != ".exr") ThrowInputError("--out: {} must end in .png or .exr", o.out);
    if (!o.frames.empty()) ThrowInputError("--frames: not with --frame");
  } else {
    pipeline::CheckVideoName(out);
  }
  const int given = (o.at.empty() ? 0 : 1) + (o.azimuth || o.elevation ? 1 : 0) + (o.like_frame ? 1 : 0);
  if (given != 1) ThrowInputError("give the new sun one way: --at, --sun-azimuth with --sun-elevation, or --like-frame");
  if (o.azimuth.has_value() != o.elevation.has_value()) ThrowInputError("--sun-azimuth and --sun-elevation go together");
  if (o.azimuth && !std::isfinite(*o.azimuth)) ThrowInputError("--sun-azimuth: {} is not an angle", *o.azimuth);
  if (o.elevation && !(*o.elevation >= -90.0 && *o.elevation <= 90.0)) {
    ThrowInputError("--sun-elevation: {} is outside [-90, 90]", *o.elevation);
  }
  if (o.sky != "keep" && o.sky != "follow") ThrowInputError("--sky: '{}' is not keep or follow", o.sky);
}

// --frames a:b (frame numbers, both included, each in frames.csv); both empty without it.
struct FrameRange {
  std::optional<int> first;
  std::optional<size_t> last_position;  // in frames.csv
};
FrameRange ParseFrameRange(const scene::Scene& scene, const std::string& text) {
  FrameRange range;
  if (text.empty()) return range;
  const size_t colon = text.find(':');
  int first = 0, last = 0;
  try {
    if (colon == std::string::npos) throw std::invalid_argument("");
    size_t used = 0;
    first = std::stoi(text.substr(0, colon), &used);
    if (used != colon) throw std::invalid_argument("");
    last = std::stoi(text.substr(colon + 1), &used);
    if (used != text.size() - colon - 1) throw std::invalid_argument("");
  } catch (const std::exception&) {
    ThrowInputError("--frames: '{}' is not a:b (frame numbers)", text);
  }
  if (last < first) ThrowInputError("--frames: {} ends before it starts", text);
  scene::FramePosition(scene, first, "--frames");
  range.first = first;
  range.last_position = scene::FramePosition(scene, last, "--frames");
  return range;
}

// The new sun from --at or --sun-azimuth/--sun-elevation (--like-frame needs the bake: LikeFrame),
// and the new light's options. `month_utc`: the month for the clear-sky model without --at.
relight::RelightTarget TargetFromOptions(const RelightOptions& o, const scene::Scene& scene, int month_utc) {
  relight::RelightTarget target;
  target.clear_sky = o.clear_sky;
  if (!o.e_sun.empty()) target.e_sun = RgbOption(o.e_sun, "--e-sun");
  if (!o.e_sky.empty()) target.e_sky = RgbOption(o.e_sky, "--e-sky");
  if (!o.at.empty()) {
    const UtcTime utc = ParseUtcTime(o.at, "--at");
    const scene::SceneSun at = scene::SunAt(scene, utc);
    target.sun_dir_in_scene = glm::vec3(at.dir);
    target.sun_elevation_deg = at.position.ApparentElevationDeg();
    target.month = utc.month;
    target.what = fmt::format("the sun at {} ({:.1f}° up, azimuth {:.1f}°)", o.at, target.sun_elevation_deg,
                              at.position.azimuth_deg);
  } else if (o.azimuth) {
    target.sun_dir_in_scene = glm::vec3(scene.GeoFrame().DirectionInScene(*o.azimuth, 90.0 - *o.elevation));
    target.sun_elevation_deg = *o.elevation;
    target.month = month_utc;
    target.what = fmt::format("the sun at {:.1f}° up, azimuth {:.1f}°", *o.elevation, *o.azimuth);
  }
  return target;
}

// --like-frame: that frame's own fit becomes the new sun and light.
void LikeFrame(const pipeline::FrameFit& like, relight::RelightTarget* target) {
  if (!like.fit.IsUsable()) ThrowInputError("--like-frame: frame {} has no estimate ({})", like.row.frame, like.fit.message);
  target->sun_dir_in_scene = like.sun_dir;
  target->sun_elevation_deg = like.row.sun_elevation_deg;
  target->month = like.row.time_utc.month;
  target->light = like.fit.light;
  target->overcast_share = like.fit.overcast_share;
  target->what = fmt::format("the sun and light of frame {} ({:.1f}° up, azimuth {:.1f}°)", like.row.frame,
                             target->sun_elevation_deg, like.row.sun_azimuth_deg);
}

// --frame N: that frame under its own fit, relit, as PNG or EXR (with --like-frame, compared).
void RelightOneFrame(const RelightOptions& o, const scene::Scene& scene, const bake::SceneBake& baked,
                     const pipeline::FrameFit& fit, const std::optional<pipeline::FrameFit>& like, pipeline::RelightStage* stage) {
  const fs::path out(o.out);
  if (!fit.fit.IsUsable()) ThrowInputError("frame {}: no estimate ({}); it cannot be relit", *o.frame, fit.fit.message);
  std::vector<float> image;
  stage->Relight(fit.frame, fit.fit.light, fit.fit.overcast_share, fit.sun_dir, fit.row.sun_elevation_deg, &image);
  const int w = stage->relighter().width(), h = stage->relighter().height();
  if (out.extension() == ".exr") {
    scene::WriteRgbExr(out, w, h, image.data());
  } else {
    report::WritePng(out, {capture::EncodeToBgr8(image.data(), w, h, fit.frame.exposure, &scene.response)});
  }
  Log().info("frame {}: wrote {}", *o.frame, o.out);
  if (like) CompareWithRealFrame(scene, baked, stage->relighter(), stage->target(), fit, image, *like, out);
}

// The recording's frames (or --frames a:b) through the pipeline with the relight stage, into a video.
void RelightVideo(const RelightOptions& o, const scene::Scene& scene, const bake::SceneBake& baked,
                  const scene::RayCaster& caster, const FrameRange& range, pipeline::VideoOutput* video,
                  pipeline::RelightStage* stage) {
  pipeline::LightingPipelineOptions options;
  options.progress_label = "relight";
  const StopOnInterrupt interrupt;
  options.stop = interrupt.flag();
  if (range.last_position) options.max_frames = static_cast<int>(*range.last_position) + 1;
  options.first_output_frame = range.first;
  RequireValid("options", options.Check());
  pipeline::LightingPipeline lighting(scene, baked, caster, options);
  lighting.SetStage(stage);
  lighting.SetVideo(&video->writer());
  const pipeline::PipelineRun run = lighting.Run(scene::OpenFrameSource(scene));
  video->Commit();
  fmt::print("{}: {} frames relit to {} in {:.1f} s ({:.1f} fps)\n", scene.name, stage->relit(), stage->target().what,
             run.seconds, static_cast<double>(run.frames.size()) / std::max(run.seconds, 1e-9));
  if (stage->unrelit() > 0) {
    Log().warn("{} frames had no estimate yet (no usable fit) and are written as they are", stage->unrelit());
  }
  Log().info("wrote {}", o.out);
}

void RunRelight(const RelightOptions& o) {
  CheckRelightOptions(o);
  const scene::Scene scene = scene::LoadScene(o.recording);
  // One frame compared with a real one writes its strip beside --out.
  RefuseInputsAsOutputs(scene, {{"--out", o.out}, {"--out's strip", o.frame && o.like_frame ? StripPath(o.out) : fs::path()}});
  if (!scene.frame_times) ThrowInputError("{}: frames: a live device has no recorded frames", scene.file.string());
  const FrameRange range = ParseFrameRange(scene, o.frames);
  const size_t position = o.frame ? scene::FramePosition(scene, *o.frame, "--frame") : 0;
  const size_t like_position = o.like_frame ? scene::FramePosition(scene, *o.like_frame, "--like-frame") : 0;
  relight::RelightTarget target = TargetFromOptions(o, scene, scene.frame_times->frames[position].utc.month);
  std::string why;
  std::unique_ptr<render::HeadlessGlContext> gl;
  if (o.objects || o.gpu) {
    gl = render::HeadlessGlContext::Create(&why);
    if (gl == nullptr) ThrowSystemError("OpenGL: {}", why);
  }
  std::optional<pipeline::VideoOutput> video;
  if (!o.frame) video.emplace(fs::path(o.out), scene);

  bool loaded = false;
  const bake::SceneBake baked = bake::BakeOrLoad(scene, bake::BakeOptions{}, bake::CacheDir(scene, o.cache), &loaded);
  const scene::RayCaster caster(scene.model);
  // The frame to relight and the one whose light it takes, fitted in one read of the recording.
  std::vector<size_t> positions;
  if (o.frame) positions.push_back(position);
  if (o.like_frame) positions.push_back(like_position);
  std::vector<pipeline::FrameFit> fits = pipeline::FitRecordingFrames(scene, baked, caster, positions);
  std::optional<pipeline::FrameFit> like;
  if (o.like_frame) {
    like = std::move(fits.back());
    LikeFrame(*like, &target);
  }
  if (target.sun_dir_in_scene.z <= 0.0f) {
    Log().warn("{}: the sun is {:.1f}° below the horizon; a sky-only relight (E_sun = 0)", target.what, -target.sun_elevation_deg);
  }
  pipeline::RelightStageOptions options;
  options.relight.sky = o.sky == "follow" ? relight::SkyPixels::kFollow : relight::SkyPixels::kKeep;
  options.gpu = o.gpu;
  RequireValid("relight options", options.Check());
  std::unique_ptr<render::FrameRenderer> renderer;
  if (o.objects) renderer = std::make_unique<render::FrameRenderer>(scene, baked, caster);
  pipeline::RelightStage stage(scene, baked, caster, target, options, renderer.get());
  Log().info("relighting to {}{}", target.what, o.gpu ? ", on the GPU path" : "");
  if (o.frame) {
    RelightOneFrame(o, scene, baked, fits.front(), like, &stage);
  } else {
    RelightVideo(o, scene, baked, caster, range, &*video, &stage);
  }
  if (stage.ClampedShare() > 0.0) {
    Log().info("{:.2f}% of the model's pixels were in deep shadow (E_now below 2% of what open level ground receives); "
               "their ratio is E_new over that floor", 100.0 * stage.ClampedShare());
  }
}

}  // namespace

void AddRelightCommand(CLI::App& app) {
  auto options = std::make_shared<RelightOptions>();
  CLI::App* cmd = app.add_subcommand("relight", "The camera frames under another sun: E_new / E_now (seed 004)");
  cmd->footer("Each frame (linear) times the ratio of its irradiance under the new sun and light to its irradiance\n"
              "now (the estimate), with cast shadows for both suns. The new light is the frame's own unless\n"
              "--like-frame, --clear-sky, --e-sun or --e-sky say otherwise. A sun below the horizon gives a\n"
              "sky-only relight. Examples:\n"
              "  daylit relight recordings/courtyard-a --at 2026-06-21T16:30:00Z --frames 100:199 --out relit.mp4\n"
              "  daylit relight recordings/courtyard-a --frame 152 --like-frame 452 --out relit.png");
  cmd->add_option("recording", options->recording, "Recording folder or its scene.json")->required();
  cmd->add_option("--at", options->at, "The new sun: the sun at this UTC instant (ISO 8601 with Z or an offset)");
  cmd->add_option("--sun-azimuth", options->azimuth, "The new sun: compass azimuth, degrees east of north");
  cmd->add_option("--sun-elevation", options->elevation, "The new sun: apparent elevation, degrees");
  cmd->add_option("--like-frame", options->like_frame, "The new sun and light: those of this frame (its own fit)");
  cmd->add_option("--e-sun", options->e_sun, "The new E_sun (DNI), R,G,B in radiance units")->delimiter(',');
  cmd->add_option("--e-sky", options->e_sky, "The new E_sky (DHI), R,G,B in radiance units")->delimiter(',');
  cmd->add_flag("--clear-sky", options->clear_sky,
                "Scale E_sun and E_sky by a clear-sky model (ASHRAE) from the frame's sun elevation to the new one");
  cmd->add_option("--sky", options->sky, "Pixels that show sky: keep (default) or follow (the sky's change)");
  cmd->add_option("--frame", options->frame, "Relight this frame only (frame number, as in frames.csv)");
  cmd->add_option("--frames", options->frames, "Relight frames a:b (frame numbers, both included; default all)");
  cmd->add_flag("--objects", options->objects, "Also draw the scene's virtual objects under the new light (OpenGL)");
  cmd->add_flag("--gpu", options->gpu, "Ratio and modulation in OpenGL (EGL) instead of on the CPU");
  cmd->add_option("--cache", options->cache, "Bake cache folder (as for daylit bake)");
  cmd->add_option("--out", options->out, "Video (.mp4, .mkv), or with --frame an image (.png like the video, .exr linear)")
      ->required();
  cmd->callback([options] { RunRelight(*options); });
}

}  // namespace daylit::app
