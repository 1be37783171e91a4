#include "estimation/sun_sky_fit.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <glm/gtc/constants.hpp>
#include <glm/gtx/component_wise.hpp>

#include "estimation/testing/surface_samples.h"

namespace daylit::estimation {
namespace {

// courtyard-a's clear morning: E_sun (DNI) and E_sky (DHI), radiance units.
const SunSky kClear{{86.26, 63.58, 37.08}, {9.86, 9.68, 9.96}};

// Samples as the sampler draws them: 40% in shadow, the rest sunlit at various angles; albedo and
// sky visibility as on textured walls and ground; transfer terms with light reflected from nearby
// surfaces (coloured, so they differ per channel; shadowed points get some sun that way).
// Radiance exactly the model's.
std::vector<Sample> MakeSamples(const SunSky& light, int count, std::mt19937& rng) {
  std::uniform_real_distribution<float> albedo(0.1f, 0.7f), cosine(0.1f, 1.0f), v(0.2f, 1.0f), pick(0, 1),
      bounce(0.0f, 0.12f);
  std::vector<Sample> samples(static_cast<size_t>(count));
  for (Sample& s : samples) {
    s.albedo = {albedo(rng), albedo(rng), albedo(rng)};
    s.sunlit = pick(rng) >= 0.4f;
    // One draw per statement: the order of a call's arguments is the compiler's, and the samples
    // must not depend on it.
    s.sun = glm::vec3(s.sunlit ? cosine(rng) : 0.0f);
    for (int c = 0; c < 3; ++c) s.sun[c] += bounce(rng);
    s.sky = glm::vec3(v(rng));
    for (int c = 0; c < 3; ++c) s.sky[c] += 0.5f * bounce(rng);
    s.overcast = s.sky;  // one sky shape (see the test with two)
    for (int c = 0; c < 3; ++c) {
      s.radiance[c] = static_cast<float>(s.albedo[c] / glm::pi<double>() *
                                         (s.sun[c] * light.sun_rgb[c] + s.sky[c] * light.sky_rgb[c]));
    }
  }
  return samples;
}

void ExpectNear(const SunSky& got, const SunSky& want, double relative) {
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(got.sun_rgb[c], want.sun_rgb[c], relative * want.sun_rgb[c]) << "sun channel " << c;
    EXPECT_NEAR(got.sky_rgb[c], want.sky_rgb[c], relative * want.sky_rgb[c]) << "sky channel " << c;
  }
}

TEST(SunSkyFitTest, ExactSamplesAreRecoveredTo0_1Percent) {
  std::mt19937 rng(1);
  const SunSkyFitSummary fit = FitSunSky({}, MakeSamples(kClear, 5000, rng));
  ASSERT_EQ(fit.status, SunSkyFitStatus::kConverged) << fit.message;
  ExpectNear(fit.light, kClear, 1e-3);
  EXPECT_GT(fit.confidence, 0.99);
}

// Samples of `count` points whose clear sky differs in shape from the overcast one by up to ±40%
// (points facing the sun see a clear sky as brighter than an overcast one, the aureole; points
// facing away as dimmer), lit by `sun`, a clear sky `clear` and a grey overcast `overcast`.
std::vector<Sample> TwoSkySamples(const glm::dvec3& sun, const glm::dvec3& clear, double overcast, int count,
                                  std::mt19937& rng) {
  std::uniform_real_distribution<float> shape(-0.15f, 0.15f);
  std::vector<Sample> samples = MakeSamples({sun, clear + overcast}, count, rng);
  for (Sample& s : samples) {
    s.overcast = s.sky;
    s.sky *= 0.75f + 0.5f * std::min(1.0f, s.sun.x) + shape(rng);
    for (int c = 0; c < 3; ++c) {
      s.radiance[c] = static_cast<float>(s.albedo[c] / glm::pi<double>() *
                                         (s.sun[c] * sun[c] + s.sky[c] * clear[c] + s.overcast[c] * overcast));
    }
  }
  return samples;
}

TEST(SunSkyFitTest, ASkyBetweenClearAndOvercastIsSplitAndSummed) {
  // A passing cloud: over half the DHI from a grey overcast part, the rest a bluish clear sky.
  std::mt19937 rng(11);
  const glm::dvec3 sun(30.0, 25.0, 20.0), clear(8.0, 8.5, 9.0);
  const double overcast = 12.0;
  const std::vector<Sample> samples = TwoSkySamples(sun, clear, overcast, 5000, rng);
  const SunSky light{sun, clear + overcast};
  const SunSkyFitSummary fit = FitSunSky({}, samples);
  ExpectNear(fit.light, light, 1e-3);
  // The share gives the grey part back: E_overcast = share · mean(E_sky) in every channel.
  const LightParts parts = SplitLight(fit.light, fit.overcast_share);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(parts.overcast[c], overcast, 1e-2) << c;
  // With one sky shape forced the same samples give a biased answer: the split is what fixes it.
  SunSkyFitOptions one_sky;
  one_sky.split_sky = false;
  const SunSkyFitSummary biased = FitSunSky(one_sky, samples);
  EXPECT_GT(std::abs(biased.light.sky_rgb.x / light.sky_rgb.x - 1.0), 0.01);
}

// A cloud over a weak sun, as the recordings' clouds are: the beam at 12%, a blue clear sky
// (the sky's colour) dimmed to half, a grey overcast part taking the rest. Clouds are grey, so the
// fit keeps the clear sky's blue in the clear part: E_sun comes back in every channel. (With an
// overcast part of the sky's own colour, the bluish clear part's excess blue went to E_sun, whose
// blue read 6-10% high under such clouds on both bundled recordings.)
TEST(SunSkyFitTest, AWeakSunUnderACloudKeepsItsColour) {
  std::mt19937 rng(12);
  const glm::dvec3 sun = 0.12 * glm::dvec3(100.0, 80.0, 50.0), clear(2.5, 3.5, 5.5);
  const double overcast = 14.0;
  const SunSkyFitSummary fit = FitSunSky({}, TwoSkySamples(sun, clear, overcast, 8000, rng));
  ExpectNear(fit.light, {sun, clear + overcast}, 2e-3);
}

// The same cloud with the model wrong in blue: the shadowed samples' blue clear sky predicted 10%
// too bright (a sky shape or an albedo off in one channel, as a real model is). Blue's sun is a
// small part of its sunlit samples' light, so the per-channel fit puts E_sun's blue 5% off.
// Given the sun's colour (clouds are grey: the clear frames' colour), one magnitude from the three
// channels, each weighed by what it knows of the sun, brings it back within 1% (measured 0.6%).
TEST(SunSkyFitTest, AGivenSunColourHoldsAWeakSunsChannelsTogether) {
  std::mt19937 rng(14);
  const glm::dvec3 sun = 0.12 * glm::dvec3(100.0, 80.0, 50.0), clear(2.5, 3.5, 5.5);
  const double overcast = 14.0;
  std::vector<Sample> samples = TwoSkySamples(sun, clear, overcast, 8000, rng);
  for (Sample& s : samples) {
    if (!s.sunlit) s.sky.z *= 1.1f;  // the model's blue clear sky in shade, 10% too bright
  }
  const glm::dvec3 colour = sun / sun.y;
  const SunSkyFitSummary fit = FitSunSky({}, samples, &colour);
  ASSERT_TRUE(fit.coloured.has_value());
  const double own_blue = std::abs(fit.light.sun_rgb.z / sun.z - 1.0);
  const double coloured_blue = std::abs(fit.coloured->sun_rgb.z / sun.z - 1.0);
  std::printf("E_sun blue: %.1f%% off per channel, %.1f%% with the colour given\n", 100.0 * own_blue, 100.0 * coloured_blue);
  EXPECT_GT(own_blue, 0.04);
  EXPECT_LT(coloured_blue, 0.01);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(fit.coloured->sun_rgb[c] / fit.coloured->sun_rgb.y, colour[c], 1e-9);
  // Without a colour there is no coloured fit; with exact samples it is the fit itself.
  EXPECT_FALSE(FitSunSky({}, samples).coloured.has_value());
  const std::vector<Sample> exact = TwoSkySamples(sun, clear, overcast, 8000, rng);
  const SunSkyFitSummary exact_fit = FitSunSky({}, exact, &colour);
  ExpectNear(*exact_fit.coloured, {sun, clear + overcast}, 3e-3);
}

// One sample more or less (a pixel that crosses a shadow edge's margin as the sun moves by a few
// hundredths of a degree) moves the estimate by about its own weight, not by a jump: the samples
// the sky's split and the medians read are chosen by pixel, not by place in the list. By place,
// dropping the first sample put every later one on the other side of the split, and on courtyard-a
// a sun 0.03° away moved a burst's E_sky by 1.1 points (docs/estimation.md). Under a thin cloud,
// with clear and overcast sky shapes that differ little (±5%) and the model's own error (±10% per
// sample): the split is poorly posed, as it is there.
TEST(SunSkyFitTest, OneSampleLessMovesTheEstimateByLittle) {
  std::mt19937 rng(13);
  const glm::dvec3 sun(60.0, 48.0, 34.0), clear(8.0, 8.5, 9.5);
  const double overcast = 8.0;
  std::vector<Sample> samples = MakeSamples({sun, clear + overcast}, 8000, rng);
  std::uniform_real_distribution<float> shape(-0.05f, 0.05f);
  std::normal_distribution<float> model_error(0.0f, 0.1f);
  for (size_t k = 0; k < samples.size(); ++k) {
    Sample& s = samples[k];
    s.overcast = s.sky * (1.0f + shape(rng));
    for (int c = 0; c < 3; ++c) {
      s.radiance[c] = static_cast<float>(s.albedo[c] / glm::pi<double>() *
                                         (s.sun[c] * sun[c] + s.sky[c] * clear[c] + s.overcast[c] * overcast));
    }
    s.radiance *= 1.0f + model_error(rng);
    s.pixel = static_cast<uint32_t>(37 * k + 5);  // distinct camera pixels
  }
  const SunSkyFitSummary all = FitSunSky({}, samples);
  const LightParts all_parts = SplitLight(all.light, all.overcast_share);
  for (const size_t drop : {size_t{0}, size_t{1}, size_t{4000}}) {
    std::vector<Sample> fewer = samples;
    fewer.erase(fewer.begin() + static_cast<std::ptrdiff_t>(drop));
    const SunSkyFitSummary fit = FitSunSky({}, fewer);
    const LightParts parts = SplitLight(fit.light, fit.overcast_share);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(fit.light.sun_rgb[c], all.light.sun_rgb[c], 1e-3 * all.light.sun_rgb[c]) << "drop " << drop << " channel " << c;
      EXPECT_NEAR(fit.light.sky_rgb[c], all.light.sky_rgb[c], 1e-3 * all.light.sky_rgb[c]) << "drop " << drop << " channel " << c;
      EXPECT_NEAR(parts.overcast[c], all_parts.overcast[c], 0.01 * all.light.sky_rgb[c]) << "drop " << drop << " channel " << c;
    }
  }
}

