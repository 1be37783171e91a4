// daylit replay: the main job. Every frame of a recording through the whole pipeline (bake,
// capture, sun, estimation, relighting, irradiance volume, compositing) into an augmented H.264
// video, with the estimates, their plot and a report beside it (docs/render.md).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "apps/daylit/commands.h"
#include "apps/daylit/video_output.h"
#include "bake/bake.h"
#include "base/atomic_file.h"
#include "base/error.h"
#include "base/log.h"
#include "base/statistics.h"
#include "capture/frame_source.h"
#include "capture/response.h"
#include "estimation/recording_estimator.h"
#include "render/composite_truth.h"
#include "render/frame_renderer.h"
#include "render/gl_context.h"
#include "render/gl_window.h"
#include "relight/image_relight.h"
#include "relight/time_slider.h"
#include "report/plot.h"
#include "scene/scene.h"

namespace daylit::app {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::atomic<bool> g_stop_replay{false};
extern "C" void StopReplay(int) { g_stop_replay = true; }

struct ReplayOptions {
  bool live = false;  // daylit live: the scene's camera
  std::string recording;
  std::string cache;
  std::string out = "replay.mp4";
  bool out_given = false;
  std::optional<int> frames;
  bool window = false;
  std::string screenshot;
  std::string relight_at;  // the time slider's start, HH:MM UTC
  std::string lighting = "volume";
};

// The window's overlay, drawn into the shown image: frames per second, the sun, and E_sun and
// E_sky as swatches of their colour (at full brightness, encoded as the image is) with their values.
void DrawOverlay(cv::Mat* bgr, double fps, const estimation::FrameEstimate& row, const capture::Encoder& encode) {
  const auto text = [&](const std::string& line, int x, int y) {
    cv::putText(*bgr, line, {x, y}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
    cv::putText(*bgr, line, {x, y}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  };
  text(fmt::format("frame {}  {:.0f} fps  sun {:.1f} deg up, {:.1f} deg az", row.frame, fps, row.sun_elevation_deg,
                   row.sun_azimuth_deg), 12, 22);
  int y = 34;
  for (const bool sun : {true, false}) {
    const glm::dvec3 e = sun ? row.light.sun_rgb : row.light.sky_rgb;
    const double top = std::max({e.x, e.y, e.z, 1e-9});
    cv::Scalar colour;
    for (int c = 0; c < 3; ++c) colour[2 - c] = 255.0 * encode(static_cast<float>(e[c] / top), c);
    cv::rectangle(*bgr, cv::Rect(12, y, 24, 16), colour, cv::FILLED);
    cv::rectangle(*bgr, cv::Rect(12, y, 24, 16), cv::Scalar(255, 255, 255), 1);
    text(fmt::format("{} {:.3g} {:.3g} {:.3g}", sun ? "E_sun" : "E_sky", e.x, e.y, e.z), 44, y + 13);
    y += 22;
  }
}

// The window's time slider: a bar along the bottom over the site's solar day.
struct SliderBar {
  int x0, x1, y, height;
  static SliderBar Of(int width, int height) { return {16, width - 16, height - 22, 10}; }
  bool Hit(const cv::Point2d& p) const { return p.y >= y - 14 && p.y <= y + height + 14 && p.x >= x0 - 8 && p.x <= x1 + 8; }
  int X(double fraction) const { return x0 + static_cast<int>(std::lround(fraction * (x1 - x0))); }
};

// Arrow keys move the slider by 15 min (left, right) or an hour (down, up); Backspace turns it off
// (the frame's own time); a click or drag on the bar puts it there.
void ApplyInput(const render::WindowInput& input, const UtcTime& frame_utc, const SliderBar& bar, relight::TimeSlider* slider) {
  for (const render::WindowKey key : input.keys) {
    switch (key) {
      case render::WindowKey::kLeft: slider->Step(-15, frame_utc); break;
      case render::WindowKey::kRight: slider->Step(15, frame_utc); break;
      case render::WindowKey::kDown: slider->Step(-60, frame_utc); break;
      case render::WindowKey::kUp: slider->Step(60, frame_utc); break;
      case render::WindowKey::kBackspace: slider->Off(); break;
    }
  }
  if (input.dragging && bar.Hit(*input.dragging)) {
    slider->SetFraction((input.dragging->x - bar.x0) / static_cast<double>(bar.x1 - bar.x0));
  }
}

// Where the sun is up over one solar day, sampled every 10 minutes, for shading the bar's night.
struct SunlitDay {
  double midnight = -1.0;  // the day's start, Unix seconds
  std::vector<bool> up;
};

void DrawTimeSlider(cv::Mat* bgr, const relight::TimeSlider& slider, const scene::Scene& scene, const UtcTime& frame_utc,
                    const std::optional<scene::SceneSun>& relit_sun, SunlitDay* day) {
  const SliderBar bar = SliderBar::Of(bgr->cols, bgr->rows);
  const double midnight = UnixSeconds(slider.AtFraction(frame_utc, 0.0));
  if (std::abs(midnight - day->midnight) > 1.0) {
    day->midnight = midnight;
    day->up.assign(144, false);
    for (int i = 0; i < 144; ++i) {
      day->up[i] = scene::SunAt(scene, UtcFromUnixSeconds(midnight + 600.0 * (i + 0.5))).dir.z > 0.0;
    }
  }
  for (int i = 0; i < 144; ++i) {
    const cv::Scalar colour = day->up[i] ? cv::Scalar(150, 200, 230) : cv::Scalar(90, 40, 30);
    cv::rectangle(*bgr, cv::Point(bar.X(i / 144.0), bar.y), cv::Point(bar.X((i + 1) / 144.0), bar.y + bar.height), colour,
                  cv::FILLED);
  }
  cv::rectangle(*bgr, cv::Rect(bar.x0, bar.y, bar.x1 - bar.x0, bar.height), cv::Scalar(255, 255, 255), 1);
  for (int hour = 3; hour < 24; hour += 3) {
    cv::line(*bgr, {bar.X(hour / 24.0), bar.y + bar.height}, {bar.X(hour / 24.0), bar.y + bar.height + 4},
             cv::Scalar(255, 255, 255), 1);
  }
  const int now = bar.X(slider.Fraction(frame_utc));
  cv::line(*bgr, {now, bar.y - 4}, {now, bar.y + bar.height + 4}, cv::Scalar(255, 255, 255), 2);
  const auto text = [&](const std::string& line) {
    cv::putText(*bgr, line, {bar.x0, bar.y - 8}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
    cv::putText(*bgr, line, {bar.x0, bar.y - 8}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  };
  const std::optional<UtcTime> target = slider.Target(frame_utc);
  if (!target || !relit_sun) {
    text(target ? "no estimate yet: shown as it is" : "time of day: <- -> 15 min, up/down 1 h, or click the bar");
    return;
  }
  const int x = bar.X(*slider.solar_minutes() / relight::TimeSlider::kDayMinutes);
  cv::circle(*bgr, {x, bar.y + bar.height / 2}, 7, cv::Scalar(0, 200, 255), cv::FILLED, cv::LINE_AA);
  cv::circle(*bgr, {x, bar.y + bar.height / 2}, 7, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  const int solar = static_cast<int>(std::lround(*slider.solar_minutes()));
  const UtcTime utc = UtcFromUnixSeconds(60.0 * std::round(UnixSeconds(*target) / 60.0));
  const double elevation = relit_sun->position.ApparentElevationDeg();
  text(fmt::format("relit to {:02d}:{:02d} UTC (solar {:02d}:{:02d}), sun {}  [Backspace: the frame's own time]",
                   utc.hour, utc.minute, solar / 60 % 24, solar % 60,
                   relit_sun->dir.z > 0.0 ? fmt::format("{:.1f} deg up, {:.1f} deg az", elevation, relit_sun->position.azimuth_deg)
                                          : fmt::format("{:.1f} deg below the horizon: sky only", -elevation)));
}

struct FrameFidelity {
  int frame = 0;
  render::CompositeFidelity f;
};

std::string FidelityCsv(const std::vector<FrameFidelity>& rows) {
  std::string csv = "frame,object_error,object_pixels,shadow_error,shadow_pixels,frame_shadow_error\n";
  for (const FrameFidelity& r : rows) {
    csv += fmt::format("{},{:.5f},{},{:.5f},{},{:.5f}\n", r.frame, r.f.object_error, r.f.object_pixels, r.f.shadow_error,
                       r.f.shadow_pixels, r.f.frame_shadow_error);
  }
  return csv;
}

void PlotFidelity(const std::vector<FrameFidelity>& rows, const std::string& title, const fs::path& png) {
  report::LinePlot plot({title + ": composite against the path-traced truth", "frame", "mean relative error (%)", 1400,
                         420, true});
  report::Series objects{"objects", {}, {}, report::SeriesColor(0), false, false};
  report::Series shadows{"their shadows", {}, {}, report::SeriesColor(1), false, false};
  report::Series camera{"the frame itself on the shadow pixels", {}, {}, report::SeriesColor(7), true, false};
  for (const FrameFidelity& r : rows) {
    objects.x.push_back(r.frame), objects.y.push_back(100 * r.f.object_error);
    shadows.x.push_back(r.frame), shadows.y.push_back(100 * r.f.shadow_error);
    camera.x.push_back(r.frame), camera.y.push_back(100 * r.f.frame_shadow_error);
  }
  plot.Add(std::move(objects));
  plot.Add(std::move(shadows));
  plot.Add(std::move(camera));
  report::WritePng(png, {plot.Render()});
}

void RunReplay(const ReplayOptions& o) {
  const fs::path out(o.out);
  CheckVideoName(out);
  if (o.frames && *o.frames < 1) ThrowInputError("--frames: {} is not a number of frames", *o.frames);
  const fs::path dir = out.has_parent_path() ? out.parent_path() : fs::path(".");
  const scene::Scene scene = scene::LoadScene(o.recording);
  if (o.live && scene.frames.kind != scene::FrameSourceKind::kDevice) {
    ThrowInputError("--scene: {}: frames name recorded frames, not a camera; replay them with daylit replay", scene.file.string());
  }
  if (!o.screenshot.empty() && !o.window) ThrowInputError("--screenshot: needs --window");
  if (!o.screenshot.empty() && fs::path(o.screenshot).extension() != ".png") ThrowInputError("--screenshot: {} must end in .png", o.screenshot);
  if (!o.relight_at.empty() && !o.window) ThrowInputError("--relight-at: needs --window (daylit relight writes a relit video)");
  render::FrameRendererOptions render_options;
  render_options.lights = render::ParseLighting(o.lighting, "--lighting");
  relight::TimeSlider slider(scene.location.longitude_deg);
  if (!o.relight_at.empty()) slider.SetUtcMinutes(relight::ParseUtcTimeOfDay(o.relight_at, "--relight-at"));
  // Everything that can fail without the bake fails before it: the frames, GL, the output.
  std::unique_ptr<capture::FrameSource> source = scene::OpenFrameSource(scene);
  // In a window, a recording plays at its own pace; a camera paces itself.
  if (o.window && scene.frame_times) source = capture::Paced(std::move(source), 1.0);
  const bool write_video = !o.window || o.out_given;
  std::optional<VideoOutput> output;
  if (write_video) output.emplace(out, scene);
  capture::AsyncVideoWriter* video = output ? &output->writer() : nullptr;
  // GL: a window's context, or a headless one.
  std::string why;
  std::unique_ptr<render::GlWindow> window;
  std::unique_ptr<render::HeadlessGlContext> gl;
  if (o.window) {
    window = render::GlWindow::Create(scene.intrinsics.width, scene.intrinsics.height, "daylit: " + scene.name, &why);
    if (window == nullptr) ThrowInputError("--window: {}", why);
  } else {
    gl = render::HeadlessGlContext::Create(&why);
    if (gl == nullptr) ThrowInputError("OpenGL: {}", why);
  }

  bool loaded = false;
  const fs::path cache = bake::CacheDir(scene, o.cache);
  const bake::SceneBake baked = bake::BakeOrLoad(scene, bake::BakeOptions{}, cache, &loaded);
  Log().info("{} the bake: {}", loaded ? "loaded" : "made", cache.string());
  const scene::RayCaster caster(scene.model);
  render::FrameRenderer renderer(scene, baked, caster, render_options);
  if (gl) Log().info("rendering with {} ({})", gl->renderer(), gl->platform());
  const int w = renderer.width(), h = renderer.height();

  std::vector<FrameFidelity> fidelity;
  double worst = -1.0, worst_exposure = 1.0;
  std::vector<float> worst_truth, worst_composite;
  std::vector<float> composite, linear;
  std::vector<double> render_ms;
  const capture::Encoder to_screen(scene.response);
  cv::Mat shown_rgb(h, w, CV_32FC3), shown;
  Clock::time_point last_shown = Clock::now();
  double shown_fps = 0.0;
  // The window's time slider relights the frames (relight::ImageRelighter, made when first used).
  std::unique_ptr<relight::ImageRelighter> relighter;
  SunlitDay sunlit_day;
  estimation::EstimateOptions options;
  options.max_frames = o.frames;
  options.progress_label = "replay";
  g_stop_replay = false;
  options.stop = &g_stop_replay;
  options.on_frame = [&](const estimation::FrameEstimate& row, const capture::Frame& frame, const glm::vec3& sun_dir,
                         double overcast_share) {
    // A frame that could not be read shows the last one again, so the video keeps its timing.
    if (frame.rgb.empty()) {
      if (video) video->Write({}, 1.0);
      return;
    }
    const Clock::time_point t0 = Clock::now();
    if (video) composite = video->TakeBuffer();
    if (window) ApplyInput(window->TakeInput(), row.time_utc, SliderBar::Of(w, h), &slider);
    // Relit to the slider's time: the frame times E_new / E_now, the objects under the new sun.
    std::optional<scene::SceneSun> relit_sun;
    const std::optional<UtcTime> relit_to = slider.Target(row.time_utc);
    if (relit_to && row.HasEstimate()) {
      relit_sun = scene::SunAt(scene, *relit_to);
      const glm::vec3 next_sun(relit_sun->dir);
      if (relighter == nullptr) relighter = std::make_unique<relight::ImageRelighter>(scene, baked, caster);
      relighter->SetSuns(sun_dir, next_sun);
      estimation::SunSky next = row.light;
      if (next_sun.z <= 0.0f) next.sun_rgb = glm::dvec3(0.0);
      renderer.Linearize(frame, &composite);
      relighter->Apply(relight::SplitLight(row.light, overcast_share), relight::SplitLight(next, overcast_share),
                       composite.data());
      renderer.RenderLinear(next, overcast_share, next_sun, composite.data());
    } else {
      renderer.Render(frame, row.light, overcast_share, sun_dir, &composite);
    }
    render_ms.push_back(1e3 * std::chrono::duration<double>(Clock::now() - t0).count());
    const std::optional<render::TruthFrame> truth = relit_to ? std::nullopt : render::ReadTruthFrame(scene, frame.index);
    if (truth) {
      renderer.Linearize(frame, &linear);
      const render::CompositeFidelity f = render::CompareComposite(composite, linear, truth->with, truth->without, truth->mask);
      fidelity.push_back({frame.index, f});
      const double score = std::max(f.object_error, f.shadow_error);
      if (score > worst) {  // its strip is written once, after the last frame
        worst = score;
        worst_truth = truth->with, worst_composite = composite, worst_exposure = frame.exposure;
      }
    }
    if (window) {
      to_screen.Apply(composite.data(), static_cast<float>(frame.exposure), shown_rgb.ptr<float>(), composite.size());
      shown_rgb.convertTo(shown, CV_8UC3, 255.0);
      cv::cvtColor(shown, shown, cv::COLOR_RGB2BGR);
      const Clock::time_point now = Clock::now();
      const double dt = std::chrono::duration<double>(now - last_shown).count();
      shown_fps = shown_fps == 0.0 ? 1.0 / std::max(dt, 1e-3) : 0.9 * shown_fps + 0.1 / std::max(dt, 1e-3);
      last_shown = now;
      DrawOverlay(&shown, shown_fps, row, to_screen);
      DrawTimeSlider(&shown, slider, scene, row.time_utc, relit_sun, &sunlit_day);
      if (!window->Show(shown)) g_stop_replay = true;  // closed: end as Ctrl-C does
    }
    if (video) video->Write(std::move(composite), frame.exposure);
  };
  std::signal(SIGINT, StopReplay);
  const estimation::EstimateRun run = estimation::EstimateRecording(scene, baked, options, std::move(source));
  std::signal(SIGINT, SIG_DFL);
  if (output) output->Commit();
  if (!o.screenshot.empty()) report::WritePng(o.screenshot, {window->Screenshot()});

  const size_t n = run.frames.size();
  fmt::memory_buffer report;
  auto say = [&report](const std::string& line) {
    fmt::print("{}\n", line);
    fmt::format_to(std::back_inserter(report), "{}\n", line);
  };
  if (run.undecodable > 0 && o.live) Log().warn("{} frames could not be read from the camera", run.undecodable);
  say(fmt::format("{}: {} frames in {:.1f} s, {:.1f} fps end to end (decode, estimate, relight, render, encode)",
                  scene.name, n, run.seconds, static_cast<double>(n) / std::max(run.seconds, 1e-9)));
  say(fmt::format("  per frame (median): estimate {:.1f} ms, relight + render {:.1f} ms (encoding on its own thread)",
                  run.median_frame_ms, MedianInPlace(render_ms, 0.0)));
  if (run.undecodable > 0) say(fmt::format("  {} frames could not be decoded (shown as the frame before)", run.undecodable));
  if (const relight::EnvLights* lights = renderer.env_lights()) {
    say(fmt::format("  the objects lit by the sun and {} lights, their directions fitted {} times (sun moves and large "
                    "changes of the light)", lights->count(), lights->generation()));
  }
  WriteFileAtomically(dir / "estimates.csv", estimation::EstimatesCsv(run.frames));
  std::optional<estimation::TruthComparison> lighting;
  if (scene.groundtruth.lighting) {
    lighting = estimation::CompareWithTruth(run.frames, *scene.groundtruth.lighting);
    say(fmt::format("lighting against groundtruth.csv, median relative error over {} frames (R, G, B):", lighting->frames));
    say(fmt::format("  E_sun    {:5.1f}% {:5.1f}% {:5.1f}%", 100 * lighting->sun_error.x, 100 * lighting->sun_error.y,
                    100 * lighting->sun_error.z));
    say(fmt::format("  E_sky    {:5.1f}% {:5.1f}% {:5.1f}%", 100 * lighting->sky_error.x, 100 * lighting->sky_error.y,
                    100 * lighting->sky_error.z));
  }
  estimation::PlotEstimates(run.frames, lighting ? &*lighting : nullptr, scene.name, dir / "lighting.png");
  if (!fidelity.empty()) {
    double objects = 0.0, shadows = 0.0;
    const FrameFidelity* worst_objects = &fidelity[0];
    const FrameFidelity* worst_shadows = &fidelity[0];
    for (const FrameFidelity& r : fidelity) {
      objects += r.f.object_error / static_cast<double>(fidelity.size());
      shadows += r.f.shadow_error / static_cast<double>(fidelity.size());
      if (r.f.object_error > worst_objects->f.object_error) worst_objects = &r;
      if (r.f.shadow_error > worst_shadows->f.shadow_error) worst_shadows = &r;
    }
    say(fmt::format("composite against the path-traced truth over {} frames (mean relative error of linear radiance):",
                    fidelity.size()));
    say(fmt::format("  objects        {:5.1f}% (worst {:.1f}% at frame {})", 100 * objects,
                    100 * worst_objects->f.object_error, worst_objects->frame));
    say(fmt::format("  their shadows  {:5.1f}% (worst {:.1f}% at frame {})", 100 * shadows,
                    100 * worst_shadows->f.shadow_error, worst_shadows->frame));
    render::WriteCompositeStrip(dir / "worst_vs_truth.png", w, h, worst_truth, worst_composite, worst_exposure, scene.response);
    WriteFileAtomically(dir / "fidelity.csv", FidelityCsv(fidelity));
    PlotFidelity(fidelity, scene.name, dir / "fidelity.png");
  }
  WriteFileAtomically(dir / "report.txt", fmt::to_string(report));
  Log().info("wrote {}estimates.csv, lighting.png, report.txt{} in {}", video ? out.filename().string() + ", " : "",
             fidelity.empty() ? "" : ", fidelity.csv, fidelity.png, worst_vs_truth.png", dir.string());
}

}  // namespace

namespace {

// What replay and live share: the cache, the video and report, the frame count, the window.
void AddPipelineOptions(CLI::App* cmd, const std::shared_ptr<ReplayOptions>& options, const std::string& default_out) {
  cmd->add_option("--cache", options->cache, "Bake cache folder (as for daylit bake)");
  CLI::Option* out = cmd->add_option("--out", options->out,
                                     "Augmented video, .mp4 or .mkv (default " + default_out + "); its folder gets the report");
  cmd->add_option("--frames", options->frames, "Stop after this many frames");
  cmd->add_flag("--window", options->window,
                "Show it in a window instead of writing the video (with fps, the sun and E_sun/E_sky swatches); "
                "--out as well writes both; Esc, Q or closing the window ends it");
  AddLightingOption(cmd, &options->lighting);
  cmd->add_option("--screenshot", options->screenshot, "With --window: the window's last frame as a PNG");
  cmd->add_option("--relight-at", options->relight_at,
                  "With --window: start the time slider at this UTC time of day (HH:MM); the frames are shown "
                  "relit to the sun of that time on their own day (daylit relight's ratio), objects included");
  cmd->callback([options, out] {
    options->out_given = out->count() > 0;
    RunReplay(*options);
  });
}

}  // namespace

void AddReplayCommand(CLI::App& app) {
  auto options = std::make_shared<ReplayOptions>();
  CLI::App* cmd = app.add_subcommand("replay", "The whole pipeline over a recording, into an augmented video");
  cmd->footer("Bakes (cached), then for every frame: decode, sun, estimate, relight the env map, update the\n"
              "irradiance volume, composite the objects with OpenGL (EGL, no display needed), encode H.264.\n"
              "Beside the video: estimates.csv, lighting.png, report.txt; with the recording's ground truth,\n"
              "fidelity.csv, fidelity.png and worst_vs_truth.png. Ctrl-C ends it with a complete video.\n"
              "--window plays it at the recording's pace.");
  cmd->add_option("recording", options->recording, "Recording folder or its scene.json")->required();
  AddPipelineOptions(cmd, options, "replay.mp4");
}

void AddLiveCommand(CLI::App& app) {
  auto options = std::make_shared<ReplayOptions>();
  options->live = true;
  options->out = "live.mp4";
  CLI::App* cmd = app.add_subcommand("live", "The replay's pipeline on the scene's V4L2 camera, to a video or a window");
  cmd->footer("scene.json's frames name the device ({\"device\": \"/dev/video0\", \"fps\": 30}); its exposure, gain\n"
              "and white balance are locked as for daylit record. Opens the camera before the bake. Runs until\n"
              "--frames, Ctrl-C, or (with --window) the window is closed; the video and report are then complete.");
  cmd->add_option("--scene", options->recording, "scene.json whose frames name a camera")->required();
  AddPipelineOptions(cmd, options, "live.mp4");
}

}  // namespace daylit::app
