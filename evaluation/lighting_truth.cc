#include "evaluation/lighting_truth.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <map>

#include <fmt/format.h>
#include <glm/gtx/component_wise.hpp>

#include "base/atomic_file.h"
#include "base/check.h"
#include "base/csv.h"
#include "base/statistics.h"
#include "report/plot.h"

namespace daylit::evaluation {
namespace {

double Median(std::vector<double> v) { return MedianInPlace(v, static_cast<double>(NAN)); }

}  // namespace

TruthComparison CompareWithTruth(const std::vector<estimation::FrameEstimate>& frames, const std::filesystem::path& groundtruth_csv) {
  const CsvTable table = ReadCsvFile(groundtruth_csv);
  const size_t c_frame = static_cast<size_t>(table.RequireColumn("frame"));
  std::array<size_t, 6> c{};
  const char* names[6] = {"sun_r", "sun_g", "sun_b", "sky_r", "sky_g", "sky_b"};
  for (size_t k = 0; k < 6; ++k) c[k] = static_cast<size_t>(table.RequireColumn(names[k]));
  std::map<int, estimation::SunSky> truth_by_frame;
  for (size_t r = 0; r < table.rows.size(); ++r) {
    estimation::SunSky t;
    for (int k = 0; k < 3; ++k) {
      t.sun_rgb[k] = ParseFiniteDouble(table.rows[r][c[static_cast<size_t>(k)]], table.Where(r));
      t.sky_rgb[k] = ParseFiniteDouble(table.rows[r][c[static_cast<size_t>(k) + 3]], table.Where(r));
    }
    truth_by_frame[static_cast<int>(ParseCount(table.rows[r][c_frame], table.Where(r) + ": frame", INT32_MAX))] = t;
  }
  TruthComparison cmp;
  std::array<std::vector<double>, 3> sun, sky, ratio;
  for (const estimation::FrameEstimate& f : frames) {
    const auto it = truth_by_frame.find(f.frame);
    cmp.truth.push_back(it == truth_by_frame.end() ? estimation::SunSky{glm::dvec3(NAN), glm::dvec3(NAN)} : it->second);
    cmp.worst_channel_error.push_back(NAN);
    if (it == truth_by_frame.end() || !f.Decoded()) continue;
    ++cmp.frames;
    double frame_worst = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double ts = it->second.sun_rgb[k], tk = it->second.sky_rgb[k];
      if (tk > 0) sky[static_cast<size_t>(k)].push_back(std::abs(f.light.sky_rgb[k] / tk - 1.0));
      if (ts > 0) sun[static_cast<size_t>(k)].push_back(std::abs(f.light.sun_rgb[k] / ts - 1.0));
      if (tk > 0) frame_worst = std::max(frame_worst, std::abs(f.light.sky_rgb[k] / tk - 1.0));
      if (ts > 0) frame_worst = std::max(frame_worst, std::abs(f.light.sun_rgb[k] / ts - 1.0));
      if (ts > 0 && tk > 0 && f.light.sky_rgb[k] > 0) {
        ratio[static_cast<size_t>(k)].push_back(std::abs((f.light.sun_rgb[k] / f.light.sky_rgb[k]) / (ts / tk) - 1.0));
      }
    }
    cmp.worst_channel_error.back() = frame_worst;
  }
  std::vector<double> worst;
  std::copy_if(cmp.worst_channel_error.begin(), cmp.worst_channel_error.end(), std::back_inserter(worst),
               [](double e) { return !std::isnan(e); });
  cmp.p90_worst_channel_error = PercentileInPlace(worst, 0.9, cmp.p90_worst_channel_error);
  std::vector<double> confidence;
  for (const estimation::FrameEstimate& f : frames) confidence.push_back(f.confidence);
  cmp.ranking = RankByConfidence(confidence, cmp.worst_channel_error);
  for (int k = 0; k < 3; ++k) {
    cmp.sun_error[k] = Median(sun[static_cast<size_t>(k)]);
    cmp.sky_error[k] = Median(sky[static_cast<size_t>(k)]);
    cmp.ratio_error[k] = Median(ratio[static_cast<size_t>(k)]);
  }
  return cmp;
}

