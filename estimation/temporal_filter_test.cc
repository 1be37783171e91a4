#include "estimation/temporal_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace daylit::estimation {
namespace {

SunSky Light(double sun, double sky) { return {glm::dvec3(sun), glm::dvec3(sky)}; }

TEST(TemporalFilterTest, ACloudShowsOnTheFrameItArrives) {
  // Clear sky, then a cloud leaves 20% of the beam at frame 10 (10 fps).
  TemporalFilter filter;
  std::vector<double> sun;
  for (int f = 0; f < 20; ++f) {
    sun.push_back(filter.Update(0.1 * f, Light(f < 10 ? 100.0 : 20.0, 10.0), 1.0).light.sun_rgb.x);
  }
  EXPECT_NEAR(sun[9], 100.0, 1e-9);
  // The step beyond the noise band (3% of E_sun = 3.0) is taken at once, leaving 0.7 of the band;
  // then the band is the new light's, and what lies beyond it again goes at once.
  EXPECT_NEAR(sun[10], 20.0 + 0.7 * 3.0, 1e-9);
  EXPECT_LE(sun[11] - 20.0, 0.7 * 0.03 * sun[10] + 1e-9);
  EXPECT_LT(std::abs(sun[14] - 20.0), 0.005 * 80.0);  // within 0.5% of the step after 4 frames
}

TEST(TemporalFilterTest, TheSkyFollowsItsOwnStepUnderAStrongSun) {
  // A cloud leaves the sky around a low sun: E_sky drops 30% while E_sun holds at ten times it.
  // The sky's band is 3% of the sky, not of sun + sky (which would be a third of the sky here and
  // smooth the step over frames: courtyard-c's clearing frames had E_sky 34% high that way).
  TemporalFilter filter;
  std::vector<double> sky;
  for (int f = 0; f < 12; ++f) sky.push_back(filter.Update(0.1 * f, Light(100.0, f < 10 ? 13.0 : 10.0), 1.0).light.sky_rgb.y);
  EXPECT_NEAR(sky[9], 13.0, 1e-9);
  EXPECT_LE(sky[10] / 10.0 - 1.0, 0.7 * 0.03 * 13.0 / 10.0 + 1e-9);  // within 2.8% on the frame
  EXPECT_LE(sky[11] / 10.0 - 1.0, 0.7 * 0.03 + 1e-9);
}

TEST(TemporalFilterTest, AMedianWindowStopsASingleWildFit) {
  // Not the default (it delays each cloud edge by a frame), for sources with glitches.
  TemporalFilterOptions options;
  options.median_window = 3;
  TemporalFilter filter(options);
  double worst = 0.0;
  for (int f = 0; f < 30; ++f) {
    const double raw = f == 15 ? 300.0 : 100.0;  // one wild fit
    worst = std::max(worst, std::abs(filter.Update(0.1 * f, Light(raw, 10.0), 1.0).light.sun_rgb.x - 100.0));
  }
  EXPECT_LT(worst, 1e-9);
}

TEST(TemporalFilterTest, FrameToFrameNoiseIsReduced) {
  TemporalFilter filter;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);  // 1% of E_sun: the fits' jitter on courtyard-a
  double raw_sq = 0.0, out_sq = 0.0;
  int n = 0;
  for (int f = 0; f < 3000; ++f) {
    const double raw = 100.0 + noise(rng);
    const double out = filter.Update(0.1 * f, Light(raw, 10.0), 1.0).light.sun_rgb.x;
    if (f < 10) continue;
    raw_sq += (raw - 100.0) * (raw - 100.0), out_sq += (out - 100.0) * (out - 100.0), ++n;
  }
  const double ratio = std::sqrt(out_sq / raw_sq);
  EXPECT_NEAR(ratio, std::sqrt(0.3 / 1.7), 0.03);  // exponential smoothing with gain 0.3: 0.42
}

TEST(TemporalFilterTest, GapsRestartAndMissingFitsHold) {
  TemporalFilter filter;
  for (int f = 0; f < 10; ++f) filter.Update(0.1 * f, Light(100.0, 10.0), 1.0);
  const FilteredLight held = filter.Update(1.0, std::nullopt, 0.0);
  EXPECT_DOUBLE_EQ(held.light.sun_rgb.x, 100.0);
  EXPECT_LT(held.confidence, 1.0);  // holding, with fading trust
  // The next burst, two hours later: no blending of morning into noon.
  EXPECT_DOUBLE_EQ(filter.Update(7200.0, Light(300.0, 30.0), 0.9).light.sun_rgb.y, 300.0);
  // A fit with no confidence does not move the estimate.
  EXPECT_DOUBLE_EQ(filter.Update(7200.1, Light(0.0, 0.0), 0.0).light.sky_rgb.z, 30.0);
  // But the very first fit starts a filter, however unsure: there is nothing else to report.
  TemporalFilter fresh;
  EXPECT_DOUBLE_EQ(fresh.Update(0.0, Light(50.0, 5.0), 0.01).light.sun_rgb.x, 50.0);
}

}  // namespace
}  // namespace daylit::estimation