// The fits of SurfaceSamples(sky_factor) without the shadows' E_sun (the scene's) and with it.
struct SceneAndShadowFits {
  SunSkyFitSummary scene, fit;
};
SceneAndShadowFits FitSurfaceSamples(const std::array<double, 5>& sky_factor, unsigned seed) {
  std::mt19937 rng(seed);
  const std::vector<Sample> samples = testing::SurfaceSamples(kClear, sky_factor, rng);
  SunSkyFitOptions scene_only;
  scene_only.sun_from_shadows = false;
  return {FitSunSky(scene_only, samples), FitSunSky({}, samples)};
}

// The sky 50% brighter than the model's on the shaded surface: the whole scene's fit takes that for
// sky everywhere, the sunlit samples' sky part grows, and E_sun reads 5-10% low. The other
// surfaces' own shadows say what the sun is, whatever the sky; the gains, far apart beyond the
// model's known error, say the scene's sky is off. The shadows rest on 38% of what the frame knows
// of the sun, so their estimate is weighed by what that share passes on of the model's error
// (measured: ρ 0.60, E_sun −4.7 / −6.2 / −10.1% → −2.6 / −2.6 / −2.2%).
TEST(SunSkyFitTest, TheSurfacesOwnShadowsTellTheSunWhereTheSkyIsOffBySurface) {
  const auto [scene, fit] = FitSurfaceSamples({1.0, 1.0, 1.5, 1.0, 1.0}, 23);
  ASSERT_TRUE(scene.IsUsable() && fit.IsUsable());
  for (int c = 0; c < 3; ++c) {
    const double scene_error = scene.light.sun_rgb[c] / kClear.sun_rgb[c] - 1.0, error = fit.light.sun_rgb[c] / kClear.sun_rgb[c] - 1.0;
    std::printf("channel %d: E_sun %+.1f%% from the scene, %+.2f%% with the shadows\n", c, 100 * scene_error, 100 * error);
    EXPECT_LT(scene_error, -0.04) << c;
    EXPECT_LT(std::abs(error), 0.03) << c;
    EXPECT_LT(std::abs(error), 0.6 * std::abs(scene_error)) << c;
  }
  EXPECT_GT(fit.shadow_weight, 0.5);
  EXPECT_GT(fit.shadow_information, 0.3);
}