ConfidenceRanking RankByConfidence(const std::vector<double>& confidence, const std::vector<double>& error) {
  DAYLIT_CHECK(confidence.size() == error.size(), "{} confidences for {} errors", confidence.size(), error.size());
  std::vector<double> bad, good;
  for (size_t i = 0; i < error.size(); ++i) {
    if (error[i] > kBadFrameError) bad.push_back(confidence[i]);
    if (error[i] <= kGoodFrameError) good.push_back(confidence[i]);
  }
  ConfidenceRanking r;
  r.bad_frames = static_cast<int>(bad.size()), r.good_frames = static_cast<int>(good.size());
  if (bad.empty() || good.empty()) return r;
  std::sort(good.begin(), good.end());
  double wins = 0.0;
  int below_90 = 0;
  for (const double b : bad) {
    const auto lo = std::lower_bound(good.begin(), good.end(), b), hi = std::upper_bound(good.begin(), good.end(), b);
    const double above = static_cast<double>(good.end() - hi), tied = static_cast<double>(hi - lo);
    wins += above + 0.5 * tied;
    below_90 += above >= 0.9 * static_cast<double>(good.size()) ? 1 : 0;
  }
  r.auc = wins / (static_cast<double>(bad.size()) * static_cast<double>(good.size()));
  r.bad_below_90_percent_of_good = static_cast<double>(below_90) / static_cast<double>(bad.size());
  return r;
}

std::filesystem::path BurstsCsvPath(const std::filesystem::path& csv) {
  if (csv.filename() == "estimates.csv") return csv.parent_path() / "bursts.csv";
  return csv.parent_path() / (csv.stem().string() + "_bursts.csv");
}

std::filesystem::path ReportPathBeside(const std::filesystem::path& csv) {
  if (csv.filename() == "estimates.csv") return csv.parent_path() / "report.txt";
  return csv.parent_path() / (csv.stem().string() + "_report.txt");
}

std::vector<Burst> SplitBursts(const std::vector<estimation::FrameEstimate>& frames) {
  std::vector<Burst> bursts;
  for (size_t i = 0; i < frames.size(); ++i) {
    if (i == 0 || capture::StartsBurst(frames[i - 1].time_utc, frames[i].time_utc)) {
      bursts.push_back({static_cast<int>(bursts.size()), i, i});
    }
    bursts.back().end = i + 1;
  }
  return bursts;
}

std::vector<BurstLighting> CompareBursts(const std::vector<estimation::FrameEstimate>& frames, const TruthComparison* truth) {
  std::vector<BurstLighting> out;
  for (const Burst& b : SplitBursts(frames)) {
    BurstLighting r;
    r.burst = b;
    r.first_frame = frames[b.begin].frame, r.last_frame = frames[b.end - 1].frame;
    r.sun_elevation_deg = frames[b.begin].sun_elevation_deg;
    std::array<std::vector<double>, 3> sun, sky, sun_error, sky_error, sun_half, sky_half, sun_bound, sun_share;
    std::vector<double> confidence, sunlit, shadowed;
    r.min_confidence = 1.0;
    for (size_t i = b.begin; i < b.end; ++i) {
      const estimation::FrameEstimate& f = frames[i];
      if (!f.Decoded()) continue;
      confidence.push_back(f.confidence);
      sunlit.push_back(f.sunlit_samples), shadowed.push_back(f.shadowed_samples);
      r.frames_without_sunlit += f.sun_up && f.sunlit_samples == 0 ? 1 : 0;
      r.frames_without_shadowed += f.shadowed_samples == 0 ? 1 : 0;
      r.min_confidence = std::min(r.min_confidence, f.confidence);
      r.frames_sun_not_observed += f.interval.known && !f.interval.sun_observed ? 1 : 0;
      for (size_t k = 0; k < 3; ++k) {
        sun[k].push_back(f.light.sun_rgb[static_cast<int>(k)]), sky[k].push_back(f.light.sky_rgb[static_cast<int>(k)]);
        if (f.interval.known) {
          sun_half[k].push_back(f.interval.sun[static_cast<int>(k)]), sky_half[k].push_back(f.interval.sky[static_cast<int>(k)]);
          if (!f.interval.sun_observed) sun_bound[k].push_back(f.interval.sun_bound[static_cast<int>(k)]);
        }
        if (truth == nullptr) continue;
        const estimation::SunSky& t = truth->truth[i];
        const int c = static_cast<int>(k);
        if (t.sun_rgb[c] > 0) sun_error[k].push_back(std::abs(f.light.sun_rgb[c] / t.sun_rgb[c] - 1.0));
        if (t.sky_rgb[c] > 0) sky_error[k].push_back(std::abs(f.light.sky_rgb[c] / t.sky_rgb[c] - 1.0));
        const double horizontal = std::max(0.0, t.sun_rgb[c] * std::sin(glm::radians(f.sun_elevation_deg)));
        if (horizontal + t.sky_rgb[c] > 0.0) sun_share[k].push_back(horizontal / (horizontal + t.sky_rgb[c]));
      }
    }
    r.confidence = Median(confidence);
    if (!sunlit.empty()) r.sunlit_samples = static_cast<int>(Median(sunlit)), r.shadowed_samples = static_cast<int>(Median(shadowed));
    r.has_truth = truth != nullptr;
    for (int c = 0; c < 3; ++c) {
      const size_t k = static_cast<size_t>(c);
      r.sun[c] = Median(sun[k]), r.sky[c] = Median(sky[k]);
      if (!sun_half[k].empty()) r.sun_half_width[c] = Median(sun_half[k]), r.sky_half_width[c] = Median(sky_half[k]);
      if (!sun_bound[k].empty() && 2 * sun_bound[k].size() >= sun_half[k].size()) r.sun_bound[c] = Median(sun_bound[k]);
      if (r.has_truth) r.sun_error[c] = Median(sun_error[k]), r.sky_error[c] = Median(sky_error[k]);
      if (!sun_share[k].empty()) r.true_sun_share[c] = Median(sun_share[k]);
    }
    if (r.has_truth) {
      r.interval_covers = true;
      for (int c = 0; c < 3; ++c) {
        // A NaN error (no truth in the burst) or width (no fit) covers nothing.
        if (!std::isnan(r.sun_error[c]) && !(r.sun_error[c] <= r.sun_half_width[c])) r.interval_covers = false;
        if (!std::isnan(r.sky_error[c]) && !(r.sky_error[c] <= r.sky_half_width[c])) r.interval_covers = false;
      }
    }
    out.push_back(r);
  }
  return out;
}

