// Issue 4's figures on the bundled courtyard-a recording (path-traced, with ground truth): the
// median relative error over its 600 frames ≤ 5% for E_sun and E_sky in each channel, and the
// sun/sky ratio within 5%. The whole `daylit estimate` pipeline: exact decoding on its own thread,
// the bake, sun from the ephemeris, sampler with transfer terms, fit, temporal filter.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "tests/courtyard_fixture.h"
#include "base/log.h"
#include "evaluation/lighting_truth.h"
#include "pipeline/lighting_pipeline.h"
#include "scene/raycaster.h"
#include "scene/scene.h"

namespace daylit {
namespace {

TEST(EstimateRecordingTest, CourtyardLightingWithin5PercentOfTheTruth) {
  const scene::Scene& scene = testing::Courtyard().scene;
  const bake::SceneBake& baked = testing::Courtyard().bake;
  const scene::RayCaster caster(scene.model);
  pipeline::LightingPipeline lighting(scene, baked, caster, {});
  const pipeline::PipelineRun run = lighting.Run(scene::OpenFrameSource(scene));
  ASSERT_EQ(run.frames.size(), 600u);
  EXPECT_EQ(run.undecodable, 0);
  ASSERT_TRUE(scene.groundtruth.lighting.has_value());
  const evaluation::TruthComparison truth = evaluation::CompareWithTruth(run.frames, *scene.groundtruth.lighting);
  EXPECT_EQ(truth.frames, 600);
  for (int c = 0; c < 3; ++c) {
    EXPECT_LE(truth.sun_error[c], 0.05) << "E_sun channel " << c;
    EXPECT_LE(truth.sky_error[c], 0.05) << "E_sky channel " << c;
    EXPECT_LE(truth.ratio_error[c], 0.05) << "sun/sky channel " << c;
  }
  // The overcast burst (frames 300-399: 12% of the beam, most of the sky grey) still has a sun.
  for (size_t i = 300; i < 400; i += 25) {
    EXPECT_GT(run.frames[i].light.sun_rgb.y, 0.5 * truth.truth[i].sun_rgb.y) << i;
    EXPECT_LT(run.frames[i].light.sun_rgb.y, 1.5 * truth.truth[i].sun_rgb.y) << i;
  }
  // Every frame has a confident estimate, and the sun moved (a re-cast) once per burst only.
  for (const estimation::FrameEstimate& f : run.frames) EXPECT_GT(f.confidence, 0.3) << f.frame;
  EXPECT_EQ(run.sun_moves_ms.size(), 6u);
}

// A burst held to its own bar (the issues' bar is 5%), with the reason beside it.
struct BurstBar {
  int burst;
  double bar;
};

// A bundled recording through the pipeline with the default options, against its ground truth
// (which the caller has checked is there), per frame and per burst.
struct RunAgainstTruth {
  pipeline::PipelineRun run;
  evaluation::TruthComparison truth;
  std::vector<evaluation::BurstLighting> bursts;
};
RunAgainstTruth RunWithTruth(const testing::BundledCourtyard& c) {
  const scene::RayCaster caster(c.scene.model);
  pipeline::LightingPipeline lighting(c.scene, c.bake, caster, {});
  RunAgainstTruth out;
  out.run = lighting.Run(scene::OpenFrameSource(c.scene));
  // Every frame's reweighting ran until its estimate stopped moving (each frame of the four
  // recordings within 30 steps; with 8, 362 of a's, 154 of b's, 51 of c's and 481 of e's had not).
  const auto still_moving = std::count_if(out.run.frames.begin(), out.run.frames.end(), [](const auto& f) {
    return f.status == estimation::FrameStatus::kNotConverged;
  });
  EXPECT_EQ(still_moving, 0) << c.scene.name;
  out.truth = evaluation::CompareWithTruth(out.run.frames, *c.scene.groundtruth.lighting);
  out.bursts = evaluation::CompareBursts(out.run.frames, &out.truth);
  return out;
}

// Issues 18 and 37: every burst's median error per channel ≤ 5%, on every recording, and the 90th
// percentile over frames of the worst channel.
void ExpectPerBurst(const testing::BundledCourtyard& c, double p90_bar, double auc_bar, const std::vector<BurstBar>& wider = {}) {
  ASSERT_TRUE(c.scene.groundtruth.lighting.has_value());
  const RunAgainstTruth measured = RunWithTruth(c);
  const evaluation::TruthComparison& truth = measured.truth;
  const std::vector<evaluation::BurstLighting>& bursts = measured.bursts;
  ASSERT_EQ(bursts.size(), c.scene.name == "courtyard-a" ? 6u : 5u);
  for (const evaluation::BurstLighting& b : bursts) {
    double bar = 0.05;
    for (const BurstBar& w : wider) bar = w.burst == b.burst.index ? w.bar : bar;
    for (int ch = 0; ch < 3; ++ch) {
      EXPECT_LE(b.sun_error[ch], bar) << c.scene.name << " burst " << b.burst.index << " E_sun channel " << ch;
      EXPECT_LE(b.sky_error[ch], bar) << c.scene.name << " burst " << b.burst.index << " E_sky channel " << ch;
      testing::RecordFigure(fmt::format("{}/estimate/burst{}/sun_error/{}", c.scene.name, b.burst.index, "rgb"[ch]), b.sun_error[ch]);
      testing::RecordFigure(fmt::format("{}/estimate/burst{}/sky_error/{}", c.scene.name, b.burst.index, "rgb"[ch]), b.sky_error[ch]);
    }
    // Issue 51: the 90% interval, made from the frames alone, holds the burst's errors.
    EXPECT_TRUE(b.interval_covers) << c.scene.name << " burst " << b.burst.index;
  }
  testing::RecordFigure(c.scene.name + "/estimate/p90_worst_channel", truth.p90_worst_channel_error);
  // Issue 37: no more than 5% of the frames more than 10% off.
  EXPECT_LE(truth.ranking.bad_frames, truth.frames / 20) << c.scene.name;
  EXPECT_LE(truth.p90_worst_channel_error, p90_bar) << c.scene.name;
  // The confidence ranks frames by their true error (frames over 10% against those within 5%);
  // with no frame over 10% there is nothing to rank.
  testing::RecordFigure(c.scene.name + "/estimate/bad_frames", truth.ranking.bad_frames);
  if (truth.ranking.bad_frames > 0) {
    EXPECT_GE(truth.ranking.auc, auc_bar) << c.scene.name;
    testing::RecordFigure(c.scene.name + "/estimate/confidence_auc", truth.ranking.auc);
  }
}

TEST(EstimateRecordingTest, CourtyardAEveryBurstWithin5Percent) {
  // Every burst within the 5%, the overcast burst 3 too (measured: worst 3.4%, burst 5's
  // E_sky blue; burst 3's E_sun blue 3.1%). The 90th percentile of the worst channel (measured
  // 6.4%) and the confidence's AUC (measured 0.934 over 11 frames beyond 10%: those with a weak
  // sun, which the split's share flags) at the bars.
  ExpectPerBurst(testing::Courtyard(), 0.10, 0.90);
}

TEST(EstimateRecordingTest, CourtyardBEveryBurstWithin5Percent) {
  // Issue 37's third recording. Measured: worst 4.1% (the overcast burst 2's E_sun red, 5.7%
  // before its weak sun took the clear frames' colour, docs/estimation.md item 8), the others
  // within 3.4% (6.6%, 2.1%, 2.7% and 14.9% before the sky's fill rule and the physical sky,
  // item 7); the 90th percentile 6.7%; 10 frames of 500 beyond 10%, ranked with AUC 0.94.
  ExpectPerBurst(testing::CourtyardB(), 0.10, 0.90);
}

TEST(EstimateRecordingTest, CourtyardCEveryBurstWithin5Percent) {
  // Measured: worst 1.7% (burst 2's E_sun green), the 90th percentile 4.6%, and no frame is over
  // 10%: the confidence has nothing to rank (when one is, the bar holds).
  ExpectPerBurst(testing::CourtyardC(), 0.10, 0.90);
}

// Issue 51 on the realistic recording: its surfaces disagree by 4-12%, and the 90% interval, made
// from the frames alone, holds every burst's errors (E_sun up to 16.0%, E_sky up to 10.7%). Where
// E_sun comes from the surfaces' own shadows, the interval is theirs, not the scene's fit's, which
// those surfaces' disagreement describes (measured: E_sun's median half-width over bursts 34.3%,
// 59.6% with the scene's alone; E_sky's 20.7%). The bars: the errors it must hold, and an interval
// no wider than half again what it is.
TEST(EstimateRecordingTest, CourtyardEsIntervalHoldsEveryBurstAndIsTheShadowsWhereTheyTellTheSun) {
  const testing::BundledCourtyard& c = testing::CourtyardE();
  ASSERT_TRUE(c.scene.groundtruth.lighting.has_value());
  const std::vector<evaluation::BurstLighting> bursts = RunWithTruth(c).bursts;
  ASSERT_EQ(bursts.size(), 5u);
  std::vector<double> sun_widths, sky_widths;
  for (const evaluation::BurstLighting& b : bursts) {
    EXPECT_TRUE(b.interval_covers) << "burst " << b.burst.index;
    sun_widths.push_back((b.sun_half_width.x + b.sun_half_width.y + b.sun_half_width.z) / 3.0);
    sky_widths.push_back((b.sky_half_width.x + b.sky_half_width.y + b.sky_half_width.z) / 3.0);
  }
  std::sort(sun_widths.begin(), sun_widths.end());
  std::sort(sky_widths.begin(), sky_widths.end());
  testing::RecordFigure("courtyard-e/estimate/sun_half_width_median", sun_widths[2]);
  testing::RecordFigure("courtyard-e/estimate/sky_half_width_median", sky_widths[2]);
  EXPECT_LT(sun_widths[2], 0.5);
  EXPECT_LT(sky_widths[2], 0.3);
}

TEST(EstimateRecordingTest, EveryDiffuseSurfaceInShadeIsSaidNotNaN) {
  // courtyard-c with only the arcade's back wall and its roof's underside marked diffuse: in shade
  // in every frame while the sun is up. E_sun is not observed: every frame says so, with
  // confidence 0 and no NaN, and the report names the bursts.
  const testing::BundledCourtyard& c = testing::CourtyardC();
  bake::SceneBake shade = c.bake;
  const int wall = c.scene.model.SurfaceIndex("building_arcade"), roof = c.scene.model.SurfaceIndex("arcade_roof");
  ASSERT_GE(wall, 0);
  ASSERT_GE(roof, 0);
  for (size_t i = 0; i < shade.camera.diffuse.size(); ++i) {
    const uint32_t s = shade.camera.surface[i];
    if (s != static_cast<uint32_t>(wall) && s != static_cast<uint32_t>(roof)) shade.camera.diffuse[i] = 0;
  }
  const scene::RayCaster caster(c.scene.model);
  pipeline::LightingPipeline lighting(c.scene, shade, caster, {});
  const pipeline::PipelineRun run = lighting.Run(scene::OpenFrameSource(c.scene));
  ASSERT_EQ(run.frames.size(), 500u);
  for (const estimation::FrameEstimate& f : run.frames) {
    EXPECT_TRUE(f.sun_up) << f.frame;
    EXPECT_EQ(f.sunlit_samples, 0) << f.frame;
    EXPECT_GT(f.shadowed_samples, 1000) << f.frame;
    for (int ch = 0; ch < 3; ++ch) {
      EXPECT_TRUE(std::isfinite(f.light.sun_rgb[ch]) && std::isfinite(f.light.sky_rgb[ch])) << f.frame;
    }
    EXPECT_TRUE(std::isfinite(f.confidence)) << f.frame;
    EXPECT_LE(f.confidence, 1e-9) << f.frame;
  }
  const std::vector<evaluation::BurstLighting> bursts = evaluation::CompareBursts(run.frames, nullptr);
  ASSERT_EQ(bursts.size(), 5u);
  for (const evaluation::BurstLighting& b : bursts) {
    EXPECT_EQ(b.frames_without_sunlit, static_cast<int>(b.burst.end - b.burst.begin)) << b.burst.index;
    EXPECT_EQ(b.frames_without_shadowed, 0) << b.burst.index;
  }
  const std::string csv = evaluation::BurstsCsv(bursts);
  EXPECT_NE(csv.find("frames_without_sunlit"), std::string::npos);
}

}  // namespace
}  // namespace daylit