// Where the model is right (every surface's sky within 1% of it) the surfaces' differences are
// information, and the whole scene's fit is kept as it is.
TEST(SunSkyFitTest, WhereTheSurfacesAgreeTheScenesFitIsKept) {
  const auto [scene, fit] = FitSurfaceSamples({1.01, 0.995, 1.0, 0.99, 1.005}, 29);
  ASSERT_TRUE(scene.IsUsable() && fit.IsUsable());
  EXPECT_EQ(fit.shadow_weight, 0.0);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(fit.light.sun_rgb[c], scene.light.sun_rgb[c]) << c;
    EXPECT_EQ(fit.light.sky_rgb[c], scene.light.sky_rgb[c]) << c;
    EXPECT_NEAR(fit.light.sun_rgb[c], kClear.sun_rgb[c], 0.02 * kClear.sun_rgb[c]) << c;
  }
}

TEST(SunSkyFitTest, SensorNoiseWithin1Percent) {
  std::mt19937 rng(2);
  std::vector<Sample> samples = MakeSamples(kClear, 5000, rng);
  std::normal_distribution<float> noise(0.0f, 0.03f);  // 3% per pixel
  for (Sample& s : samples) s.radiance *= glm::vec3(1.0f + noise(rng), 1.0f + noise(rng), 1.0f + noise(rng));
  const SunSkyFitSummary fit = FitSunSky({}, samples);
  ExpectNear(fit.light, kClear, 0.01);
  EXPECT_GT(fit.confidence, 0.7);
  EXPECT_NEAR(fit.residual_spread, 0.03, 0.01);
}

