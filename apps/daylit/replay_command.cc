// daylit replay: the main job. Every frame of a recording through the whole pipeline (bake,
// capture, sun, estimation, relighting, irradiance volume, compositing) into an augmented H.264
// video, with the estimates, their plot and a report beside it (docs/render.md).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include <fmt/format.h>

#include "apps/daylit/commands.h"
#include "apps/daylit/shadow_check.h"
#include "calibrate/shadow_calibration.h"
#include "bake/bake.h"
#include "base/statistics.h"
#include "base/error.h"
#include "base/log.h"
#include "capture/frame_source.h"
#include "evaluation/fidelity_sink.h"
#include "evaluation/lighting_truth.h"
#include "evaluation/run_report.h"
#include "pipeline/lighting_pipeline.h"
#include "pipeline/serve_sink.h"
#include "pipeline/stages.h"
#include "pipeline/video_output.h"
#include "pipeline/window_sink.h"
#include "render/time_slider.h"
#include "render/frame_renderer.h"
#include "render/gl_context.h"
#include "render/gl_window.h"
#include "report/plot.h"
#include "scene/scene.h"
#include "serve/lighting_server.h"

namespace daylit::app {
namespace {

namespace fs = std::filesystem;
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
  double calibrate_s = 0.0;  // live: fit north on this many seconds of the camera first
  std::string serve;         // [HOST:]PORT of the lighting server; empty: none
  bool pace = false;         // a recording at its own pace (as in a window)
  bool hold = false;         // --serve: keep serving the last frame after the run, until Ctrl-C
};

// daylit live --calibrate: the camera's frames through the estimator, for at most `seconds`, cut
// into minutes (the sun moves 0.25° in one), until the first minute that shows the sun clearly on
// the model; north is fitted on its shadows (one time of day: the clock is held), and the scene
// with it. The frames read go only to the fit.
constexpr double kCalibrationStretchS = 60.0;

scene::Scene CalibrateOnTheCamera(const scene::Scene& scene, const bake::SceneBake& baked, const scene::RayCaster& caster,
                                  capture::FrameSource* source, double seconds, const std::atomic<bool>* stop) {
  pipeline::LightingPipelineOptions options;
  options.max_frames = std::max(1, static_cast<int>(std::lround(seconds * scene.frames.fps)));
  options.progress_label = "calibrate";
  options.stop = stop;
  RequireValid("--calibrate", options.Check());
  pipeline::LightingPipeline lighting(scene, baked, caster, options);
  calibrate::ObserveOptions observe;
  observe.max_burst_s = kCalibrationStretchS;
  ShadowCheckSink shadows(scene, baked, observe, /*stop_at_first_sunlit_burst=*/true);
  lighting.AddSink(&shadows);
  lighting.Run(capture::Borrowed(source));
  const calibrate::ShadowObservations observed = shadows.Finish();
  scene::Scene calibrated = scene;
  if (observed.bursts.empty()) {
    Log().warn("--calibrate: the camera's first {:g} s show no clear sun on the model; north left at {:.3f} deg", seconds,
               scene.north_azimuth_deg);
    return calibrated;
  }
  const calibrate::BurstShadows& stretch = observed.bursts.front();
  calibrate::FitOptions fit_options;
  fit_options.clock = false;
  const calibrate::FitResult fit = calibrate::Calibrate(scene, baked, caster, observed, fit_options);
  if (fit.at_range_edge) {
    Log().warn("--calibrate: the shadows agree best at the search's edge (north {:+.1f} deg): north left at {:.3f} deg; "
               "check north_azimuth_deg",
               fit.north_offset_deg, scene.north_azimuth_deg);
    return calibrated;
  }
  // A fit no surer than issue 19's bar on north would move it at random: kept out, and said.
  constexpr double kNorthSigmaBarDeg = 0.3;
  if (!(fit.north_sigma_deg <= kNorthSigmaBarDeg)) {
    Log().warn("--calibrate: the shadows of the camera's frames {}-{} constrain north only to ±{:.2f} deg ({} clear frames, "
               "{} shadow-edge pixels; fitted {:+.3f}): north left at {:.3f} deg; a stretch of one time of day constrains "
               "north as far as its shadow edges do: calibrate again under another sun, or run daylit calibrate-scene on a "
               "recording that spans hours",
               stretch.first_frame, stretch.last_frame, fit.north_sigma_deg, fit.frames, fit.edge_pixels, fit.north_offset_deg,
               scene.north_azimuth_deg);
    return calibrated;
  }
  calibrated.north_azimuth_deg += fit.north_offset_deg;
  Log().info("--calibrate: north {:.3f} -> {:.3f} deg ({:+.3f} ± {:.3f}) from {} clear frames of the camera's frames {}-{}, "
             "{} shadow-edge pixels ({:.1f}% on the wrong side before, {:.1f}% after); the clock held (one time of day); "
             "write \"north_azimuth_deg\": {:.3f} into {} to keep it",
             scene.north_azimuth_deg, calibrated.north_azimuth_deg, fit.north_offset_deg, fit.north_sigma_deg, fit.frames,
             stretch.first_frame, stretch.last_frame, fit.edge_pixels, 100.0 * fit.disagree_before,
             100.0 * fit.disagree_after, calibrated.north_azimuth_deg, scene.file.string());
  return calibrated;
}

// report.txt (also on stdout), estimates.csv, lighting.png and, with truth, the fidelity files.
void WriteReplayReport(const scene::Scene& scene, const pipeline::PipelineRun& run, const render::FrameRenderer& renderer,
                       const evaluation::FidelitySink& fidelity, bool live, const std::string& gl_renderer,
                       const fs::path& dir) {
  const size_t n = run.frames.size();
  evaluation::RunReport report;
  evaluation::RunFigures(run, &report);
  if (!gl_renderer.empty()) report.Figure("gl_renderer", gl_renderer);
  if (run.undecodable > 0 && live) Log().warn("{} frames could not be read from the camera", run.undecodable);
  report.Say(fmt::format("{}: {} frames in {:.1f} s, {:.1f} fps end to end (decode, estimate, relight, render, encode)",
                         scene.name, n, run.seconds, static_cast<double>(n) / std::max(run.seconds, 1e-9)));
  // A frame whose sun moved (the first always) is timed as a sun move: a run of one frame, or of
  // frames that each moved the sun, has no estimate timing to give.
  const std::string estimate_ms = std::isfinite(run.median_estimate_ms) ? fmt::format("{:.1f} ms", run.median_estimate_ms)
                                                                        : std::string("not timed (too few frames)");
  report.Say(fmt::format("  per frame (median): estimate {}, relight + render {:.1f} ms (encoding on its own thread)",
                         estimate_ms, run.median_stage_ms));
  if (run.undecodable > 0) report.Say(fmt::format("  {} frames could not be decoded (shown as the frame before)", run.undecodable));
  if (live) {
    std::vector<double> latency = run.latency_ms;
    const double median = PercentileInPlace(latency, 0.5, static_cast<double>(NAN)),
                 p95 = PercentileInPlace(latency, 0.95, static_cast<double>(NAN)),
                 worst = PercentileInPlace(latency, 1.0, static_cast<double>(NAN));
    report.Say(fmt::format("  {} frames dropped by the camera's driver (gaps in its sequence numbers), {} given up "
                           "unestimated (the read-ahead's queue full: over a second behind at 960x540); a frame's age when estimated: median {:.0f} ms, "
                           "95th percentile {:.0f} ms, worst {:.0f} ms (the first frame waits for the set-up)",
                           run.dropped, run.skipped, median, p95, worst));
    const int made = run.composited + run.composites_skipped;
    report.Say(fmt::format("  composited {} of {} frames; {} estimated only, their image the one before, because "
                           "a newer frame was already waiting (the machine slower than the camera){}",
                           run.composited, made, run.composites_skipped,
                           run.composites_skipped > 0 ? fmt::format(": {:.1f} composites a second",
                                                                    run.composited / std::max(run.seconds, 1e-9))
                                                      : std::string()));
    if (made > 0 && run.composites_skipped * 10 > made) {
      Log().warn("composited only {} of {} frames: the machine is slower than the camera (a smaller camera "
                 "resolution or frame rate in scene.json composites every frame)", run.composited, made);
    }
    report.Figure("latency_p95_ms", p95);
    report.Figure("dropped", run.dropped);
    report.Figure("skipped", run.skipped);
    report.Figure("composited", run.composited);
    report.Figure("composites_skipped", run.composites_skipped);
    report.Figure("latency_median_ms", median);
    report.Figure("latency_worst_ms", worst);
  }
  if (const lightfit::EnvLights* lights = renderer.env_lights()) {
    report.Say(fmt::format("  the objects lit by the sun and {} lights, their directions fitted {} times (sun moves and "
                           "large changes of the light; {} stopped at the iteration limit)",
                           lights->count(), lights->generation(), lights->unconverged_fits()));
    report.Figure("lights/fits", lights->generation());
  }
  evaluation::ReportLighting(scene, run.frames, dir / "estimates.csv", dir / "lighting.png", &report);
  fidelity.Finish(dir, &report);
  report.Write(dir / "report.txt");
  report.WriteFigures(dir / "figures.json");
}

void RunReplay(const ReplayOptions& o) {
  const fs::path out(o.out);
  pipeline::CheckVideoName(out);
  if (o.frames && *o.frames < 1) ThrowInputError("--frames: {} is not a number of frames", *o.frames);
  const fs::path dir = out.has_parent_path() ? out.parent_path() : fs::path(".");
  scene::Scene scene = scene::LoadScene(o.recording);
  {
    std::vector<std::pair<std::string, fs::path>> outputs = {{"--out", out}, {"--screenshot", o.screenshot}};
    for (const char* beside : {"estimates.csv", "bursts.csv", "lighting.png", "report.txt", "figures.json", "fidelity.csv",
                               "fidelity.png", "worst_vs_truth.png"}) {
      outputs.emplace_back(fmt::format("--out's folder ({})", beside), dir / beside);
    }
    RefuseInputsAsOutputs(scene, outputs);
  }
  if (o.calibrate_s > 0.0 && !o.live) ThrowInputError("--calibrate: only for daylit live (a recording: daylit calibrate-scene)");
  if (o.live && scene.frames.kind != scene::FrameSourceKind::kDevice) {
    ThrowInputError("--scene: {}: frames name recorded frames, not a camera; replay them with daylit replay", scene.file.string());
  }
  if (!o.screenshot.empty() && !o.window) ThrowInputError("--screenshot: needs --window");
  if (!o.screenshot.empty() && fs::path(o.screenshot).extension() != ".png") ThrowInputError("--screenshot: {} must end in .png", o.screenshot);
  if (!o.relight_at.empty() && !o.window) ThrowInputError("--relight-at: needs --window (daylit relight writes a relit video)");
  if (o.hold && o.serve.empty()) ThrowInputError("--hold: needs --serve");
  // The port is taken before any work, so that a port in use fails at once.
  std::optional<serve::LightingServer> server;
  if (!o.serve.empty()) server.emplace(serve::ParseHostPort(o.serve, "--serve"), serve::SceneJson(scene));
  render::FrameRendererOptions render_options;
  render_options.lights = render::ParseLighting(o.lighting, "--lighting");
  RequireValid("render options", render_options.Check());
  render::TimeSlider slider(scene.location.longitude_deg);
  if (!o.relight_at.empty()) slider.SetUtcMinutes(render::ParseUtcTimeOfDay(o.relight_at, "--relight-at"));
  // Everything that can fail without the bake fails before it: the frames, GL, the output.
  std::unique_ptr<capture::FrameSource> source = scene::OpenFrameSource(scene);
  // In a window, a recording plays at its own pace; a camera paces itself.
  if ((o.window || o.pace) && scene.frame_times) source = capture::Paced(std::move(source), 1.0);
  std::optional<pipeline::VideoOutput> video;
  if (!o.window || o.out_given) video.emplace(out, scene);
  std::string why;
  std::unique_ptr<render::GlWindow> window;
  std::unique_ptr<render::HeadlessGlContext> gl;
  if (o.window) {
    window = render::GlWindow::Create(scene.intrinsics.width, scene.intrinsics.height, "daylit: " + scene.name, &why);
    if (window == nullptr) ThrowInputError("--window: {}", why);
  } else {
    gl = render::HeadlessGlContext::Create(&why);
    if (gl == nullptr) ThrowSystemError("OpenGL: {}", why);
    Log().info("rendering with {} ({})", gl->renderer(), gl->platform());
  }
  bool loaded = false;
  const fs::path cache = bake::CacheDir(scene, o.cache);
  const bake::SceneBake baked = bake::BakeOrLoad(scene, bake::BakeOptions{}, cache, &loaded);
  Log().info("{} the bake: {}", loaded ? "loaded" : "made", cache.string());

  const scene::RayCaster caster(scene.model);
  const StopOnInterrupt interrupt;
  if (o.calibrate_s > 0.0) scene = CalibrateOnTheCamera(scene, baked, caster, source.get(), o.calibrate_s, interrupt.flag());
  render::FrameRenderer renderer(scene, baked, caster, render_options);
  pipeline::CompositeStage composite(scene, baked, caster, &renderer, &slider);
  evaluation::FidelitySink fidelity(scene);
  std::optional<pipeline::WindowSink> shown;
  pipeline::LightingPipelineOptions options;
  options.max_frames = o.frames;
  options.progress_label = "replay";
  options.stop = interrupt.flag();
  RequireValid("options", options.Check());
  pipeline::LightingPipeline lighting(scene, baked, caster, options);
  lighting.SetStage(&composite);
  lighting.AddSink(&fidelity);
  std::optional<pipeline::ServeSink> serving;
  if (server) lighting.AddSink(&serving.emplace(scene, renderer, &*server));
  if (window) lighting.AddSink(&shown.emplace(scene, window.get(), &slider));
  if (video) lighting.SetVideo(&video->writer());
  const pipeline::PipelineRun run = lighting.Run(std::move(source));
  if (video) video->Commit();
  if (!o.screenshot.empty()) report::WritePng(o.screenshot, {window->Screenshot()});
  WriteReplayReport(scene, run, renderer, fidelity, o.live, gl ? gl->renderer() : std::string(), dir);
  Log().info("wrote {}estimates.csv, lighting.png, report.txt, figures.json{} in {}", video ? out.filename().string() + ", " : "",
             fidelity.frames().empty() ? "" : ", fidelity.csv, fidelity.png, worst_vs_truth.png", dir.string());
  if (server && o.hold) {
    Log().info("--hold: still serving frame {} on port {}; Ctrl-C ends it", run.frames.empty() ? -1 : run.frames.back().frame,
               server->port());
    while (!interrupt.flag()->load()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

}  // namespace

namespace {

// What replay and live share: the cache, the video and report, the frame count, the window.
void AddPipelineOptions(CLI::App* cmd, const std::shared_ptr<ReplayOptions>& options, const std::string& default_out) {
  cmd->add_option("--cache", options->cache, "Bake cache folder (as for daylit bake)");
  CLI::Option* out = cmd->add_option("--out", options->out,
                                     "Augmented video, .mp4 or .mkv (default " + default_out + "); its folder gets the report");
  cmd->add_option("--frames", options->frames, "Stop after this many frames")->check(FrameCount());
  cmd->add_flag("--window", options->window,
                "Show it in a window instead of writing the video (with fps, the sun and E_sun/E_sky swatches); "
                "--out as well writes both; Esc, Q or closing the window ends it");
  AddLightingOption(cmd, &options->lighting);
  cmd->add_option("--screenshot", options->screenshot, "With --window: the window's last frame as a PNG");
  cmd->add_option("--relight-at", options->relight_at,
                  "With --window: start the time slider at this UTC time of day (HH:MM); the frames are shown "
                  "relit to the sun of that time on their own day (daylit relight's ratio), objects included");
  cmd->add_option("--serve", options->serve,
                  "Serve each frame's lighting over HTTP while it runs, on [HOST:]PORT (host 127.0.0.1 unless given): "
                  "GET /lighting, /stream (Server-Sent Events), /scene, /envmap, /frame.jpg, /video.mjpg and the "
                  "browser viewer at / (docs/serve.md); port 0: any free one (the log names it)");
  cmd->add_flag("--pace", options->pace, "Play a recording at its own pace (as --window does), e.g. for a viewer of --serve");
  cmd->add_flag("--hold", options->hold, "With --serve: after the last frame, keep serving it until Ctrl-C");
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
  cmd->add_option("--calibrate", options->calibrate_s,
                  "First fit north on the camera's first clear minute within this many seconds (its shadows against "
                  "the model's; daylit calibrate-scene's method, the clock held) and run on with it")
      ->check(CLI::Range(1.0, 600.0));
  AddPipelineOptions(cmd, options, "live.mp4");
}

}  // namespace daylit::app
