#include "evaluation/split_check.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include "base/atomic_file.h"
#include "base/check.h"
#include "base/log.h"
#include "base/options_check.h"
#include "base/statistics.h"
#include "capture/frame_times.h"
#include "report/plot.h"

namespace daylit::evaluation {
namespace {

double Largest(const glm::dvec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }

int LargestChannel(const glm::dvec3& v) {
  return std::abs(v.x) >= std::abs(v.y) && std::abs(v.x) >= std::abs(v.z) ? 0 : std::abs(v.y) >= std::abs(v.z) ? 1 : 2;
}

// The relative change of `changed` against `full` per channel (0 where full is 0).
glm::dvec3 RelativeChange(const glm::dvec3& changed, const glm::dvec3& full) {
  glm::dvec3 out(0.0);
  for (int c = 0; c < 3; ++c) out[c] = full[c] > 0.0 ? changed[c] / full[c] - 1.0 : 0.0;
  return out;
}

// The jackknife standard error from the leave-one-out changes `moves`: √((K − 1)/K · Σ (m − m̄)²).
glm::dvec3 JackknifeError(const std::vector<glm::dvec3>& moves) {
  if (moves.size() < 2) return glm::dvec3(0.0);
  glm::dvec3 mean(0.0), square(0.0);
  for (const glm::dvec3& m : moves) mean += m;
  mean /= static_cast<double>(moves.size());
  for (const glm::dvec3& m : moves) square += (m - mean) * (m - mean);
  const double k = static_cast<double>(moves.size());
  return glm::sqrt((k - 1.0) / k * square);
}

glm::dvec3 MedianOf(const std::vector<glm::dvec3>& values) {
  glm::dvec3 out(0.0);
  for (int c = 0; c < 3; ++c) {
    std::vector<double> channel;
    for (const glm::dvec3& v : values) channel.push_back(v[c]);
    out[c] = MedianInPlace(channel, 0.0);
  }
  return out;
}

}  // namespace

std::string SplitCheckOptions::Check() const {
  return FirstProblem({InOpenClosed("threshold", threshold, 0.0, 10.0), InClosed("every", every, 1, 1000000),
                       InClosed("min_stratum_samples", min_stratum_samples, 1, 1000000), fit.Check()});
}

SplitCheck::SplitCheck(const scene::Scene& scene, const bake::SceneBake& bake, SplitCheckOptions options)
    : scene_(scene), bake_(bake), options_(std::move(options)) {
  DAYLIT_CHECK(options_.Check().empty(), "split check options: {}", options_.Check());
}

std::string SplitCheck::StratumName(uint32_t key) const {
  const uint32_t surface = key / 2;
  const std::string name = surface < scene_.model.surface_names.size() ? scene_.model.surface_names[surface] : "?";
  return fmt::format("{} {}", name, key % 2 == 1 ? "sunlit" : "shadowed");
}

SplitCheck::Checked SplitCheck::CheckFrame(const std::vector<estimation::Sample>& samples,
                                           const estimation::SunSkyFitSummary& fit) const {
  Checked out;
  std::map<uint32_t, size_t> count;
  std::vector<uint32_t> key_of(samples.size());
  size_t sunlit_strata = 0;
  for (size_t i = 0; i < samples.size(); ++i) {
    const uint32_t surface = bake_.camera.surface[samples[i].pixel];
    key_of[i] = 2 * surface + (samples[i].sunlit ? 1u : 0u);
    if (count[key_of[i]]++ == 0 && samples[i].sunlit) ++sunlit_strata;
  }
  std::vector<uint32_t> keys;
  for (const auto& [key, n] : count) {
    if (n >= static_cast<size_t>(options_.min_stratum_samples)) keys.push_back(key);
  }
  out.sun_present = fit.sunlit_samples > 0 && glm::length(fit.light.sun_rgb) > 0.0 &&
                    fit.sun_share_sunlit > options_.fit.absent_sun_share;
  std::vector<estimation::SunSkyFitSummary> refits(keys.size());
  std::vector<uint8_t> usable(keys.size(), 0);
  tbb::parallel_for(size_t{0}, keys.size(), [&](size_t k) {
    std::vector<estimation::Sample> others;
    others.reserve(samples.size());
    bool sunlit_left = false;
    for (size_t i = 0; i < samples.size(); ++i) {
      if (key_of[i] == keys[k]) continue;
      others.push_back(samples[i]);
      sunlit_left = sunlit_left || samples[i].sunlit;
    }
    // Without any sunlit sample E_sun is not observed and E_sky would take the reflected sun for
    // sky: that refit says nothing about the split.
    if (fit.sunlit_samples > 0 && !sunlit_left) return;
    refits[k] = estimation::FitSunSkyAsCarried(options_.fit, others, fit.carried_colour, fit.carried_weight);
    usable[k] = refits[k].IsUsable() ? 1 : 0;
  });
  std::vector<glm::dvec3> sun_moves, sky_moves;
  for (size_t k = 0; k < keys.size(); ++k) {
    if (!usable[k]) {
      if (keys[k] % 2 == 1 && sunlit_strata == 1) out.single_sunlit = true;
      continue;
    }
    const glm::dvec3 sky = RelativeChange(refits[k].light.sky_rgb, fit.light.sky_rgb);
    out.sky_moves.emplace_back(keys[k], sky);
    glm::dvec3 observed(0.0), predicted(0.0);
    for (size_t i = 0; i < samples.size(); ++i) {
      if (key_of[i] != keys[k]) continue;
      observed += glm::dvec3(samples[i].radiance);
      predicted += glm::dvec3(estimation::PredictedRadiance(samples[i], refits[k].light, refits[k].overcast_share));
    }
    out.held_out.emplace_back(keys[k], observed / glm::max(predicted, glm::dvec3(1e-12)));
    sky_moves.push_back(sky);
    if (out.sun_present) {
      const glm::dvec3 sun = RelativeChange(refits[k].light.sun_rgb, fit.light.sun_rgb);
      out.sun_moves.emplace_back(keys[k], sun);
      sun_moves.push_back(sun);
    }
  }
  out.sun_spread = JackknifeError(sun_moves);
  out.sky_spread = JackknifeError(sky_moves);
  return out;
}

void SplitCheck::Add(int frame, const UtcTime& utc, const std::vector<estimation::Sample>& samples,
                     const estimation::SunSkyFitSummary& fit) {
  if (bursts_.empty() || capture::StartsBurst(bursts_.back().last_utc, utc)) {
    bursts_.push_back({frame, frame, utc, 0, {}});
  }
  Burst& burst = bursts_.back();
  burst.last_frame = frame;
  burst.last_utc = utc;
  if (!fit.IsUsable() || samples.empty()) return;
  if (burst.fitted++ % options_.every != 0) return;
  burst.checked.push_back(CheckFrame(samples, fit));
}

std::vector<BurstSplit> SplitCheck::Bursts() const {
  std::vector<BurstSplit> out;
  for (size_t b = 0; b < bursts_.size(); ++b) {
    const Burst& burst = bursts_[b];
    BurstSplit r;
    r.burst = static_cast<int>(b);
    r.first_frame = burst.first_frame, r.last_frame = burst.last_frame;
    r.frames_checked = static_cast<int>(burst.checked.size());
    std::vector<glm::dvec3> sun_spread, sky_spread;
    std::map<uint32_t, std::vector<glm::dvec3>> sun_moves, sky_moves, held_out;
    for (const Checked& c : burst.checked) {
      for (const auto& [key, ratio] : c.held_out) held_out[key].push_back(ratio);
      sky_spread.push_back(c.sky_spread);
      if (c.sun_present) sun_spread.push_back(c.sun_spread);
      r.single_sunlit += c.single_sunlit ? 1 : 0;
      for (const auto& [key, move] : c.sun_moves) sun_moves[key].push_back(move);
      for (const auto& [key, move] : c.sky_moves) sky_moves[key].push_back(move);
    }
    r.sun_frames = static_cast<int>(sun_spread.size());
    r.sun_spread = MedianOf(sun_spread);
    r.sky_spread = MedianOf(sky_spread);
    for (const auto& [key, moves] : sky_moves) {
      StratumInfluence s;
      s.surface = scene_.model.surface_names[key / 2];
      s.sunlit = key % 2 == 1;
      s.frames = static_cast<int>(moves.size());
      s.sky = MedianOf(moves);
      if (const auto it = sun_moves.find(key); it != sun_moves.end()) s.sun = MedianOf(it->second);
      if (const auto it = held_out.find(key); it != held_out.end()) s.held_out = MedianOf(it->second);
      const double move = std::max(Largest(s.sky), Largest(s.sun));
      if (move > r.worst_move) r.worst_move = move, r.worst_stratum = StratumName(key);
      const double residual = Largest(s.held_out - glm::dvec3(1.0));
      if (residual > r.odd_residual) r.odd_residual = residual, r.odd_stratum = StratumName(key);
      r.strata.push_back(std::move(s));
    }
    r.flagged = std::max(Largest(r.sun_spread), Largest(r.sky_spread)) > options_.threshold;
    out.push_back(std::move(r));
  }
  return out;
}

std::string SplitCheckCsv(const std::vector<BurstSplit>& bursts) {
  std::string csv =
      "burst,first_frame,last_frame,frames_checked,sun_frames,sun_spread_r,sun_spread_g,sun_spread_b,sky_spread_r,"
      "sky_spread_g,sky_spread_b,single_sunlit_frames,worst_stratum,worst_move,odd_stratum,odd_residual,flagged\n";
  for (const BurstSplit& b : bursts) {
    csv += fmt::format("{},{},{},{},{},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{},{},{:.4f},{},{:.4f},{}\n", b.burst,
                       b.first_frame, b.last_frame, b.frames_checked, b.sun_frames, b.sun_spread.x, b.sun_spread.y,
                       b.sun_spread.z, b.sky_spread.x, b.sky_spread.y, b.sky_spread.z, b.single_sunlit, b.worst_stratum,
                       b.worst_move, b.odd_stratum, b.odd_residual, b.flagged ? 1 : 0);
  }
  return csv;
}

void SplitCheck::Finish(const std::filesystem::path& dir, RunReport* report) const {
  std::filesystem::create_directories(dir);
  const std::vector<BurstSplit> bursts = Bursts();
  WriteFileAtomically(dir / "split_check.csv", SplitCheckCsv(bursts));
  report::BarChartOptions chart;
  chart.title = fmt::format("{}: how far one stratum left out moves the estimate (jackknife, median over each burst; "
                            "flagged beyond {:.0f}%)",
                            scene_.name, 100.0 * options_.threshold);
  chart.x_label = "relative standard error (R, G, B)";
  chart.colors = {{214, 39, 40}, {44, 160, 44}, {31, 119, 180}};
  std::vector<report::BarRow> rows;
  for (const BurstSplit& b : bursts) {
    const char* mark = b.flagged ? " *" : "";
    rows.push_back({fmt::format("burst {} E_sun{}", b.burst, mark), {b.sun_spread.x, b.sun_spread.y, b.sun_spread.z}});
    rows.push_back({fmt::format("burst {} E_sky{}", b.burst, mark), {b.sky_spread.x, b.sky_spread.y, b.sky_spread.z}});
  }
  report::WritePng(dir / "split_check.png", {report::RenderBarChart(chart, rows)});
  const int flagged = static_cast<int>(std::count_if(bursts.begin(), bursts.end(), [](const BurstSplit& b) { return b.flagged; }));
  report->Say(fmt::format("split check (the fit with each stratum left out in turn, no truth needed): {} of {} bursts "
                          "move by more than {:.0f}%",
                          flagged, bursts.size(), 100.0 * options_.threshold));
  for (const BurstSplit& b : bursts) {
    if (!b.flagged) continue;
    const bool sun = Largest(b.sun_spread) >= Largest(b.sky_spread);
    const glm::dvec3& spread = sun ? b.sun_spread : b.sky_spread;
    const std::string message = fmt::format(
        "split check: burst {} (frames {}-{}): E_{} moves by {:.1f}% ({}, jackknife) with one stratum left out, "
        "{:.1f}% without {}; the stratum the others' light predicts worst is {} ({:+.1f}%): its model (albedo, the "
        "light reflected onto it, the sky it sees, something unmodelled in front of it) disagrees with the rest",
        b.burst, b.first_frame, b.last_frame, sun ? "sun" : "sky", 100.0 * Largest(spread), "RGB"[LargestChannel(spread)],
        100.0 * b.worst_move, b.worst_stratum, b.odd_stratum, 100.0 * b.odd_residual);
    Log().warn("{}", message);
    report->Say("  " + message);
  }
  report->Figure("split_check/flagged_bursts", static_cast<double>(flagged));
}

void SplitCheckSink::Consume(const pipeline::PipelineFrame& frame) {
  check_->Add(frame.frame.index, frame.frame.utc, frame.light.samples, frame.light.fit);
}

}  // namespace daylit::evaluation