TEST(SunSkyFitTest, OutliersAndAMovingOccluderDoNotMoveTheEstimate) {
  std::mt19937 rng(3);
  std::vector<Sample> samples = MakeSamples(kClear, 5000, rng);
  std::uniform_real_distribution<float> wild(0.0f, 40.0f);
  // 10% wild values (specular glints, misregistration), and a person in dark clothes covering
  // 15% of the samples (a contiguous block: one region of the image).
  for (size_t i = 0; i < samples.size(); i += 10) samples[i].radiance = {wild(rng), wild(rng), wild(rng)};
  for (size_t i = 1000; i < 1750; ++i) samples[i].radiance *= 0.25f;
  const SunSkyFitSummary fit = FitSunSky({}, samples);
  ExpectNear(fit.light, kClear, 0.02);
  EXPECT_LT(fit.inlier_share, 0.8);  // the outliers are seen as such
}

// With outliers the reweighting needs several iterations; cut to one it stops while the estimate
// still moves, and says so: usable, but not kConverged.
TEST(SunSkyFitTest, RunningOutOfIterationsIsNoConvergence) {
  std::mt19937 rng(3);
  std::vector<Sample> samples = MakeSamples(kClear, 5000, rng);
  std::uniform_real_distribution<float> wild(0.0f, 40.0f);
  for (size_t i = 0; i < samples.size(); i += 10) samples[i].radiance = {wild(rng), wild(rng), wild(rng)};
  EXPECT_EQ(FitSunSky({}, samples).status, SunSkyFitStatus::kConverged);
  SunSkyFitOptions one;
  one.iterations = 1;
  const SunSkyFitSummary cut = FitSunSky(one, samples);
  EXPECT_EQ(cut.status, SunSkyFitStatus::kNoConvergence) << cut.message;
  EXPECT_TRUE(cut.IsUsable());
  EXPECT_NE(cut.message.find("still moving after 1 iterations"), std::string::npos) << cut.message;
}

