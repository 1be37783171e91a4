// The estimates against a recording's ground truth (groundtruth.csv of recording-format.md), and
// their plot over time.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "capture/frame_times.h"
#include "estimation/frame_estimator.h"
#include "evaluation/run_report.h"
#include "scene/scene.h"

namespace daylit::evaluation {

struct ConfidenceRanking {
  int bad_frames = 0, good_frames = 0;  // worst channel > 10%, ≤ 5%
  double auc = NAN;
  // The share of bad frames that score below at least 90% of the good ones.
  double bad_below_90_percent_of_good = NAN;
};
constexpr double kBadFrameError = 0.10, kGoodFrameError = 0.05;
// The true sun's share of the horizontal light below which E_sun's bar is its interval, not its
// relative error (issue 51's "where the sun is so weak that a relative error means little").
constexpr double kWeakSunShare = 0.10;
// `confidence` and `error` aligned; frames with a NaN error are left out.
ConfidenceRanking RankByConfidence(const std::vector<double>& confidence, const std::vector<double>& error);

// Against groundtruth.csv: median over frames of |estimate/truth − 1| per channel, for E_sun
// (frames where the true E_sun is > 0), E_sky, and the sun/sky ratio. Throws InputError naming
// the file and row for a malformed table.
struct TruthComparison {
  glm::dvec3 sun_error{0.0}, sky_error{0.0}, ratio_error{0.0};
  int frames = 0;
  std::vector<estimation::SunSky> truth;  // per frame, aligned with the estimates
  // Per frame, aligned: the largest |estimate/truth − 1| over E_sun's and E_sky's channels (E_sun
  // where its truth is > 0); NaN without truth. Its 90th percentile over the frames with truth.
  std::vector<double> worst_channel_error;
  double p90_worst_channel_error = NAN;
  // Whether the confidence ranks frames by their error: the ROC AUC of "confidence lower" for the
  // frames whose worst channel is off by more than 10% against those within 5% (the probability
  // that such a bad frame scores below such a good one, ties half). NaN without both kinds.
  ConfidenceRanking ranking;
};
TruthComparison CompareWithTruth(const std::vector<estimation::FrameEstimate>& frames,
                                 const std::filesystem::path& groundtruth_csv);

// A burst: consecutive frames less than kBurstGapS apart (capture::StartsBurst; a time-lapse's
// bursts are hours apart).
// [begin, end) are positions in the run's frames.
struct Burst {
  int index = 0;
  size_t begin = 0, end = 0;
};
constexpr double kBurstGapS = capture::kBurstGapS;
std::vector<Burst> SplitBursts(const std::vector<estimation::FrameEstimate>& frames);

// One burst's estimates and, with truth, their errors: medians over its frames of
// |estimate/truth − 1| per channel (E_sun over frames whose true E_sun is > 0).
struct BurstLighting {
  Burst burst;
  int first_frame = 0, last_frame = 0;
  double sun_elevation_deg = 0.0;  // at its first frame
  glm::dvec3 sun{0.0}, sky{0.0};   // median estimates
  double confidence = 0.0;         // median
  double min_confidence = 0.0;
  // The fit's strata over the burst's decoded frames: median sample counts, and the frames where
  // one was empty (no sunlit sample while the sun was up: E_sun not observed; no shadowed one:
  // E_sky rests on the sunlit samples alone). Both lower the confidence.
  int sunlit_samples = 0, shadowed_samples = 0;
  int frames_without_sunlit = 0, frames_without_shadowed = 0;
  // The 90% interval (estimation/light_interval.h): the median over its decoded frames of their
  // relative half-widths, per channel, and the frames whose sun was not observed (too weak a part
  // of the sunlit samples' light for a width to mean anything).
  glm::dvec3 sun_half_width{NAN}, sky_half_width{NAN};
  int frames_sun_not_observed = 0;
  // Where the sun is not observed in half the burst's frames or more: the median of those frames'
  // sun_bound (light_interval.h), which the burst's E_sun bound in bursts.csv is at least; else 0.
  glm::dvec3 sun_bound{0.0};
  bool has_truth = false;
  glm::dvec3 sun_error{NAN}, sky_error{NAN};
  // With truth: each of the six errors within its half-width (E_sun's only where observed).
  bool interval_covers = false;
  // With truth: the true sun's share of the horizontal light, E_sun·sin(elevation) over that plus
  // E_sky, per channel, the median over the burst's frames. Under kWeakSunShare a relative error
  // of E_sun means little (a sun behind cloud, 4% of the light, read as 5% makes a 25% error), and
  // the bar there is its interval (issue 51): WeakSun(c), and whether the interval holds it.
  glm::dvec3 true_sun_share{NAN};
  bool WeakSun(int c) const { return true_sun_share[c] < kWeakSunShare; }
  bool SunHeldByInterval(int c) const { return sun_error[c] <= sun_half_width[c]; }
};
std::vector<BurstLighting> CompareBursts(const std::vector<estimation::FrameEstimate>& frames, const TruthComparison* truth);
// bursts.csv: burst,first_frame,last_frame,frames,sun_elevation_deg,sun_r,sun_g,sun_b,sky_r,sky_g,
// sky_b,confidence,min_confidence,sunlit_samples,shadowed_samples,frames_without_sunlit,
// frames_without_shadowed,sun_r_lo,sun_r_hi,...,sky_b_lo,sky_b_hi (the 90% interval around the
// burst's medians),frames_sun_not_observed[,sun_error_r,...,sky_error_b,interval_covers,
// true_sun_share_r,true_sun_share_g,true_sun_share_b with truth].
std::string BurstsCsv(const std::vector<BurstLighting>& bursts);

// Where the bursts' table goes beside the estimates' CSV `csv`: bursts.csv beside estimates.csv,
// else <stem>_bursts.csv.
std::filesystem::path BurstsCsvPath(const std::filesystem::path& csv);
// Where `daylit estimate` writes its report beside the estimates' CSV `csv` (evaluation/run_report.h:
// the text it prints, the version and how the run was started): report.txt beside estimates.csv,
// else <csv stem>_report.txt.
std::filesystem::path ReportPathBeside(const std::filesystem::path& csv);

// Estimate vs truth over time, per channel: a PNG with a sun panel and a sky panel.
void PlotEstimates(const std::vector<estimation::FrameEstimate>& frames, const TruthComparison* truth,
                   const std::string& title, const std::filesystem::path& png);

// The estimates of a run as estimates.csv (`csv`), the bursts' table beside it (<csv>_bursts.csv,
// bursts.csv beside a CSV named estimates.csv) and their plot (`png`, the bursts marked); the
// per-burst table and, with the scene's ground truth, the median errors and the 90th percentile
// as the report's lines and figures. Returns the comparison, if there was truth.
std::optional<TruthComparison> ReportLighting(const scene::Scene& scene, const std::vector<estimation::FrameEstimate>& frames,
                                              const std::filesystem::path& csv, const std::filesystem::path& png,
                                              RunReport* report);

}  // namespace daylit::evaluation
