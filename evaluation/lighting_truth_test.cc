#include "evaluation/lighting_truth.h"

#include <gtest/gtest.h>

#include <cmath>

#include "base/utc_time.h"

namespace daylit::evaluation {
namespace {

estimation::FrameEstimate Frame(int index, double seconds, double sun_r, double sky_r) {
  estimation::FrameEstimate f;
  f.frame = index;
  f.time_utc = UtcFromUnixSeconds(1.8e9 + seconds);
  f.light.sun_rgb = glm::dvec3(sun_r, 10.0, 10.0);
  f.light.sky_rgb = glm::dvec3(sky_r, 2.0, 2.0);
  f.confidence = 0.5 + 0.01 * index;
  f.sunlit_samples = 100 + index, f.shadowed_samples = 200 + index;
  f.sun_up = true;
  return f;
}

// Two bursts of three frames 0.1 s apart, an hour between them, and a frame 2 s after the last:
// a third burst (less than 2 s apart is the same burst).
std::vector<estimation::FrameEstimate> Frames() {
  return {Frame(0, 0.0, 10, 2), Frame(1, 0.1, 11, 2), Frame(2, 0.2, 12, 2),
          Frame(3, 3600.0, 10, 1), Frame(4, 3600.1, 10, 3), Frame(5, 3601.9, 10, 2), Frame(6, 3603.9, 10, 2)};
}

TEST(LightingTruthTest, BurstsAreFramesLessThanTwoSecondsApart) {
  const std::vector<Burst> bursts = SplitBursts(Frames());
  ASSERT_EQ(bursts.size(), 3u);
  EXPECT_EQ(bursts[0].begin, 0u);
  EXPECT_EQ(bursts[0].end, 3u);
  EXPECT_EQ(bursts[1].begin, 3u);
  EXPECT_EQ(bursts[1].end, 6u);  // 1.8 s after the one before: the same burst
  EXPECT_EQ(bursts[2].begin, 6u);  // 2.0 s after: a new one
  EXPECT_TRUE(SplitBursts({}).empty());
}

TEST(LightingTruthTest, EachBurstHasItsOwnMedianErrors) {
  std::vector<estimation::FrameEstimate> frames = Frames();
  frames[4].sunlit_samples = 0;    // burst 1: one frame with the sun up and nothing sunlit,
  frames[3].shadowed_samples = 0;  // one with nothing in shade
  frames[5].sunlit_samples = 0, frames[5].sun_up = false;  // and one with the sun down: not empty
  for (estimation::FrameEstimate& f : frames) {  // every frame's 90% interval: ±30% on E_sun, ±10% on E_sky
    f.interval.known = f.interval.sun_observed = true;
    f.interval.sun = glm::dvec3(0.3), f.interval.sky = glm::dvec3(0.1);
  }
  TruthComparison truth;
  for (size_t i = 0; i < frames.size(); ++i) truth.truth.push_back({glm::dvec3(10.0), glm::dvec3(2.0)});
  truth.truth[1].sun_rgb = glm::dvec3(0.0);  // no sun there: left out of E_sun's errors
  const std::vector<BurstLighting> bursts = CompareBursts(frames, &truth);
  ASSERT_EQ(bursts.size(), 3u);
  // Burst 0: E_sun errors 0 and 20% (frame 1 has no true sun, and its 10% is left out): of two,
  // the median is the upper one (base/statistics.h); E_sky exact.
  EXPECT_NEAR(bursts[0].sun_error.x, 0.20, 1e-12);
  EXPECT_NEAR(bursts[0].sky_error.x, 0.0, 1e-12);
  // Burst 1: E_sky errors 50%, 50%, 0: median 50%, while the whole run's median is 0.
  EXPECT_NEAR(bursts[1].sky_error.x, 0.5, 1e-12);
  EXPECT_NEAR(bursts[1].sun_error.x, 0.0, 1e-12);
  EXPECT_EQ(bursts[1].first_frame, 3);
  EXPECT_EQ(bursts[1].last_frame, 5);
  EXPECT_NEAR(bursts[1].confidence, 0.54, 1e-12);
  EXPECT_NEAR(bursts[1].min_confidence, 0.53, 1e-12);
  EXPECT_EQ(bursts[1].frames_without_sunlit, 1);
  EXPECT_EQ(bursts[1].frames_without_shadowed, 1);
  EXPECT_EQ(bursts[0].frames_without_sunlit + bursts[0].frames_without_shadowed, 0);
  EXPECT_EQ(bursts[0].sunlit_samples, 101);  // median of 100, 101, 102
  EXPECT_EQ(bursts[1].sunlit_samples, 0);    // of 0, 0, 103: the upper of the middle
  const std::string csv = BurstsCsv(bursts);
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "burst,first_frame,last_frame,frames,sun_elevation_deg,sun_r,sun_g,sun_b,sky_r,sky_g,sky_b,confidence,"
            "min_confidence,sunlit_samples,shadowed_samples,frames_without_sunlit,frames_without_shadowed,sun_r_lo,"
            "sun_r_hi,sun_g_lo,sun_g_hi,sun_b_lo,sun_b_hi,sky_r_lo,sky_r_hi,sky_g_lo,sky_g_hi,sky_b_lo,sky_b_hi,"
            "frames_sun_not_observed,sun_error_r,sun_error_g,sun_error_b,sky_error_r,sky_error_g,sky_error_b,"
            "interval_covers,true_sun_share_r,true_sun_share_g,true_sun_share_b");
  // The interval: burst 0's errors (20%, 0) lie within ±30% and ±10%, burst 1's E_sky (50%) does not.
  EXPECT_TRUE(bursts[0].interval_covers);
  EXPECT_FALSE(bursts[1].interval_covers);
  EXPECT_NEAR(bursts[1].sky_half_width.x, 0.1, 1e-12);
  EXPECT_NE(csv.find(",0,204,1,1,"), std::string::npos) << csv;  // burst 1: medians 0 and 204, one empty each
  // Without truth: the estimates only.
  EXPECT_FALSE(CompareBursts(frames, nullptr)[0].has_truth);
  EXPECT_TRUE(std::isnan(CompareBursts(frames, nullptr)[0].sun_error.x));
}

// Issue 51: where the true sun is under 10% of the horizontal light, E_sun's bar is its interval.
// The sun at 30° (sin 0.5): E_sun 10 against E_sky 2 is 5 / 7 = 71% of the horizontal light; E_sun
// 0.3 against 2 is 0.15 / 2.15 = 7.0%, a weak sun, whose estimate of 0.36 (20% off) the interval of
// ±30% holds.
TEST(LightingTruthTest, AWeakSunIsJudgedByItsInterval) {
  std::vector<estimation::FrameEstimate> frames = {Frame(0, 0.0, 10, 2), Frame(1, 0.1, 10, 2), Frame(2, 3600.0, 0.36, 2)};
  TruthComparison truth;
  for (estimation::FrameEstimate& f : frames) {
    f.sun_elevation_deg = 30.0;
    f.interval.known = f.interval.sun_observed = true;
    f.interval.sun = glm::dvec3(0.3), f.interval.sky = glm::dvec3(0.1);
    truth.truth.push_back({glm::dvec3(f.light.sun_rgb.x < 1.0 ? 0.3 : 10.0, 10.0, 10.0), glm::dvec3(2.0)});
  }
  const std::vector<BurstLighting> bursts = CompareBursts(frames, &truth);
  ASSERT_EQ(bursts.size(), 2u);
  EXPECT_NEAR(bursts[0].true_sun_share.x, 5.0 / 7.0, 1e-9);
  EXPECT_FALSE(bursts[0].WeakSun(0));
  EXPECT_NEAR(bursts[1].true_sun_share.x, 0.15 / 2.15, 1e-9);
  EXPECT_TRUE(bursts[1].WeakSun(0));
  EXPECT_FALSE(bursts[1].WeakSun(1));  // green's sun is strong there
  EXPECT_NEAR(bursts[1].sun_error.x, 0.2, 1e-9);
  EXPECT_TRUE(bursts[1].SunHeldByInterval(0));
}

// A burst whose sun is not observed in most frames, estimated at 0: its E_sun bound in bursts.csv
// is the median of those frames' sun_bound, not 0; a burst where it is observed in most has none.
TEST(LightingTruthTest, ABurstWhoseSunIsNotObservedIsBoundedByWhatItsFramesWouldHaveSeen) {
  std::vector<estimation::FrameEstimate> frames = Frames();
  for (estimation::FrameEstimate& f : frames) {
    f.light.sun_rgb = glm::dvec3(0.0);
    f.interval.known = true, f.interval.sun_observed = false;
    f.interval.sun = glm::dvec3(10.0), f.interval.sky = glm::dvec3(0.1);
    f.interval.sun_bound = glm::dvec3(1.0, 2.0, 3.0) * static_cast<double>(f.frame + 1);
  }
  frames[4].interval.sun_observed = frames[5].interval.sun_observed = true;  // burst 1: observed in two of three
  frames[4].interval.sun = frames[5].interval.sun = glm::dvec3(0.2);
  const std::vector<BurstLighting> bursts = CompareBursts(frames, nullptr);
  ASSERT_EQ(bursts.size(), 3u);
  EXPECT_EQ(bursts[0].sun_bound, glm::dvec3(2.0, 4.0, 6.0));  // frames 0-2: bounds 1, 2, 3 times (1, 2, 3)
  EXPECT_EQ(bursts[1].sun_bound, glm::dvec3(0.0));
  const std::string csv = BurstsCsv(bursts);
  // Burst 0: E_sun 0, 0, 0 with [0, 2], [0, 4], [0, 6]; E_sky 2 ± 10%.
  EXPECT_NE(csv.find(",0,2,0,4,0,6,1.8,2.2,"), std::string::npos) << csv;
}

TEST(LightingTruthTest, ConfidenceRankingIsTheAucOfBadFramesAgainstGoodOnes) {
  // Errors: two bad frames (> 10%), three good (≤ 5%), one in between and one without truth,
  // which count as neither.
  const std::vector<double> error = {0.20, 0.11, 0.01, 0.02, 0.05, 0.07, NAN};
  // Every bad frame below every good one: 1; every one above: 0.
  EXPECT_DOUBLE_EQ(RankByConfidence({0.1, 0.2, 0.9, 0.8, 0.7, 0.0, 0.0}, error).auc, 1.0);
  EXPECT_DOUBLE_EQ(RankByConfidence({0.9, 0.95, 0.1, 0.2, 0.3, 1.0, 1.0}, error).auc, 0.0);
  // The first bad frame below all three good ones (3); the second above one, tied with one and
  // below one (1 + 0.5): 4.5 of 6 pairs.
  const ConfidenceRanking r = RankByConfidence({0.1, 0.8, 0.9, 0.8, 0.7, 0.0, 0.0}, error);
  EXPECT_EQ(r.bad_frames, 2);
  EXPECT_EQ(r.good_frames, 3);
  EXPECT_DOUBLE_EQ(r.auc, (3.0 + 1.0 + 0.5) / 6.0);
  EXPECT_DOUBLE_EQ(r.bad_below_90_percent_of_good, 0.5);
  EXPECT_TRUE(std::isnan(RankByConfidence({0.5, 0.5}, {0.01, 0.02}).auc));  // no bad frame
}

}  // namespace
}  // namespace daylit::evaluation