// The reweighting stops when the estimate stops moving, not at a count a clean frame needs: a
// frame whose samples disagree takes more steps, and its last iterate at a fixed count is not the
// fit's answer (here 5.6% from it after 8 steps; courtyard-e: E_sun up to 6%, 481 of 500 frames
// still moving after 8).
TEST(SunSkyFitTest, TheReweightingRunsUntilTheEstimateStopsMoving) {
  std::mt19937 rng(11);
  std::vector<Sample> samples = MakeSamples(kClear, 5000, rng);
  std::uniform_real_distribution<float> wild(0.0f, 40.0f);
  for (size_t i = 0; i < samples.size(); i += 10) samples[i].radiance = {wild(rng), wild(rng), wild(rng)};
  // Two populations that disagree: 40% of the samples (a glossy ground, a wall the model has
  // wrong) 1.5 times brighter where sunlit and as much darker in shade.
  for (size_t i = 1000; i < 3000; ++i) samples[i].radiance *= samples[i].sunlit ? 1.5f : 1.0f / 1.5f;
  SunSkyFitOptions many;
  many.iterations = 1000;
  const SunSkyFitSummary fit = FitSunSky({}, samples), optimum = FitSunSky(many, samples);
  SunSkyFitOptions eight;
  eight.iterations = 8;
  eight.accelerate = false;
  const SunSkyFitSummary cut = FitSunSky(eight, samples);
  EXPECT_EQ(fit.status, SunSkyFitStatus::kConverged) << fit.message;
  double off_cut = 0.0;
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(fit.light.sun_rgb[c] / optimum.light.sun_rgb[c], 1.0, 1e-3) << c;
    EXPECT_NEAR(fit.light.sky_rgb[c] / optimum.light.sky_rgb[c], 1.0, 1e-3) << c;
    off_cut = std::max({off_cut, std::abs(cut.light.sun_rgb[c] / optimum.light.sun_rgb[c] - 1.0),
                        std::abs(cut.light.sky_rgb[c] / optimum.light.sky_rgb[c] - 1.0)});
  }
  EXPECT_EQ(cut.status, SunSkyFitStatus::kNoConvergence);
  EXPECT_GT(off_cut, 0.03);
}

// The acceleration of the reweighting (Anderson, depth 1) changes the path, not the answer: on
// the same disagreeing samples, and on clean ones, the accelerated fit is within 0.1% of the
// optimum (the plain reweighting run 1000 steps), in fewer steps than the plain one where the
// weights settle slowly.
TEST(SunSkyFitTest, TheAcceleratedReweightingReachesTheSameAnswerInFewerSteps) {
  for (const bool disagree : {false, true}) {
    std::mt19937 rng(11);
    std::vector<Sample> samples = MakeSamples(kClear, 5000, rng);
    std::uniform_real_distribution<float> wild(0.0f, 40.0f);
    for (size_t i = 0; i < samples.size(); i += 10) samples[i].radiance = {wild(rng), wild(rng), wild(rng)};
    if (disagree) {
      for (size_t i = 1000; i < 3000; ++i) samples[i].radiance *= samples[i].sunlit ? 1.5f : 1.0f / 1.5f;
    }
    SunSkyFitOptions plain, many;
    plain.accelerate = false;
    many.accelerate = false;
    many.iterations = 1000;
    const SunSkyFitSummary fast = FitSunSky({}, samples), slow = FitSunSky(plain, samples), optimum = FitSunSky(many, samples);
    std::printf("%s: %d steps accelerated, %d plain\n", disagree ? "40% disagreeing" : "clean", fast.reweighting_steps,
                slow.reweighting_steps);
    EXPECT_EQ(fast.status, SunSkyFitStatus::kConverged) << fast.message;
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(fast.light.sun_rgb[c] / optimum.light.sun_rgb[c], 1.0, 1e-3) << c;
      EXPECT_NEAR(fast.light.sky_rgb[c] / optimum.light.sky_rgb[c], 1.0, 1e-3) << c;
    }
    // Clean samples settle in 3 steps a channel, with nothing to gain; disagreeing ones in 19
    // against 22 here (6.3 -> 4.2 a fit over courtyard-a's frames, docs/estimation.md).
    if (disagree) {
      EXPECT_LT(fast.reweighting_steps, slow.reweighting_steps);
    } else {
      EXPECT_LE(fast.reweighting_steps, slow.reweighting_steps);
    }
  }
}