std::string BurstsCsv(const std::vector<BurstLighting>& bursts) {
  const bool truth = !bursts.empty() && bursts[0].has_truth;
  std::string csv = "burst,first_frame,last_frame,frames,sun_elevation_deg,sun_r,sun_g,sun_b,sky_r,sky_g,sky_b,confidence,"
                    "min_confidence,sunlit_samples,shadowed_samples,frames_without_sunlit,frames_without_shadowed,";
  csv += estimation::IntervalCsvHeader();
  csv += ",frames_sun_not_observed";
  csv += truth ? ",sun_error_r,sun_error_g,sun_error_b,sky_error_r,sky_error_g,sky_error_b,interval_covers,"
                 "true_sun_share_r,true_sun_share_g,true_sun_share_b\n"
               : "\n";
  for (const BurstLighting& b : bursts) {
    csv += fmt::format("{},{},{},{},{:.3f},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.4f},{:.4f}", b.burst.index,
                       b.first_frame, b.last_frame, b.burst.end - b.burst.begin, b.sun_elevation_deg, b.sun.x, b.sun.y,
                       b.sun.z, b.sky.x, b.sky.y, b.sky.z, b.confidence, b.min_confidence);
    csv += fmt::format(",{},{},{},{}", b.sunlit_samples, b.shadowed_samples, b.frames_without_sunlit,
                       b.frames_without_shadowed);
    estimation::LightInterval interval;
    interval.sun = b.sun_half_width, interval.sky = b.sky_half_width, interval.sun_bound = b.sun_bound;
    csv += estimation::IntervalCsvFields(estimation::BoundsOf({b.sun, b.sky}, interval));
    csv += fmt::format(",{}", b.frames_sun_not_observed);
    if (truth) {
      csv += fmt::format(",{:.5f},{:.5f},{:.5f},{:.5f},{:.5f},{:.5f},{},{:.4f},{:.4f},{:.4f}", b.sun_error.x, b.sun_error.y,
                         b.sun_error.z, b.sky_error.x, b.sky_error.y, b.sky_error.z, b.interval_covers ? 1 : 0,
                         b.true_sun_share.x, b.true_sun_share.y, b.true_sun_share.z);
    }
    csv += "\n";
  }
  return csv;
}

