#include "evaluation/residuals.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "base/atomic_file.h"
#include "base/check.h"
#include "base/log.h"
#include "base/options_check.h"
#include "base/statistics.h"
#include "capture/frame_times.h"
#include "estimation/sun_sky_fit.h"
#include "report/plot.h"

namespace daylit::evaluation {
namespace {

// The largest |ratio − 1| over the channels.
double Deviation(const glm::dvec3& ratio) {
  return std::max({std::abs(ratio.x - 1.0), std::abs(ratio.y - 1.0), std::abs(ratio.z - 1.0)});
}

// Blue below 1, white at 1, red above, saturated at ±25%.
cv::Scalar RatioColor(double ratio) {
  const double t = std::clamp(std::log(std::max(ratio, 1e-6)) / std::log(1.25), -1.0, 1.0);
  const double fade = 255.0 * (1.0 - std::abs(t));
  return t >= 0.0 ? cv::Scalar(fade, fade, 255.0) : cv::Scalar(255.0, fade, fade);  // BGR
}

std::string RatioText(const glm::dvec3& r) { return fmt::format("{:.3f}/{:.3f}/{:.3f}", r.x, r.y, r.z); }

}  // namespace

std::string ResidualOptions::Check() const {
  return FirstProblem({InOpenClosed("threshold", threshold, 0.0, 10.0),
                       InClosed("min_samples_per_frame", min_samples_per_frame, 1, 1000000),
                       InClosed("min_frames", min_frames, 1, 1000000)});
}

ResidualSink::ResidualSink(const scene::Scene& scene, const bake::SceneBake& bake, ResidualOptions options)
    : scene_(scene), bake_(bake), options_(options), strata_(2 * scene.model.surface_names.size()) {
  DAYLIT_CHECK(options_.Check().empty(), "residual options: {}", options_.Check());
}

void ResidualSink::Consume(const pipeline::PipelineFrame& frame) {
  if (capture::StartsBurst(last_utc_, frame.frame.utc)) {
    bursts_.emplace_back(strata_.size());
  }
  last_utc_ = frame.frame.utc;
  const estimation::FrameLight& light = frame.light;
  if (!light.fit.IsUsable() || light.samples.empty()) return;
  std::vector<glm::dvec3> observed(strata_.size(), glm::dvec3(0.0)), predicted(strata_.size(), glm::dvec3(0.0));
  std::vector<size_t> count(strata_.size(), 0);
  for (const estimation::Sample& s : light.samples) {
    const uint32_t surface = bake_.camera.surface[s.pixel];
    if (surface == bake::kNoSurface || 2 * static_cast<size_t>(surface) + 1 >= strata_.size()) continue;
    const size_t key = 2 * static_cast<size_t>(surface) + (s.sunlit ? 1 : 0);
    observed[key] += glm::dvec3(s.radiance);
    predicted[key] += glm::dvec3(estimation::PredictedRadiance(s, light.fit.light, light.fit.overcast_share));
    ++count[key];
  }
  for (size_t key = 0; key < strata_.size(); ++key) {
    if (count[key] < static_cast<size_t>(options_.min_samples_per_frame)) continue;
    const glm::dvec3 p = glm::max(predicted[key], glm::dvec3(1e-12));
    for (Accumulated* a : {&strata_[key], &bursts_.back()[key]}) {
      a->ratios.push_back(observed[key] / p);
      a->samples += count[key];
    }
  }
  if (light.fit.residual_spread <= worst_spread_ || frame.frame.rgb.empty()) return;
  // The new worst frame: its grey image, darkened, with each sample coloured by its ratio.
  worst_spread_ = light.fit.residual_spread;
  worst_frame_ = frame.frame.index;
  cv::Mat grey;
  cv::cvtColor(frame.frame.rgb, grey, cv::COLOR_RGB2GRAY);
  grey.convertTo(grey, CV_8U, 0.6 * 255.0);
  cv::cvtColor(grey, worst_image_, cv::COLOR_GRAY2BGR);
  const uint32_t width = static_cast<uint32_t>(bake_.camera.width);
  for (const estimation::Sample& s : light.samples) {
    const glm::dvec3 p(estimation::PredictedRadiance(s, light.fit.light, light.fit.overcast_share));
    const double ratio = (s.radiance.x + s.radiance.y + s.radiance.z) / std::max(p.x + p.y + p.z, 1e-12);
    const cv::Rect dot(static_cast<int>(s.pixel % width) - 1, static_cast<int>(s.pixel / width) - 1, 3, 3);
    cv::rectangle(worst_image_, dot, RatioColor(ratio), cv::FILLED);
  }
}

std::optional<StratumResidual> ResidualSink::StratumOf(const std::vector<Accumulated>& strata, size_t surface,
                                                      bool sunlit) const {
  const Accumulated& a = strata[2 * surface + (sunlit ? 1 : 0)];
  if (a.ratios.empty()) return std::nullopt;
  StratumResidual r;
  r.surface = scene_.model.surface_names[surface];
  r.sunlit = sunlit;
  r.frames = static_cast<int>(a.ratios.size());
  r.samples = a.samples;
  for (int c = 0; c < 3; ++c) {
    std::vector<double> channel;
    for (const glm::dvec3& v : a.ratios) channel.push_back(v[c]);
    r.ratio[c] = MedianInPlace(channel, 1.0);
  }
  r.biased = r.frames >= options_.min_frames && Deviation(r.ratio) > options_.threshold;
  return r;
}

std::vector<StratumResidual> ResidualSink::Strata() const {
  std::vector<StratumResidual> out;
  for (size_t surface = 0; 2 * surface < strata_.size(); ++surface) {
    for (const bool sunlit : {true, false}) {
      if (const std::optional<StratumResidual> r = StratumOf(strata_, surface, sunlit)) out.push_back(*r);
    }
  }
  return out;
}

std::vector<StratumResidual> ResidualSink::BurstStrata() const {
  std::vector<StratumResidual> out;
  for (size_t b = 0; b < bursts_.size(); ++b) {
    for (size_t surface = 0; 2 * surface < strata_.size(); ++surface) {
      for (const bool sunlit : {true, false}) {
        if (std::optional<StratumResidual> r = StratumOf(bursts_[b], surface, sunlit)) {
          r->burst = static_cast<int>(b);
          out.push_back(*r);
        }
      }
    }
  }
  return out;
}

std::vector<ResidualFinding> ResidualSink::Findings() const {
  std::vector<ResidualFinding> findings;
  for (size_t surface = 0; 2 * surface < strata_.size(); ++surface) {
    const std::optional<StratumResidual> sunlit_stratum = StratumOf(strata_, surface, true),
                                         shadowed_stratum = StratumOf(strata_, surface, false);
    const StratumResidual* sunlit = sunlit_stratum ? &*sunlit_stratum : nullptr;
    const StratumResidual* shadowed = shadowed_stratum ? &*shadowed_stratum : nullptr;
    const bool sun_off = sunlit != nullptr && sunlit->biased, shade_off = shadowed != nullptr && shadowed->biased;
    if (!sun_off && !shade_off) continue;
    // Both strata judged and off the same way: the surface reflects more or less than its albedo
    // says. One stratum alone: what differs between them, the sun on it or the light around it.
    const auto brightness = [](const StratumResidual* r) { return r->ratio.x + r->ratio.y + r->ratio.z - 3.0; };
    const bool both_judged = sunlit != nullptr && shadowed != nullptr && sunlit->frames >= options_.min_frames &&
                             shadowed->frames >= options_.min_frames;
    std::string cause;
    if (sun_off && shade_off && brightness(sunlit) * brightness(shadowed) > 0.0) {
      cause = "its albedo";
    } else if (sun_off && !both_judged) {
      cause = "its albedo, or its geometry or the sun's visibility on it (only its sunlit part is seen)";
    } else if (shade_off && !both_judged) {
      cause = "its albedo, or light the model does not carry to it (only its shadowed part is seen)";
    } else if (sun_off) {
      cause = "its geometry or the sun's visibility on it (a normal, the pose, a shadow the model lacks)";
    } else {
      cause = "light the model does not carry to it: something unmodelled in front of it, or reflected light";
    }
    std::string where;
    if (sunlit != nullptr) where += fmt::format("sunlit {} over {} frames", RatioText(sunlit->ratio), sunlit->frames);
    if (shadowed != nullptr) {
      where += fmt::format("{}shadowed {} over {} frames", where.empty() ? "" : ", ", RatioText(shadowed->ratio),
                           shadowed->frames);
    }
    const std::string& name = scene_.model.surface_names[surface];
    findings.push_back({name, cause,
                        fmt::format("{}: observed/predicted radiance (R/G/B) {}, beyond {:.0f}%: likely {}", name,
                                    where, 100.0 * options_.threshold, cause)});
  }
  return findings;
}

std::string ResidualsCsv(const std::vector<StratumResidual>& strata) {
  std::string csv = "burst,surface,stratum,frames,samples,ratio_r,ratio_g,ratio_b,biased\n";
  for (const StratumResidual& r : strata) {
    csv += fmt::format("{},{},{},{},{},{:.4f},{:.4f},{:.4f},{}\n", r.burst < 0 ? "all" : std::to_string(r.burst), r.surface,
                       r.sunlit ? "sunlit" : "shadowed", r.frames, r.samples, r.ratio.x, r.ratio.y, r.ratio.z,
                       r.biased ? 1 : 0);
  }
  return csv;
}

void ResidualSink::Finish(const std::filesystem::path& dir, RunReport* report) const {
  std::filesystem::create_directories(dir);
  const std::vector<StratumResidual> strata = Strata(), per_burst = BurstStrata();
  std::vector<StratumResidual> all = strata;
  all.insert(all.end(), per_burst.begin(), per_burst.end());
  WriteFileAtomically(dir / "residuals.csv", ResidualsCsv(all));
  report::BarChartOptions chart;
  chart.title = fmt::format("{}: observed / predicted radiance per surface and stratum (median over frames)", scene_.name);
  chart.x_label = "observed / predicted (R, G, B)";
  chart.origin = 1.0;
  chart.colors = {{214, 39, 40}, {44, 160, 44}, {31, 119, 180}};
  std::vector<report::BarRow> rows;
  for (const StratumResidual& r : strata) {
    rows.push_back({fmt::format("{} {}{}", r.surface, r.sunlit ? "sunlit" : "shadow", r.biased ? " *" : ""),
                    {r.ratio.x, r.ratio.y, r.ratio.z}});
  }
  report::BarChartOptions burst_chart = chart;
  burst_chart.title = fmt::format("{}: the same per burst (median over each burst's frames)", scene_.name);
  std::vector<report::BarRow> burst_rows;
  for (const StratumResidual& r : per_burst) {
    burst_rows.push_back({fmt::format("burst {} {} {}{}", r.burst, r.surface, r.sunlit ? "sunlit" : "shadow", r.biased ? " *" : ""),
                          {r.ratio.x, r.ratio.y, r.ratio.z}});
  }
  report::WritePng(dir / "residuals.png", {report::RenderBarChart(chart, rows), report::RenderBarChart(burst_chart, burst_rows)});
  if (!worst_image_.empty()) report::WritePng(dir / "worst_frame_residuals.png", {worst_image_});
  const std::vector<ResidualFinding> findings = Findings();
  report->Say(fmt::format("residuals (observed/predicted per surface and stratum, no truth needed): {} of {} strata "
                          "beyond {:.0f}%; worst frame {} (residual spread {:.3f})",
                          std::count_if(strata.begin(), strata.end(), [](const StratumResidual& r) { return r.biased; }),
                          strata.size(), 100.0 * options_.threshold, worst_frame_, worst_spread_));
  for (const ResidualFinding& f : findings) {
    Log().warn("residuals: {}", f.message);
    report->Say("  " + f.message);
  }
  report->Figure("residuals/biased_surfaces", static_cast<double>(findings.size()));
}

}  // namespace daylit::evaluation
