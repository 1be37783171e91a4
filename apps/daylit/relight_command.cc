// daylit relight: the camera frames under another sun (seed 004, docs/relight.md): each frame,
// linear, times the ratio E_new / E_now of two irradiance maps from the camera's viewpoint; with
// --objects, the virtual objects drawn under the new light too.
#include <algorithm>
#include <atomic>
#include <csignal>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "apps/daylit/commands.h"
#include "apps/daylit/video_output.h"
#include "bake/bake.h"
#include "base/error.h"
#include "base/log.h"
#include "capture/frame_source.h"
#include "capture/response.h"
#include "estimation/recording_estimator.h"
#include "relight/image_relight.h"
#include "render/composite_truth.h"
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

std::atomic<bool> g_stop_relight{false};
extern "C" void StopRelight(int) { g_stop_relight = true; }

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

// The new sun, and the new light if it is fixed (--like-frame).
struct Target {
  glm::vec3 sun_dir{0.0f, 0.0f, 1.0f};
  double elevation_deg = 90.0;
  int month = 6;                          // for the clear-sky model
  std::optional<estimation::SunSky> light;  // --like-frame: that frame's estimate
  double overcast_share = 0.0;
  std::optional<glm::dvec3> e_sun, e_sky;   // --e-sun, --e-sky
  std::string what;                       // for the log
};

glm::dvec3 RgbOption(const std::vector<double>& v, const char* option) {
  if (v.size() != 3) ThrowInputError("{}: give R,G,B ({} values given)", option, v.size());
  for (const double x : v) {
    if (!std::isfinite(x) || x < 0.0) ThrowInputError("{}: {} is not an irradiance (finite, ≥ 0)", option, x);
  }
  return {v[0], v[1], v[2]};
}

// The light a frame is relit to, from its own (`now`, the estimate) and the options.
estimation::SunSky NewLight(const RelightOptions& o, const Target& target, const estimation::SunSky& now,
                            double now_elevation_deg) {
  estimation::SunSky light = target.light ? *target.light : now;
  if (o.clear_sky) {
    const glm::dvec2 f = relight::ClearSkyFactors(now_elevation_deg, target.elevation_deg, target.month);
    light.sun_rgb *= f.x, light.sky_rgb *= f.y;
  }
  if (target.e_sun) light.sun_rgb = *target.e_sun;
  if (target.e_sky) light.sky_rgb = *target.e_sky;
  if (target.sun_dir.z <= 0.0f) light.sun_rgb = glm::dvec3(0.0);
  return light;
}

// The relit frame's comparison with a real one (--like-frame), printed; the strip beside `out`.
void CompareWithRealFrame(const scene::Scene& scene, const bake::SceneBake& baked, const relight::ImageRelighter& relighter,
                          const Target& target, const estimation::FrameFit& original, const std::vector<float>& relit,
                          const estimation::FrameFit& real, const fs::path& out) {
  const capture::Linearizer linearizer(scene.response);
  std::vector<float> before, after;
  capture::LinearRadiance(original.frame, linearizer, &before);
  capture::LinearRadiance(real.frame, linearizer, &after);
  const relight::SceneLight light{target.sun_dir, relight::SplitLight(*target.light, target.overcast_share)};
  const double error = relight::DiffuseError(baked.camera, relit.data(), after.data());
  const std::vector<uint8_t> relit_layout = relight::ShadowLayout(baked.camera, relighter.terms().next, light, relit.data());
  const std::vector<uint8_t> real_layout = relight::ShadowLayout(baked.camera, relighter.terms().next, light, after.data());
  fmt::print("relit frame {} against frame {}: diffuse pixels {:.1f}% mean relative error; shadow layout IoU {:.3f}\n",
             original.row.frame, real.row.frame, 100 * error, relight::ShadowIoU(relit_layout, real_layout));
  if (const std::optional<render::TruthFrame> truth = render::ReadTruthFrame(scene, real.row.frame)) {
    fmt::print("  against the path tracer's noise-free frame {}: {:.1f}% (the real frame itself: {:.1f}%)\n",
               real.row.frame, 100 * relight::DiffuseError(baked.camera, relit.data(), truth->without.data()),
               100 * relight::DiffuseError(baked.camera, after.data(), truth->without.data()));
  }
  fs::path strip = out;
  strip.replace_extension();
  strip += "_strip.png";
  const int w = baked.camera.width, h = baked.camera.height;
  report::WritePng(strip, {capture::EncodeToBgr8(before.data(), w, h, original.frame.exposure, &scene.response),
                           capture::EncodeToBgr8(relit.data(), w, h, real.frame.exposure, &scene.response),
                           capture::EncodeToBgr8(after.data(), w, h, real.frame.exposure, &scene.response)});
  Log().info("wrote {} (original | relit | real, the last two at the real frame's exposure)", strip.string());
}