void PlotEstimates(const std::vector<estimation::FrameEstimate>& frames, const TruthComparison* truth, const std::string& title,
                   const std::filesystem::path& png) {
  std::vector<cv::Mat> panels;
  for (const bool sun : {true, false}) {
    report::LinePlot plot({sun ? title + ": E_sun (DNI), estimate solid, truth dashed" : "E_sky (DHI)",
                           sun ? "" : "frame", "radiance units", 1400, 360, true});
    for (int k = 0; k < 3; ++k) {
      const std::array<int, 3> color = k == 0 ? std::array<int, 3>{214, 39, 40} : k == 1 ? std::array<int, 3>{44, 160, 44}
                                                                                          : std::array<int, 3>{31, 119, 180};
      report::Series est{std::string(1, "RGB"[k]), {}, {}, color, false, false};
      report::Series tru{std::string(1, "RGB"[k]) + " truth", {}, {}, color, true, false};
      for (size_t i = 0; i < frames.size(); ++i) {
        est.x.push_back(frames[i].frame);
        est.y.push_back(sun ? frames[i].light.sun_rgb[k] : frames[i].light.sky_rgb[k]);
        if (truth != nullptr) {
          tru.x.push_back(frames[i].frame);
          tru.y.push_back(sun ? truth->truth[i].sun_rgb[k] : truth->truth[i].sky_rgb[k]);
        }
      }
      plot.Add(std::move(est));
      if (truth != nullptr) plot.Add(std::move(tru));
    }
    // Each burst's start as a grey dashed line from 0 to the top of the data.
    double top = 0.0;
    for (size_t i = 0; i < frames.size(); ++i) {
      const estimation::SunSky& l = frames[i].light;
      top = std::max(top, std::max(glm::compMax(sun ? l.sun_rgb : l.sky_rgb), 0.0));
      if (truth != nullptr && std::isfinite(truth->truth[i].sun_rgb.x)) {
        top = std::max(top, glm::compMax(sun ? truth->truth[i].sun_rgb : truth->truth[i].sky_rgb));
      }
    }
    report::Series starts{"burst starts", {}, {}, {150, 150, 150}, true, false};
    for (const Burst& b : SplitBursts(frames)) {
      if (b.begin == 0) continue;
      const double x = frames[b.begin].frame;
      starts.x.insert(starts.x.end(), {x, x, x}), starts.y.insert(starts.y.end(), {0.0, top, NAN});
    }
    if (!starts.x.empty()) plot.Add(std::move(starts));
    panels.push_back(plot.Render());
  }
  report::WritePng(png, panels);
}

