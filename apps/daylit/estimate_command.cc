#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "apps/daylit/commands.h"
#include "apps/daylit/shadow_check.h"
#include "bake/bake.h"
#include "base/error.h"
#include "base/log.h"
#include "evaluation/lighting_truth.h"
#include "evaluation/residuals.h"
#include "evaluation/split_check.h"
#include "evaluation/run_report.h"
#include "pipeline/lighting_pipeline.h"
#include "scene/raycaster.h"
#include "scene/scene.h"

namespace daylit::app {
namespace {

struct EstimateCommandOptions {
  std::string recording;
  std::string cache;
  std::string out = "estimates.csv";
  std::string plot;
  std::string figures;
  std::string residuals;
  evaluation::ResidualOptions residual;
  evaluation::SplitCheckOptions split;
  pipeline::LightingPipelineOptions pipeline;
};

void RunEstimateCommand(const EstimateCommandOptions& o) {
  if (const std::string why = o.pipeline.Check(); !why.empty()) ThrowInputError("options: {}", why);
  if (const std::string why = o.residual.Check(); !why.empty()) ThrowInputError("--residual-{}", why);
  if (!(o.split.threshold > 0.0 && o.split.threshold <= 10.0)) ThrowInputError("--split-threshold: {} is not in (0, 10]", o.split.threshold);
  if (!o.figures.empty() && std::filesystem::path(o.figures).extension() != ".json") {
    ThrowInputError("--figures: {} must end in .json", o.figures);
  }
  const std::string plot = o.plot.empty() ? std::filesystem::path(o.out).replace_extension(".png").string() : o.plot;
  const std::filesystem::path report_file = evaluation::ReportPathBeside(o.out);
  RefuseSharedOutputs({{"--out", o.out}, {"--plot (or the --out's .png)", plot},
                       {"the bursts' table", evaluation::BurstsCsvPath(o.out)}, {"the report", report_file},
                       {"--figures", o.figures}});
  RequireWritable("--out", o.out), RequireWritable("--plot", plot), RequireWritable("--figures", o.figures);
  const scene::Scene scene = scene::LoadScene(o.recording);
  std::vector<std::pair<std::string, std::filesystem::path>> outputs = {
      {"--out", o.out}, {"--plot (or the --out's .png)", plot}, {"the bursts' table", evaluation::BurstsCsvPath(o.out)},
      {"the report", report_file}, {"--figures", o.figures}, {"--residuals", o.residuals}};
  if (!o.residuals.empty()) {
    for (const char* name : {"residuals.csv", "residuals.png", "worst_frame_residuals.png", "split_check.csv", "split_check.png"}) {
      outputs.emplace_back(fmt::format("--residuals' {}", name), std::filesystem::path(o.residuals) / name);
    }
  }
  RefuseInputsAsOutputs(scene, outputs);
  // The frames first: a camera that is not there is an error now, not after the bake.
  std::unique_ptr<capture::FrameSource> source = scene::OpenFrameSource(scene);
  const std::filesystem::path dir = bake::CacheDir(scene, o.cache);
  bool loaded = false;
  const bake::SceneBake baked = bake::BakeOrLoad(scene, bake::BakeOptions{}, dir, &loaded);
  Log().info("{} the bake: {}", loaded ? "loaded" : "made", dir.string());
  // Ctrl-C ends a live run after the frame at hand; the CSV and plot are still written.
  pipeline::LightingPipelineOptions options = o.pipeline;
  const StopOnInterrupt interrupt;
  options.stop = interrupt.flag();
  const scene::RayCaster caster(scene.model);
  pipeline::LightingPipeline lighting(scene, baked, caster, options);
  std::optional<evaluation::ResidualSink> residuals;
  std::optional<evaluation::SplitCheck> split;
  std::optional<evaluation::SplitCheckSink> split_sink;
  if (!o.residuals.empty()) {
    lighting.AddSink(&residuals.emplace(scene, baked, o.residual));
    evaluation::SplitCheckOptions split_options = o.split;
    split_options.fit = options.estimator.fit;  // the refits are the estimator's fits
    lighting.AddSink(&split_sink.emplace(&split.emplace(scene, baked, split_options)));
  }
  // A recording's shadows are checked against the model's (north and clock); a live run is not.
  std::optional<ShadowCheckSink> shadows;
  if (scene.frame_times) lighting.AddSink(&shadows.emplace(scene, baked));
  const pipeline::PipelineRun run = lighting.Run(std::move(source));
  const size_t n = run.frames.size();
  double moves_ms = 0.0;
  for (const double ms : run.sun_moves_ms) moves_ms += ms;
  evaluation::RunReport report;
  evaluation::RunFigures(run, &report);
  evaluation::ReportLighting(scene, run.frames, o.out, plot, &report);
  if (residuals) residuals->Finish(o.residuals, &report);
  if (split) split->Finish(o.residuals, &report);
  if (shadows) CheckShadowsAndSay(scene, baked, caster, shadows->Finish(), &report);
  report.Write(report_file);
  if (!o.figures.empty()) report.WriteFigures(o.figures);
  // Frames whose sun moved are timed as sun moves: a one-frame run has no per-frame figure.
  const std::string per_frame = std::isfinite(run.median_estimate_ms) ? fmt::format("{:.2f} ms", run.median_estimate_ms)
                                                                      : std::string("not timed (every frame moved the sun)");
  Log().info("{} frames in {:.2f} s ({:.0f} fps end to end); estimation after decoding {} per frame (median), "
             "plus {} sun moves taking {:.0f} ms in all; wrote {}, {} and {}",
             n, run.seconds, static_cast<double>(n) / std::max(run.seconds, 1e-9), per_frame,
             run.sun_moves_ms.size(), moves_ms, o.out, plot, report_file.string());
  if (run.undecodable > 0) Log().warn("{} frames could not be decoded", run.undecodable);
}

}  // namespace

void AddEstimateCommand(CLI::App& app) {
  auto options = std::make_shared<EstimateCommandOptions>();
  CLI::App* cmd = app.add_subcommand("estimate", "Sun and sky RGB irradiance for every frame (headless, no GL)");
  cmd->footer("Bakes first when the cache is missing or stale. Writes the CSV (frame,time_utc,sun_elevation_deg,\n"
              "sun_azimuth_deg,sun_r,sun_g,sun_b,sky_r,sky_g,sky_b,confidence,samples, then each value's 90%\n"
              "interval: sun_r_lo,sun_r_hi,...,sky_b_lo,sky_b_hi) and a plot; with ground truth, prints the median\n"
              "errors and whether the intervals hold them.");
  cmd->add_option("recording", options->recording, "Recording folder or its scene.json")->required();
  cmd->add_option("--cache", options->cache, "Bake cache folder (as for daylit bake)");
  cmd->add_option("--out", options->out, "Estimates CSV (default estimates.csv)");
  cmd->add_option("--plot", options->plot, "Plot PNG (default: the CSV's name with .png)");
  cmd->add_option("--residuals", options->residuals,
                  "A folder for the self-check that needs no truth: per surface and sunlit/shadowed stratum, over the "
                  "run and per burst, observed/predicted radiance (residuals.csv, residuals.png, "
                  "worst_frame_residuals.png; biased surfaces are named on stderr with their likely cause), and the fit "
                  "repeated with each stratum left out (split_check.csv, split_check.png; bursts whose estimate one "
                  "stratum moves beyond --split-threshold are named on stderr)");
  cmd->add_option("--residual-threshold", options->residual.threshold,
                  "A surface is biased when its ratio is further than this from 1 in a channel (default 0.12)");
  cmd->add_option("--split-threshold", options->split.threshold,
                  "A burst's split is flagged when one stratum left out moves E_sun or E_sky by more than this "
                  "(jackknife standard error, relative; default 0.05)");
  cmd->add_option("--figures", options->figures,
                  "Also write the run's figures as JSON (fps, ms per frame, errors against the truth; docs/results.md)");
  cmd->add_option("--samples", options->pipeline.estimator.sampler.samples, "Samples per frame (default 8000)")
      ->check(CLI::Range(100, 1000000));
  cmd->add_option("--frames", options->pipeline.max_frames, "Stop after this many frames (a live camera runs until Ctrl-C)")
      ->check(FrameCount());
  cmd->callback([options] { RunEstimateCommand(*options); });
}

}  // namespace daylit::app