TEST(SunSkyFitTest, OvercastGivesNoSunWithConfidence) {
  // Sunlit and shadowed areas look alike: E_sun must come out ≈ 0, not noise.
  std::mt19937 rng(4);
  const SunSky overcast{{0.0, 0.0, 0.0}, {30.7, 30.7, 30.7}};
  std::vector<Sample> samples = MakeSamples(overcast, 5000, rng);
  std::normal_distribution<float> noise(0.0f, 0.02f);
  for (Sample& s : samples) s.radiance *= 1.0f + noise(rng);
  const SunSkyFitSummary fit = FitSunSky({}, samples);
  for (int c = 0; c < 3; ++c) {
    EXPECT_LT(fit.light.sun_rgb[c], 0.01 * overcast.sky_rgb[c]) << c;
    EXPECT_NEAR(fit.light.sky_rgb[c], 30.7, 0.3);
  }
  EXPECT_GT(fit.confidence, 0.8);
}

TEST(SunSkyFitTest, AnIllPosedSplitLowersTheConfidence) {
  // The same exact samples under three lights. A sun at 4% of its clear beam behind thin cloud:
  // the sunlit samples' light is mostly sky, so any model error in the sky's part passes to E_sun
  // amplified (the recordings' worst E_sun frames are such). Shadows lit mostly by sun reflected
  // from nearby walls pass the sun's model error to E_sky. Both fits are exact here (the samples
  // are the model's), yet the confidence must say how much a model error would move them.
  std::mt19937 rng(8);
  const std::vector<Sample> clear_samples = MakeSamples(kClear, 5000, rng);
  const SunSkyFitSummary clear = FitSunSky({}, clear_samples);
  EXPECT_GT(clear.sun_share_sunlit, 0.5);
  EXPECT_GT(clear.sky_share_shadowed, 0.5);
  EXPECT_GT(clear.confidence, 0.99);

  const SunSky thin{kClear.sun_rgb * 0.04, kClear.sky_rgb * 2.0};
  std::mt19937 rng_thin(8);
  const SunSkyFitSummary weak = FitSunSky({}, MakeSamples(thin, 5000, rng_thin));
  ExpectNear(weak.light, thin, 1e-3);
  EXPECT_LT(weak.sun_share_sunlit, 0.25);
  EXPECT_LT(weak.confidence, 0.5);
  EXPECT_GT(weak.confidence, 0.1);  // still usable: the filter takes it

  std::mt19937 rng_bounce(8);
  std::vector<Sample> bounced = MakeSamples(kClear, 5000, rng_bounce);
  for (Sample& s : bounced) {
    if (s.sunlit) continue;
    s.sun *= 4.0f;  // an arcade's back wall: lit by the sunlit ground in front of it
    for (int c = 0; c < 3; ++c) {
      s.radiance[c] = static_cast<float>(s.albedo[c] / glm::pi<double>() *
                                         (s.sun[c] * kClear.sun_rgb[c] + s.sky[c] * kClear.sky_rgb[c]));
    }
  }
  const SunSkyFitSummary reflected = FitSunSky({}, bounced);
  ExpectNear(reflected.light, kClear, 1e-3);
  // The sky's share of the shadowed samples' light, per channel a mean of shares (the least
  // channel counts): about 0.3 by this construction, against over 0.5 in the clear case.
  glm::dvec3 share_sum(0.0);
  int shadowed = 0;
  for (const Sample& s : bounced) {
    if (s.sunlit) continue;
    const glm::dvec3 sky = glm::dvec3(s.sky) * kClear.sky_rgb, sun = glm::dvec3(s.sun) * kClear.sun_rgb;
    share_sum += sky / (sky + sun), ++shadowed;
  }
  const double share = glm::compMin(share_sum / static_cast<double>(shadowed));
  EXPECT_NEAR(reflected.sky_share_shadowed, share, 1e-3);
  EXPECT_LT(share, 0.35);
  EXPECT_LT(reflected.confidence, 0.65);
}

