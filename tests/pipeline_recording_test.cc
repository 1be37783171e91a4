// pipeline::LightingPipeline over the bundled recording: the frame loop hands every frame from
// first_output_frame on, in order, to the stage (readable frames only) and then to the sinks; a
// sink's stop and the stop flag end the run after the frame at hand; the estimates do not depend
// on whether a stage or sinks are attached; behind a live camera every frame is still estimated,
// the stage left out while a newer frame waits, and the camera never kept waiting.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include "base/error.h"
#include "pipeline/frame_fits.h"
#include "pipeline/lighting_pipeline.h"
#include "scene/raycaster.h"
#include "scene/sun_tracker.h"
#include "tests/courtyard_fixture.h"

namespace daylit::pipeline {
namespace {

// The frame's own pixels, scaled: a stage that needs no GL.
class ScaleStage final : public FrameStage {
 public:
  ImageLight Process(const capture::Frame& frame, const estimation::FrameLight&, const scene::TrackedSun&,
                     std::vector<float>* image) override {
    const float* rgb = frame.rgb.ptr<float>();
    image->assign(rgb, rgb + frame.rgb.total() * 3);
    for (float& v : *image) v *= 2.0f;
    ++calls;
    return ImageLight::kOtherLight;
  }
  int calls = 0;
};

struct Seen {
  int frame;
  double first_value;
  double sky_r;
  int generation;
};

class RecordingSink final : public FrameSink {
 public:
  explicit RecordingSink(int stop_after = -1) : stop_after_(stop_after) {}
  void Consume(const PipelineFrame& f) override {
    ASSERT_NE(f.image, nullptr) << f.frame.index;
    EXPECT_EQ(f.image_light, ImageLight::kOtherLight);
    EXPECT_EQ(f.light.row.frame, f.frame.index);
    seen.push_back({f.frame.index, (*f.image)[0] / (2.0 * f.frame.rgb.ptr<float>()[0]), f.light.row.light.sky_rgb.x,
                    f.sun.generation});
  }
  bool StopRequested() const override { return stop_after_ >= 0 && static_cast<int>(seen.size()) >= stop_after_; }
  std::vector<Seen> seen;

