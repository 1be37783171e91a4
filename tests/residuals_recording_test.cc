// Issue 18's self-check without ground truth (evaluation::ResidualSink, `daylit estimate
// --residuals`), on courtyard-c: as baked, no surface's observed/predicted radiance is biased
// beyond the threshold; with one surface's baked albedo scaled by 0.8, the residuals name that
// surface, for its albedo, and no other.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "evaluation/residuals.h"
#include "pipeline/lighting_pipeline.h"
#include "scene/raycaster.h"
#include "tests/courtyard_fixture.h"

namespace daylit {
namespace {

std::vector<evaluation::ResidualFinding> Findings(const scene::Scene& scene, const bake::SceneBake& baked,
                                                  std::vector<evaluation::StratumResidual>* strata) {
  const scene::RayCaster caster(scene.model);
  pipeline::LightingPipeline lighting(scene, baked, caster, {});
  evaluation::ResidualSink residuals(scene, baked);
  lighting.AddSink(&residuals);
  lighting.Run(scene::OpenFrameSource(scene));
  *strata = residuals.Strata();
  return residuals.Findings();
}

TEST(ResidualsRecordingTest, NoSurfaceAsBakedAndAnAlbedoScaledByFourFifthsAlone) {
  const testing::BundledCourtyard& c = testing::CourtyardC();
  std::vector<evaluation::StratumResidual> strata;
  const std::vector<evaluation::ResidualFinding> findings = Findings(c.scene, c.bake, &strata);
  for (const evaluation::StratumResidual& r : strata) {
    std::printf("%-22s %-8s %3d frames: %.3f %.3f %.3f\n", r.surface.c_str(), r.sunlit ? "sunlit" : "shadowed", r.frames,
                r.ratio.x, r.ratio.y, r.ratio.z);
  }
  EXPECT_GE(strata.size(), 6u);
  for (const evaluation::ResidualFinding& f : findings) ADD_FAILURE() << f.message;

  // One surface's baked albedo scaled by 0.8 (in the same test: one bake of courtyard-c per run).
  bake::SceneBake scaled = c.bake;
  const int blue = c.scene.model.SurfaceIndex("building_blue");
  ASSERT_GE(blue, 0);
  for (size_t i = 0; i < scaled.camera.surface.size(); ++i) {
    if (scaled.camera.surface[i] == static_cast<uint32_t>(blue)) scaled.camera.albedo[i] *= 0.8f;
  }
  const std::vector<evaluation::ResidualFinding> named = Findings(c.scene, scaled, &strata);
  ASSERT_EQ(named.size(), 1u);
  EXPECT_EQ(named[0].surface, "building_blue") << named[0].message;
  EXPECT_EQ(named[0].cause, "its albedo") << named[0].message;
  std::printf("%s\n", named[0].message.c_str());
}

}  // namespace
}  // namespace daylit