TEST(SunSkyFitTest, AnEmptyStratumIsSaidAndHasNoConfidence) {
  // Everything in shade while the sun is up (its light reaches the samples by reflection only):
  // E_sun is not observed. No NaN, the sky still fitted, the confidence 0 so the filter holds.
  std::mt19937 rng(9);
  std::vector<Sample> shade = MakeSamples(kClear, 3000, rng);
  for (Sample& s : shade) {
    s.sunlit = false;
    s.sun = 0.1f * s.sky;
    for (int c = 0; c < 3; ++c) {
      s.radiance[c] = static_cast<float>(s.albedo[c] / glm::pi<double>() *
                                         (s.sun[c] * kClear.sun_rgb[c] + s.sky[c] * kClear.sky_rgb[c]));
    }
  }
  const SunSkyFitSummary in_shade = FitSunSky({}, shade);
  EXPECT_TRUE(in_shade.sun_up);
  EXPECT_EQ(in_shade.sunlit_samples, 0);
  EXPECT_EQ(in_shade.status, SunSkyFitStatus::kSkyOnly);
  EXPECT_EQ(in_shade.confidence, 0.0);
  EXPECT_NE(in_shade.message.find("E_sun not observed"), std::string::npos) << in_shade.message;
  for (int c = 0; c < 3; ++c) {
    EXPECT_TRUE(std::isfinite(in_shade.light.sky_rgb[c]));
    EXPECT_EQ(in_shade.light.sun_rgb[c], 0.0);
  }
  // Everything sunlit: no shadowed stratum to pin E_sky; finite, confidence 0.
  std::mt19937 rng_lit(9);
  std::vector<Sample> lit = MakeSamples(kClear, 3000, rng_lit);
  std::erase_if(lit, [](const Sample& s) { return !s.sunlit; });
  const SunSkyFitSummary all_lit = FitSunSky({}, lit);
  EXPECT_EQ(all_lit.shadowed_samples, 0);
  EXPECT_EQ(all_lit.confidence, 0.0);
  for (int c = 0; c < 3; ++c) {
    EXPECT_TRUE(std::isfinite(all_lit.light.sun_rgb[c]) && std::isfinite(all_lit.light.sky_rgb[c]));
  }
  // The sun below the horizon is not an empty stratum: no sun term anywhere, full confidence.
  std::mt19937 rng_night(9);
  std::vector<Sample> night = MakeSamples({{0, 0, 0}, {1.2, 1.5, 2.1}}, 2000, rng_night);
  for (Sample& s : night) s.sun = glm::vec3(0.0f), s.sunlit = false;
  const SunSkyFitSummary dark = FitSunSky({}, night);
  EXPECT_FALSE(dark.sun_up);
  EXPECT_GT(dark.confidence, 0.9);
}

TEST(SunSkyFitTest, SunBelowTheHorizonFitsTheSkyAlone) {
  std::mt19937 rng(5);
  std::vector<Sample> samples = MakeSamples({{0, 0, 0}, {1.2, 1.5, 2.1}}, 2000, rng);
  for (Sample& s : samples) s.sun = glm::vec3(0.0f), s.sunlit = false;
  const SunSkyFitSummary fit = FitSunSky({}, samples);
  EXPECT_EQ(fit.status, SunSkyFitStatus::kSkyOnly);
  EXPECT_EQ(fit.light.sun_rgb, glm::dvec3(0.0));
  EXPECT_NEAR(fit.light.sky_rgb.z, 2.1, 2.1e-3);
}

TEST(SunSkyFitTest, TooFewSamplesIsAStatusNotACrash) {
  std::mt19937 rng(6);
  const SunSkyFitSummary fit = FitSunSky({}, MakeSamples(kClear, 5, rng));
  EXPECT_EQ(fit.status, SunSkyFitStatus::kTooFewSamples);
  EXPECT_FALSE(fit.IsUsable());
  EXPECT_EQ(fit.message, "5 usable samples (need 10)");
  std::string why;
  EXPECT_NE((SunSkyFitOptions{-1.0}.Check().find("cauchy_scale")), std::string::npos);
  EXPECT_EQ(SunSkyFitOptions{}.Check(), "");
}

}  // namespace
}  // namespace daylit::estimation
