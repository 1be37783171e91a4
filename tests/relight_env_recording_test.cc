// Issue 5's env-map figure on the bundled courtyard-a: the env map relit with the lighting daylit
// estimates for a frame (its unfiltered fit) against the path tracer's map of that frame
// (groundtruth/envmaps, sun disc removed there too): mean relative error ≤ 10% over the texels
// of the model's surfaces, and the sky's DHI within 5%. Two clear and two cloudy frames.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <cstdio>

#include <fmt/format.h>

#include "bake/bake.h"
#include "tests/courtyard_fixture.h"
#include "base/log.h"
#include "estimation/frame_estimator.h"
#include "pipeline/frame_fits.h"
#include "relight/env_relight.h"
#include "scene/scene.h"

namespace daylit {
namespace {

TEST(RelightEnvRecordingTest, RelitMapsMatchThePathTracedOnes) {
  const scene::Scene& scene = testing::Courtyard().scene;
  const bake::SceneBake& baked = testing::Courtyard().bake;
  const scene::RayCaster caster(scene.model);
  relight::EnvRelighter relighter(baked, glm::vec3(scene.envmap->position), caster);
  double worst_surface = 0.0, worst_sky = 0.0;
  const std::vector<size_t> frames = {300, 347, 550, 598};
  const std::vector<pipeline::FrameFit> fits = pipeline::FitRecordingFrames(scene, baked, caster, frames);
  for (size_t i = 0; i < frames.size(); ++i) {
    const int frame = static_cast<int>(frames[i]);
    const pipeline::FrameFit& fit = fits[i];
    relighter.SetSun(fit.sun_dir);
    std::vector<glm::vec3> radiance;
    relighter.Relight(fit.fit.light, fit.fit.overcast_share, &radiance);
    const HdrImage truth =
        scene::ReadHdrImage(*scene.groundtruth.composites / "envmaps" / fmt::format("{:06d}.exr", frame));
    const relight::EnvComparison cmp = relight::CompareEnvMaps(baked.env, radiance, truth);
    std::printf("frame %d: %.1f%% over %zu surface texels, sky DHI %+.1f%%\n", frame, 100 * cmp.surface_error,
                cmp.surface_texels, 100 * (cmp.sky_dhi / cmp.true_sky_dhi - 1.0));
    EXPECT_GT(cmp.surface_texels, 300000u);
    EXPECT_LE(cmp.surface_error, 0.10) << frame;
    EXPECT_NEAR(cmp.sky_dhi / cmp.true_sky_dhi, 1.0, 0.05) << frame;
    worst_surface = std::max(worst_surface, cmp.surface_error);
    worst_sky = std::max(worst_sky, std::abs(cmp.sky_dhi / cmp.true_sky_dhi - 1.0));
  }
  testing::RecordFigure("courtyard-a/env/surface_error/worst", worst_surface);
  testing::RecordFigure("courtyard-a/env/sky_dhi_error/worst", worst_sky);
}

}  // namespace
}  // namespace daylit