 private:
  int stop_after_;
};

TEST(PipelineRecordingTest, HandsEveryOutputFrameInOrderToTheStageAndTheSinks) {
  const testing::BundledCourtyard& c = testing::Courtyard();
  const scene::RayCaster caster(c.scene.model);
  LightingPipelineOptions options;
  options.max_frames = 40;
  options.first_output_frame = 15;
  LightingPipeline bare(c.scene, c.bake, caster, options);
  const PipelineRun alone = bare.Run(scene::OpenFrameSource(c.scene));

  LightingPipeline lighting(c.scene, c.bake, caster, options);
  ScaleStage stage;
  RecordingSink first, second;
  lighting.SetStage(&stage);
  lighting.AddSink(&first);
  lighting.AddSink(&second);
  const PipelineRun run = lighting.Run(scene::OpenFrameSource(c.scene));
  ASSERT_EQ(run.frames.size(), 40u);
  EXPECT_EQ(run.undecodable, 0);
  EXPECT_EQ(stage.calls, 25);
  ASSERT_EQ(first.seen.size(), 25u);
  ASSERT_EQ(second.seen.size(), 25u);
  for (size_t i = 0; i < first.seen.size(); ++i) {
    EXPECT_EQ(first.seen[i].frame, 15 + static_cast<int>(i));
    EXPECT_NEAR(first.seen[i].first_value, 1.0, 1e-6);  // the stage's image of this very frame
    EXPECT_EQ(first.seen[i].sky_r, run.frames[15 + i].light.sky_rgb.x);
    EXPECT_EQ(second.seen[i].frame, first.seen[i].frame);
  }
  // 40 frames at 10 fps: one burst, the sun counted as moved only at the start.
  EXPECT_EQ(first.seen.back().generation, 1);
  EXPECT_EQ(run.sun_moves_ms.size(), 1u);
  EXPECT_GT(run.median_stage_ms, 0.0);
  for (size_t i = 0; i < run.frames.size(); ++i) {
    EXPECT_EQ(run.frames[i].light.sun_rgb.y, alone.frames[i].light.sun_rgb.y) << i;
    EXPECT_EQ(run.frames[i].light.sky_rgb.z, alone.frames[i].light.sky_rgb.z) << i;
  }
}

TEST(PipelineRecordingTest, ASinksStopOrTheStopFlagEndsTheRunAfterTheFrameAtHand) {
  const testing::BundledCourtyard& c = testing::Courtyard();
  const scene::RayCaster caster(c.scene.model);
  ScaleStage stage;
  RecordingSink closing(7);
  LightingPipeline lighting(c.scene, c.bake, caster, {});
  lighting.SetStage(&stage);
  lighting.AddSink(&closing);
  EXPECT_EQ(lighting.Run(scene::OpenFrameSource(c.scene)).frames.size(), 7u);

  std::atomic<bool> stop{true};
  LightingPipelineOptions options;
  options.stop = &stop;
  LightingPipeline stopped(c.scene, c.bake, caster, options);
  EXPECT_TRUE(stopped.Run(scene::OpenFrameSource(c.scene)).frames.empty());
}

// The frames one command shows (render, relight --frame, relight-env) are fitted as estimate fits
// them: their rows are estimate's rows (the interval, the sun), and a frame of the overcast burst
// (11:36, E_sun a third of E_sky) carries the sun colour the bursts before it measured, where a
// frame fitted alone has only the capture's.
TEST(PipelineRecordingTest, AFrameFittedForOneCommandIsFittedAsEstimateFitsIt) {
  const testing::BundledCourtyard& c = testing::Courtyard();
  const scene::RayCaster caster(c.scene.model);
  const std::vector<size_t> positions = {330, 310, 330};
  const std::vector<FrameFit> fits = FitRecordingFrames(c.scene, c.bake, caster, positions);
  ASSERT_EQ(fits.size(), 3u);
  LightingPipelineOptions options;
  options.max_frames = 331;
  const PipelineRun run = LightingPipeline(c.scene, c.bake, caster, options).Run(scene::OpenFrameSource(c.scene));
  ASSERT_EQ(run.frames.size(), 331u);
  for (size_t i = 0; i < positions.size(); ++i) {
    const estimation::FrameEstimate& row = run.frames[positions[i]];
    const FrameFit& fit = fits[i];
    EXPECT_EQ(fit.row.frame, row.frame);
    EXPECT_EQ(fit.frame.index, row.frame);
    EXPECT_FALSE(fit.frame.rgb.empty());
    EXPECT_DOUBLE_EQ(fit.row.sun_elevation_deg, row.sun_elevation_deg);
    for (int k = 0; k < 3; ++k) {
      EXPECT_DOUBLE_EQ(fit.row.interval.sun[k], row.interval.sun[k]) << row.frame;
      EXPECT_DOUBLE_EQ(fit.row.interval.sky[k], row.interval.sky[k]) << row.frame;
    }
    EXPECT_EQ(fit.row.light.sun_rgb, fit.fit.light.sun_rgb) << "the fit's own light, not the filter's";
    // Alone: one estimator that has seen nothing before this frame.
    scene::SunTracker tracker(c.scene);
    estimation::FrameEstimator alone(c.scene, c.bake, caster, {});
    const estimation::FrameLight lone = alone.Estimate(fit.frame, tracker.Update(fit.frame.utc));
    std::printf("frame %d: carried sun colour weight %.2f after the bursts before it, %.2f alone; E_sun R G B %+.1f%% "
                "%+.1f%% %+.1f%% from alone\n", row.frame, fit.fit.carried_weight, lone.fit.carried_weight,
                100 * (fit.fit.light.sun_rgb.x / lone.fit.light.sun_rgb.x - 1), 100 * (fit.fit.light.sun_rgb.y / lone.fit.light.sun_rgb.y - 1),
                100 * (fit.fit.light.sun_rgb.z / lone.fit.light.sun_rgb.z - 1));
    EXPECT_GT(fit.fit.carried_weight, 2.0 * lone.fit.carried_weight) << row.frame;
  }
  EXPECT_EQ(fits[0].fit.light.sun_rgb, fits[2].fit.light.sun_rgb);
  EXPECT_THROW(FitRecordingFrames(c.scene, c.bake, caster, {c.scene.frame_times->frames.size()}), InputError);
}

// A camera as its V4L2 driver behaves: frame k is captured at k / fps after the first Next();
// the driver holds `buffers` of them, and one captured while all are full (the reader late) is
// lost, counted as dropped. Its frames are a recording's, with their own times.
class PacedCamera final : public capture::FrameSource {
 public:
  PacedCamera(std::vector<capture::Frame> frames, double fps, int buffers)
      : frames_(std::move(frames)), period_(1.0 / fps), buffers_(buffers) {}
  capture::FrameStatus Next(capture::Frame* frame) override {
    using Clock = std::chrono::steady_clock;
    if (!start_) start_ = Clock::now();
    const double now = std::chrono::duration<double>(Clock::now() - *start_).count();
    const long captured = std::lround(std::floor(now / period_));  // the newest frame captured
    if (captured - next_ + 1 > buffers_) {
      stats_.dropped += static_cast<int>(captured - buffers_ + 1 - next_);
      next_ = captured - buffers_ + 1;
    }
    if (next_ >= static_cast<long>(frames_.size())) return capture::FrameStatus::kEnd;
    std::this_thread::sleep_until(*start_ + std::chrono::duration_cast<Clock::duration>(
                                                std::chrono::duration<double>(static_cast<double>(next_) * period_)));
    *frame = frames_[static_cast<size_t>(next_++)];
    frame->rgb = frame->rgb.clone();
    ++stats_.delivered;
    return capture::FrameStatus::kFrame;
  }
  void Seek(int) override {}
  std::string Describe() const override { return "paced camera"; }
  bool live() const override { return true; }

