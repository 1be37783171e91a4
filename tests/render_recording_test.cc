// The augmented frame against the path tracer's: groundtruth/with_objects holds each truth frame
// rendered with the virtual objects physically present. daylit estimates the light from the
// video frame, relights, and composites; the bars are a mean relative error of linear
// radiance ≤ 10% on the objects' pixels and ≤ 10% on the pixels of their shadows.
#include "render/frame_renderer.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <optional>

#include "evaluation/composite_truth.h"
#include "render/gl_context.h"
#include "tests/courtyard_fixture.h"

namespace daylit::render {
namespace {

struct Fidelity {
  double mean_object = 0.0, mean_shadow = 0.0, worst_object = 0.0, worst_shadow = 0.0;
  int frames = 0;
};

// Over the 12 truth frames, each fitted on its own: the composite with the volume, and with
// --lighting lights:8 (the sun and 8 lights fitted to the relit env map, each with its shadows).
TEST(RenderRecordingTest, CompositesMatchThePathTracedFramesWithObjects) {
  std::string why;
  const auto gl = HeadlessGlContext::Create(&why);
  ASSERT_NE(gl, nullptr) << why;
  const testing::BundledCourtyard& c = testing::Courtyard();
  const scene::Scene& scene = c.scene;
  const scene::RayCaster caster(scene.model);
  FrameRenderer volume(scene, c.bake, caster);
  FrameRendererOptions with_lights;
  with_lights.lights = 8;
  FrameRenderer lights(scene, c.bake, caster, with_lights);
  Fidelity fidelity[2];
  std::vector<float> out, linear;
  for (size_t position = 0; position < scene.frame_times->frames.size(); ++position) {
    const int index = scene.frame_times->frames[position].index;
    const std::optional<evaluation::TruthFrame> truth = evaluation::ReadTruthFrame(scene, index);
    if (!truth) continue;
    const estimation::FrameFit fit = estimation::FitFrame(scene, c.bake, caster, position, {});
    volume.Linearize(fit.frame, &linear);
    for (int way = 0; way < 2; ++way) {
      FrameRenderer& renderer = way == 0 ? volume : lights;
      renderer.Render(fit.frame, fit.fit.light, fit.fit.overcast_share, fit.sun_dir, &out);
      const evaluation::CompositeFidelity f = evaluation::CompareComposite(out, linear, truth->with, truth->without, truth->mask);
      std::printf("frame %3d, %s: objects %.1f%% over %zu pixels, their shadows %.1f%% over %zu pixels (the video itself "
                  "%.1f%% off the noise-free frame there)\n", index, way == 0 ? "volume  " : "lights:8",
                  100 * f.object_error, f.object_pixels, 100 * f.shadow_error, f.shadow_pixels, 100 * f.frame_shadow_error);
      Fidelity& r = fidelity[way];
      r.worst_object = std::max(r.worst_object, f.object_error), r.worst_shadow = std::max(r.worst_shadow, f.shadow_error);
      r.mean_object += f.object_error, r.mean_shadow += f.shadow_error;
      ++r.frames;
    }
  }
  for (int way = 0; way < 2; ++way) {
    Fidelity& r = fidelity[way];
    ASSERT_EQ(r.frames, 12);
    r.mean_object /= r.frames, r.mean_shadow /= r.frames;
    std::printf("%s over the 12 frames: objects %.1f%% (worst %.1f%%), their shadows %.1f%% (worst %.1f%%)\n",
                way == 0 ? "volume  " : "lights:8", 100 * r.mean_object, 100 * r.worst_object, 100 * r.mean_shadow,
                100 * r.worst_shadow);
    const std::string key = std::string("courtyard-a/render/") + (way == 0 ? "volume" : "lights8");
    testing::RecordFigure(key + "/objects/mean", r.mean_object);
    testing::RecordFigure(key + "/objects/worst", r.worst_object);
    testing::RecordFigure(key + "/shadows/mean", r.mean_shadow);
    testing::RecordFigure(key + "/shadows/worst", r.worst_shadow);
  }
  // The bars, over the frames given. The shadows' worst frames are sunny ones whose dark
  // shadows the 8-bit video itself reads several percent off the noise-free truth (printed per frame).
  EXPECT_LT(fidelity[0].mean_object, 0.10);
  EXPECT_LT(fidelity[0].mean_shadow, 0.10);
  EXPECT_LT(fidelity[0].worst_object, 0.10);
  EXPECT_LT(fidelity[0].worst_shadow, 0.15);
  // The lights light the objects about as well as the volume does (the capture point's map
  // unreprojected, or without the bounce losses, about twice as far off); the shadows on the
  // real ground are the same computation either way.
  EXPECT_LT(fidelity[1].mean_object, 0.06);
  EXPECT_LT(fidelity[1].worst_object, 0.10);
  EXPECT_LT(fidelity[1].mean_shadow, 0.10);
}

}  // namespace
}  // namespace daylit::render
