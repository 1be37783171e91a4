// Issue 4's figures on the bundled courtyard-a recording (path-traced, with ground truth): the
// median relative error over its 600 frames ≤ 5% for E_sun and E_sky in each channel, and the
// sun/sky ratio within 5%. The whole `daylit estimate` pipeline: exact decoding on its own thread,
// the bake, sun from the ephemeris, sampler with transfer terms, fit, temporal filter.
#include <gtest/gtest.h>

#include <filesystem>

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

}  // namespace
}  // namespace daylit