 private:
  std::vector<capture::Frame> frames_;
  double period_;
  long buffers_;
  long next_ = 0;
  std::optional<std::chrono::steady_clock::time_point> start_;
};

// Makes the frame's own pixels, slowly: a machine on which compositing takes longer than the
// camera's frame period.
class SlowStage final : public FrameStage {
 public:
  explicit SlowStage(double seconds) : seconds_(seconds) {}
  ImageLight Process(const capture::Frame& frame, const estimation::FrameLight&, const scene::TrackedSun&,
                     std::vector<float>* image) override {
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds_));
    const float* rgb = frame.rgb.ptr<float>();
    image->assign(rgb, rgb + frame.rgb.total() * 3);
    return ImageLight::kFrameLight;
  }
  void Skip(const estimation::FrameLight&) override { ++skips; }
  int skips = 0;

 private:
  double seconds_;
};

class ImageSink final : public FrameSink {
 public:
  void Consume(const PipelineFrame& f) override {
    frames.push_back(f.frame.index);
    with_image += f.image != nullptr ? 1 : 0;
    if (f.image != nullptr) {
      EXPECT_EQ((*f.image)[0], f.frame.rgb.ptr<float>()[0]) << "this frame's own image";
    }
  }
  std::vector<int> frames;
  int with_image = 0;
};

// A camera at 10 fps and a stage that takes 0.25 s: the pipeline estimates every frame the camera
// captures, in order, with the estimates a recording's run gives; it composites some and leaves
// out the stage of those behind which a newer frame waits; the driver loses none and none is
// given up. With the stage run on every frame it would fall behind by 0.15 s a frame, and within
// a second the read-ahead's queue would overflow (frames given up, estimates missing).
TEST(PipelineRecordingTest, BehindALiveCameraEveryFrameIsEstimatedAndSomeComposited) {
  const testing::BundledCourtyard& c = testing::Courtyard();
  const scene::RayCaster caster(c.scene.model);
  constexpr int kFrames = 30;
  LightingPipelineOptions options;
  options.max_frames = kFrames;
  const PipelineRun recorded = LightingPipeline(c.scene, c.bake, caster, options).Run(scene::OpenFrameSource(c.scene));
  ASSERT_EQ(recorded.frames.size(), static_cast<size_t>(kFrames));
  std::vector<capture::Frame> frames(kFrames);
  std::unique_ptr<capture::FrameSource> source = scene::OpenFrameSource(c.scene);
  for (capture::Frame& frame : frames) ASSERT_EQ(source->Next(&frame), capture::FrameStatus::kFrame);

  options.max_frames.reset();
  LightingPipeline lighting(c.scene, c.bake, caster, options);
  SlowStage stage(0.25);
  ImageSink sink;
  lighting.SetStage(&stage);
  lighting.AddSink(&sink);
  const PipelineRun run = lighting.Run(std::make_unique<PacedCamera>(std::move(frames), 10.0, 4));
  std::printf("composited %d, estimated only %d, dropped %d, given up %d\n", run.composited, run.composites_skipped,
              run.dropped, run.skipped);
  ASSERT_EQ(run.frames.size(), static_cast<size_t>(kFrames)) << "every frame estimated";
  EXPECT_EQ(run.dropped, 0);
  EXPECT_EQ(run.skipped, 0);
  for (int i = 0; i < kFrames; ++i) {
    EXPECT_EQ(run.frames[i].frame, recorded.frames[i].frame);
    EXPECT_EQ(run.frames[i].light.sun_rgb, recorded.frames[i].light.sun_rgb) << i;
    EXPECT_EQ(run.frames[i].light.sky_rgb, recorded.frames[i].light.sky_rgb) << i;
  }
  EXPECT_EQ(run.composited + run.composites_skipped, kFrames);
  // 3 s of camera and 0.25 s a composite: at most 12, and at least a few however busy the machine.
  EXPECT_GE(run.composited, 3);
  EXPECT_LE(run.composited, 13);
  ASSERT_EQ(sink.frames.size(), static_cast<size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i) EXPECT_EQ(sink.frames[i], recorded.frames[i].frame);
  EXPECT_EQ(sink.with_image, run.composited);
  EXPECT_EQ(stage.skips, run.composites_skipped) << "the stage is told of every frame it did not make";
}

TEST(PipelineRecordingTest, OptionsAreCheckedBeforeAnyWork) {
  LightingPipelineOptions options;
  options.max_frames = 0;
  EXPECT_NE(options.Check().find("max_frames"), std::string::npos);
  options.max_frames = 3;
  options.sun.move_threshold_deg = -1.0;
  EXPECT_NE(options.Check().find("sun.move_threshold_deg"), std::string::npos);
  options.sun = {};
  options.estimator.sampler.transfer.bounces = 0;
  EXPECT_EQ(options.Check(), "estimator.sampler.transfer.bounces: 0 is outside [1, 8]");
  options.estimator.sampler.transfer.bounces = 3;
  options.estimator.filter.median_window = 4;
  EXPECT_EQ(options.Check(), "estimator.filter.median_window: 4 frames is not odd");
  options.estimator.filter.median_window = 1;
  EXPECT_EQ(options.Check(), "");
}

}  // namespace
}  // namespace daylit::pipeline