namespace {

// The per-burst table as report lines and figures (lighting/burst/<k>/...), and bursts.csv.
void ReportBursts(const std::vector<BurstLighting>& bursts, const std::filesystem::path& csv, RunReport* report) {
  WriteFileAtomically(csv, BurstsCsv(bursts));
  const bool truth = !bursts.empty() && bursts[0].has_truth;
  report->Say(fmt::format("per burst (frames less than {:g} s apart){}:", kBurstGapS,
                          truth ? ", median relative error (R, G, B)" : ", median estimate (R, G, B)"));
  report->Say(fmt::format("  {:>5} {:>9} {:>6}  {:<22}{:<22}{}", "burst", "frames", "sun", "E_sun", "E_sky",
                          "confidence (median, lowest)"));
  for (const BurstLighting& b : bursts) {
    const auto three = [&](const glm::dvec3& v) {
      return truth ? fmt::format("{:5.1f}% {:5.1f}% {:5.1f}%", 100 * v.x, 100 * v.y, 100 * v.z)
                   : fmt::format("{:6.4g} {:6.4g} {:6.4g}", v.x, v.y, v.z);
    };
    report->Say(fmt::format("  {:>5} {:>9} {:5.1f}°  {:<22}{:<22}{:.2f}, {:.2f}", b.burst.index,
                            fmt::format("{}-{}", b.first_frame, b.last_frame), b.sun_elevation_deg,
                            three(truth ? b.sun_error : b.sun), three(truth ? b.sky_error : b.sky), b.confidence,
                            b.min_confidence));
    const std::string key = fmt::format("lighting/burst/{}/", b.burst.index);
    report->Figure(key + "confidence", b.confidence);
    report->Figure(key + "sun_elevation_deg", b.sun_elevation_deg);
    report->Figure(key + "frames_without_sunlit", b.frames_without_sunlit);
    report->Figure(key + "frames_without_shadowed", b.frames_without_shadowed);
    for (int c = 0; truth && c < 3; ++c) {
      report->Figure(key + "sun_error/" + std::string(1, "rgb"[c]), b.sun_error[c]);
      report->Figure(key + "sky_error/" + std::string(1, "rgb"[c]), b.sky_error[c]);
      report->Figure(key + "true_sun_share/" + std::string(1, "rgb"[c]), b.true_sun_share[c]);
    }
  }
  // The 90% intervals, from the frames alone (estimation/light_interval.h), and with truth whether
  // each burst's errors lie within them.
  report->Say(fmt::format("  90% interval per burst (relative half-width, R, G, B; from the frames, not the truth){}:",
                          truth ? ", and whether it holds the error" : ""));
  std::vector<double> sun_widths, sky_widths;
  int covered = 0, with_interval = 0;
  for (const BurstLighting& b : bursts) {
    if (std::isnan(b.sky_half_width.x)) continue;
    ++with_interval;
    const std::string sun = b.frames_sun_not_observed * 2 > static_cast<int>(b.burst.end - b.burst.begin)
                                ? std::string("not observed")
                                : fmt::format("±{:.1f}% ±{:.1f}% ±{:.1f}%", 100 * b.sun_half_width.x,
                                              100 * b.sun_half_width.y, 100 * b.sun_half_width.z);
    report->Say(fmt::format("  {:>5}  E_sun {:<24} E_sky ±{:.1f}% ±{:.1f}% ±{:.1f}%{}", b.burst.index, sun,
                            100 * b.sky_half_width.x, 100 * b.sky_half_width.y, 100 * b.sky_half_width.z,
                            truth ? (b.interval_covers ? "  holds" : "  MISSES") : ""));
    const std::string key = fmt::format("lighting/burst/{}/", b.burst.index);
    for (int c = 0; c < 3; ++c) {
      report->Figure(key + "sun_half_width/" + std::string(1, "rgb"[c]), b.sun_half_width[c]);
      report->Figure(key + "sky_half_width/" + std::string(1, "rgb"[c]), b.sky_half_width[c]);
    }
    sun_widths.push_back(glm::compAdd(b.sun_half_width) / 3.0), sky_widths.push_back(glm::compAdd(b.sky_half_width) / 3.0);
    covered += b.interval_covers ? 1 : 0;
  }
  if (with_interval > 0) {
    report->Figure("lighting/interval/sun_half_width", Median(sun_widths));
    report->Figure("lighting/interval/sky_half_width", Median(sky_widths));
    if (truth) {
      report->Say(fmt::format("  the interval holds all six errors in {} of {} bursts", covered, with_interval));
      report->Figure("lighting/interval/covered_bursts", covered);
      report->Figure("lighting/interval/bursts", with_interval);
    }
  }
  for (const BurstLighting& b : bursts) {
    const int frames = static_cast<int>(b.burst.end - b.burst.begin);
    if (truth && (b.WeakSun(0) || b.WeakSun(1) || b.WeakSun(2))) {
      std::string channels;
      bool held = true;
      for (int c = 0; c < 3; ++c) {
        if (!b.WeakSun(c)) continue;
        channels += fmt::format("{}{} {:.1f}%", channels.empty() ? "" : ", ", "RGB"[c], 100 * b.true_sun_share[c]);
        held = held && b.SunHeldByInterval(c);
      }
      report->Say(fmt::format("  burst {}: the true sun is under {:g}% of the horizontal light ({}): a relative error of "
                              "E_sun means little there, and its bar is the interval, which {} it",
                              b.burst.index, 100 * kWeakSunShare, channels, held ? "holds" : "MISSES"));
    }
    if (b.frames_without_sunlit > 0) {
      report->Say(fmt::format("  burst {}: no sunlit sample in {} of {} frames while the sun was up: E_sun is not observed "
                              "there (fit confidence 0): the estimate holds the last fit that saw the sun, or the burst's "
                              "first fit, with E_sun = 0, if none did",
                              b.burst.index, b.frames_without_sunlit, frames));
    }
    if (b.frames_without_shadowed > 0) {
      report->Say(fmt::format("  burst {}: no shadowed sample in {} of {} frames: E_sun and E_sky are told apart by "
                              "the sunlit samples alone (fit confidence 0): the estimate holds the last fit that had both",
                              b.burst.index, b.frames_without_shadowed, frames));
    }
    if (b.frames_sun_not_observed > 0) {
      report->Say(fmt::format("  burst {}: E_sun not observed in {} of {} frames: the sun below the horizon, or too weak "
                              "a part of the sunlit samples' light (behind cloud) to be told from the sky; its interval "
                              "there runs from 0 to 11 times the value, and at least to the largest sun those frames "
                              "would not have seen",
                              b.burst.index, b.frames_sun_not_observed, frames));
    }
  }
  report->Figure("lighting/bursts", static_cast<double>(bursts.size()));
}

// How many frames were fitted and how (estimation::FrameStatus), as one report line and figures
// (lighting/frames_<status>, lighting/frames_held): what estimates.csv's status column says, counted.
void ReportFrameStatus(const std::vector<estimation::FrameEstimate>& frames, RunReport* report) {
  using estimation::FrameStatus;
  constexpr std::array<FrameStatus, 5> kAll{FrameStatus::kConverged, FrameStatus::kSkyOnly, FrameStatus::kNotConverged,
                                            FrameStatus::kTooFewSamples, FrameStatus::kUnreadable};
  std::array<int, kAll.size()> count{};
  for (const estimation::FrameEstimate& f : frames) ++count[static_cast<size_t>(f.status)];
  std::string parts;
  int held = 0;
  for (size_t k = 0; k < kAll.size(); ++k) {
    report->Figure(fmt::format("lighting/frames_{}", estimation::FrameStatusName(kAll[k])), count[k]);
    if (!estimation::IsFitted(kAll[k])) held += count[k];
    if (count[k] > 0) parts += fmt::format("{}{} {}", parts.empty() ? "" : ", ", count[k], estimation::FrameStatusName(kAll[k]));
  }
  report->Figure("lighting/frames_held", held);
  const int not_converged = count[static_cast<size_t>(FrameStatus::kNotConverged)];
  report->Say(fmt::format("frames by fit status (estimates.csv's status): {}{}{}", parts.empty() ? "none" : parts,
                          held > 0 ? fmt::format("; {} not fitted, each holding the estimate before it", held) : "",
                          not_converged > 0 ? fmt::format("; {} fitted with the reweighting still moving (the last iterate)",
                                                          not_converged)
                                            : ""));
}

}  // namespace