void RunRelight(const RelightOptions& o) {
  const fs::path out(o.out);
  const bool single = o.frame.has_value();
  if (single) {
    const std::string ext = out.extension().string();
    if (ext != ".png" && ext != ".exr") ThrowInputError("--out: {} must end in .png or .exr", o.out);
    if (!o.frames.empty()) ThrowInputError("--frames: not with --frame");
  } else {
    CheckVideoName(out);
  }
  const int given = (o.at.empty() ? 0 : 1) + (o.azimuth || o.elevation ? 1 : 0) + (o.like_frame ? 1 : 0);
  if (given != 1) ThrowInputError("give the new sun one way: --at, --sun-azimuth with --sun-elevation, or --like-frame");
  if (o.azimuth.has_value() != o.elevation.has_value()) ThrowInputError("--sun-azimuth and --sun-elevation go together");
  if (o.sky != "keep" && o.sky != "follow") ThrowInputError("--sky: '{}' is not keep or follow", o.sky);
  Target target;
  if (!o.e_sun.empty()) target.e_sun = RgbOption(o.e_sun, "--e-sun");
  if (!o.e_sky.empty()) target.e_sky = RgbOption(o.e_sky, "--e-sky");
  const scene::Scene scene = scene::LoadScene(o.recording);
  if (!scene.frame_times) ThrowInputError("{}: frames: a live device has no recorded frames", scene.file.string());
  // The frames: one, or a range of frame numbers (a:b, both included).
  std::optional<int> first, last;
  std::optional<size_t> last_position;
  if (!o.frames.empty()) {
    const size_t colon = o.frames.find(':');
    try {
      if (colon == std::string::npos) throw std::invalid_argument("");
      size_t used = 0;
      first = std::stoi(o.frames.substr(0, colon), &used);
      if (used != colon) throw std::invalid_argument("");
      last = std::stoi(o.frames.substr(colon + 1), &used);
      if (used != o.frames.size() - colon - 1) throw std::invalid_argument("");
    } catch (const std::exception&) {
      ThrowInputError("--frames: '{}' is not a:b (frame numbers)", o.frames);
    }
    if (*last < *first) ThrowInputError("--frames: {} ends before it starts", o.frames);
    scene::FramePosition(scene, *first, "--frames");
    last_position = scene::FramePosition(scene, *last, "--frames");
  }
  const size_t position = single ? scene::FramePosition(scene, *o.frame, "--frame") : 0;

  // The new sun.
  const sunmodel::SceneGeoFrame geo = scene.GeoFrame();
  if (!o.at.empty()) {
    const UtcTime utc = ParseUtcTime(o.at, "--at");
    const scene::SceneSun at = scene::SunAt(scene, utc);
    const sunmodel::SunPosition& sun = at.position;
    target.sun_dir = glm::vec3(at.dir);
    target.elevation_deg = sun.ApparentElevationDeg();
    target.month = utc.month;
    target.what = fmt::format("the sun at {} ({:.1f}° up, azimuth {:.1f}°)", o.at, target.elevation_deg, sun.azimuth_deg);
  } else if (o.azimuth) {
    if (!std::isfinite(*o.azimuth)) ThrowInputError("--sun-azimuth: {} is not an angle", *o.azimuth);
    if (!(*o.elevation >= -90.0 && *o.elevation <= 90.0)) ThrowInputError("--sun-elevation: {} is outside [-90, 90]", *o.elevation);
    target.sun_dir = glm::vec3(geo.DirectionInScene(*o.azimuth, 90.0 - *o.elevation));
    target.elevation_deg = *o.elevation;
    target.month = scene.frame_times->frames[position].utc.month;
    target.what = fmt::format("the sun at {:.1f}° up, azimuth {:.1f}°", *o.elevation, *o.azimuth);
  }

  std::string why;
  std::unique_ptr<render::HeadlessGlContext> gl;
  if (o.objects || o.gpu) {
    gl = render::HeadlessGlContext::Create(&why);
    if (gl == nullptr) ThrowInputError("OpenGL: {}", why);
  }
  std::optional<VideoOutput> video;
  if (!single) video.emplace(out, scene);

  bool loaded = false;
  const bake::SceneBake baked = bake::BakeOrLoad(scene, bake::BakeOptions{}, bake::CacheDir(scene, o.cache), &loaded);
  const scene::RayCaster caster(scene.model);
  std::optional<estimation::FrameFit> like;
  if (o.like_frame) {
    like = estimation::FitFrame(scene, baked, caster, scene::FramePosition(scene, *o.like_frame, "--like-frame"), {});
    if (!like->fit.IsUsable()) ThrowInputError("--like-frame: frame {} has no estimate ({})", *o.like_frame, like->fit.message);
    target.sun_dir = like->sun_dir;
    target.elevation_deg = like->row.sun_elevation_deg;
    target.month = like->row.time_utc.month;
    target.light = like->fit.light;
    target.overcast_share = like->fit.overcast_share;
    target.what = fmt::format("the sun and light of frame {} ({:.1f}° up, azimuth {:.1f}°)", *o.like_frame,
                              target.elevation_deg, like->row.sun_azimuth_deg);
  }
  if (target.sun_dir.z <= 0.0f) {
    Log().warn("{}: the sun is {:.1f}° below the horizon; a sky-only relight (E_sun = 0)", target.what, -target.elevation_deg);
  }
  relight::ImageRelightOptions options;
  options.sky = o.sky == "follow" ? relight::SkyPixels::kFollow : relight::SkyPixels::kKeep;
  relight::ImageRelighter relighter(scene, baked, caster, options);
  std::unique_ptr<render::ImageRelightGl> on_gpu;
  if (o.gpu) on_gpu = std::make_unique<render::ImageRelightGl>(relighter.width(), relighter.height());
  std::unique_ptr<render::FrameRenderer> renderer;
  if (o.objects) renderer = std::make_unique<render::FrameRenderer>(scene, baked, caster);
  Log().info("relighting to {}{}", target.what, o.gpu ? ", on the GPU path" : "");

  const capture::Linearizer linearizer(scene.response);
  size_t clamped = 0, model_pixels = 0;
  // One frame: linearised, relit, the objects drawn under the new light.
  const auto relight_frame = [&](const capture::Frame& frame, const estimation::SunSky& now_light, double now_overcast,
                                 const glm::vec3& now_sun, double now_elevation_deg, std::vector<float>* image) {
    capture::LinearRadiance(frame, linearizer, image);
    const estimation::SunSky next_light = NewLight(o, target, now_light, now_elevation_deg);
    const double next_overcast = target.light ? target.overcast_share : now_overcast;
    if (relighter.SetSuns(now_sun, target.sun_dir) && on_gpu) on_gpu->SetTerms(relighter.terms());
    const relight::LightParts now = relight::SplitLight(now_light, now_overcast);
    const relight::LightParts next = relight::SplitLight(next_light, next_overcast);
    const relight::RelightStats stats =
        on_gpu ? on_gpu->Apply(relighter.terms(), now, next, image->data()) : relighter.Apply(now, next, image->data());
    clamped += stats.clamped, model_pixels += stats.model_pixels;
    if (renderer) renderer->RenderLinear(next_light, next_overcast, target.sun_dir, image->data());
  };

  if (single) {
    const estimation::FrameFit fit = estimation::FitFrame(scene, baked, caster, position, {});
    if (!fit.fit.IsUsable()) ThrowInputError("frame {}: no estimate ({}); it cannot be relit", *o.frame, fit.fit.message);
    std::vector<float> image;
    relight_frame(fit.frame, fit.fit.light, fit.fit.overcast_share, fit.sun_dir, fit.row.sun_elevation_deg, &image);
    const int w = relighter.width(), h = relighter.height();
    if (out.extension() == ".exr") {
      scene::WriteRgbExr(out, w, h, image.data());
    } else {
      report::WritePng(out, {capture::EncodeToBgr8(image.data(), w, h, fit.frame.exposure, &scene.response)});
    }
    Log().info("frame {}: wrote {}", *o.frame, o.out);
    if (like) CompareWithRealFrame(scene, baked, relighter, target, fit, image, *like, out);
  } else {
    estimation::EstimateOptions estimate;
    estimate.progress_label = "relight";
    g_stop_relight = false;
    estimate.stop = &g_stop_relight;
    if (last_position) estimate.max_frames = static_cast<int>(*last_position) + 1;
    int written = 0, unrelit = 0;
    estimate.on_frame = [&](const estimation::FrameEstimate& row, const capture::Frame& frame, const glm::vec3& sun_dir,
                            double overcast_share) {
      if (first && row.frame < *first) return;
      ++written;
      capture::AsyncVideoWriter& writer = video->writer();
      if (frame.rgb.empty()) {  // could not be read: the frame before again
        writer.Write({}, 1.0);
        return;
      }
      std::vector<float> image = writer.TakeBuffer();
      if (!row.HasEstimate()) {  // no usable fit yet: written as it is
        ++unrelit;
        capture::LinearRadiance(frame, linearizer, &image);
      } else {
        relight_frame(frame, row.light, overcast_share, sun_dir, row.sun_elevation_deg, &image);
      }
      writer.Write(std::move(image), frame.exposure);
    };
    std::signal(SIGINT, StopRelight);
    const estimation::EstimateRun run = estimation::EstimateRecording(scene, baked, estimate, scene::OpenFrameSource(scene));
    std::signal(SIGINT, SIG_DFL);
    video->Commit();
    fmt::print("{}: {} frames relit to {} in {:.1f} s ({:.1f} fps)\n", scene.name, written - unrelit, target.what,
               run.seconds, static_cast<double>(run.frames.size()) / std::max(run.seconds, 1e-9));
    if (unrelit > 0) Log().warn("{} frames had no estimate yet (no usable fit) and are written as they are", unrelit);
    Log().info("wrote {}", o.out);
  }
  if (clamped > 0) {
    Log().info("{:.2f}% of the model's pixels were in deep shadow (E_now below 2% of what open level ground receives); "
               "their ratio is E_new over that floor",
               100.0 * static_cast<double>(clamped) / static_cast<double>(std::max<size_t>(model_pixels, 1)));
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