std::optional<TruthComparison> ReportLighting(const scene::Scene& scene, const std::vector<estimation::FrameEstimate>& frames,
                                              const std::filesystem::path& csv, const std::filesystem::path& png,
                                              RunReport* report) {
  WriteFileAtomically(csv, estimation::EstimatesCsv(frames));
  ReportFrameStatus(frames, report);
  std::optional<TruthComparison> truth;
  if (scene.groundtruth.lighting) truth = CompareWithTruth(frames, *scene.groundtruth.lighting);
  ReportBursts(CompareBursts(frames, truth ? &*truth : nullptr), BurstsCsvPath(csv), report);
  if (truth) {
    const auto line = [&](const char* what, const glm::dvec3& e) {
      report->Say(fmt::format("  {:<9}{:5.1f}% {:5.1f}% {:5.1f}%", what, 100 * e.x, 100 * e.y, 100 * e.z));
    };
    report->Say(fmt::format("lighting against groundtruth.csv, median relative error over {} frames (R, G, B):", truth->frames));
    line("E_sun", truth->sun_error);
    line("E_sky", truth->sky_error);
    line("sun/sky", truth->ratio_error);
    report->Say(fmt::format("  90th percentile over frames of the worst channel's error (E_sun and E_sky): {:.1f}%",
                            100 * truth->p90_worst_channel_error));
    const ConfidenceRanking& rank = truth->ranking;
    if (rank.bad_frames > 0 && rank.good_frames > 0) {
      report->Say(fmt::format("  confidence ranking: {} frames over {:g}% against {} within {:g}%: AUC {:.2f}; {:.0f}% of "
                              "those frames score below 90% of the good ones",
                              rank.bad_frames, 100 * kBadFrameError, rank.good_frames, 100 * kGoodFrameError, rank.auc,
                              100 * rank.bad_below_90_percent_of_good));
      report->Figure("lighting/confidence_auc", rank.auc);
    } else {
      report->Say(fmt::format("  confidence ranking: {} frames over {:g}%, {} within {:g}% (no ranking without both)",
                              rank.bad_frames, 100 * kBadFrameError, rank.good_frames, 100 * kGoodFrameError));
    }
    report->Figure("lighting/frames", truth->frames);
    report->Figure("lighting/bad_frames", rank.bad_frames);
    report->Figure("lighting/p90_worst_channel_error", truth->p90_worst_channel_error);
    for (int c = 0; c < 3; ++c) {
      const std::string channel(1, "rgb"[c]);
      report->Figure("lighting/sun_error/" + channel, truth->sun_error[c]);
      report->Figure("lighting/sky_error/" + channel, truth->sky_error[c]);
      report->Figure("lighting/ratio_error/" + channel, truth->ratio_error[c]);
    }
  }
  PlotEstimates(frames, truth ? &*truth : nullptr, scene.name, png);
  return truth;
}

}  // namespace daylit::evaluation
