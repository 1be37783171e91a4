// The estimation's figures on the bundled recording (960×540): per-frame estimation after decoding
// (bar ≤ 2 ms median on one core), its parts, decoding alone (the capture issue's bar ≥ 200 fps),
// and the cost of a sun move (shadow rays and transfer terms, re-run when the sun moved > 0.05°).
#include <benchmark/benchmark.h>

#include <tbb/global_control.h>

#include "bake/bake.h"
#include "base/log.h"
#include "capture/video_decoder.h"
#include "estimation/light_interval.h"
#include "estimation/sampler.h"
#include "estimation/temporal_filter.h"
#include "scene/scene.h"

namespace daylit::estimation {
namespace {

struct Courtyard {
  scene::Scene scene = scene::LoadScene(DAYLIT_SOURCE_DIR "/recordings/courtyard-a");
  bake::SceneBake bake;
  std::unique_ptr<scene::RayCaster> caster;
  cv::Mat encoded, linear;  // frame 50 (clear), as decoded and linearised
  double exposure = 0.0;
  glm::vec3 sun{0.0f};

  Courtyard() {
    SetLogVerbosity(0);
    bool loaded = false;
    bake = bake::BakeOrLoad(scene, bake::BakeOptions{}, DAYLIT_BINARY_DIR "/bench-cache/courtyard-a", &loaded);
    caster = std::make_unique<scene::RayCaster>(scene.model);
    capture::VideoDecoder decoder(scene.frames.video);
    for (int i = 0; i <= 50; ++i) decoder.Next(&encoded);
    linear.create(encoded.size(), CV_32FC3);
    scene.response.Linearize(encoded.ptr<float>(), linear.ptr<float>(), encoded.total() * 3);
    exposure = scene.frame_times->frames[50].exposure.value_or(scene.exposure);
    sun = glm::vec3(0.9571569f, -0.0397556f, 0.2868279f);  // burst 0 (info.json)
  }
  static Courtyard& Get() {
    static Courtyard c;
    return c;
  }
  glm::vec3 Capture() const { return glm::vec3(scene.envmap->position); }
};

void BM_LinearizeFrame(benchmark::State& state) {
  const Courtyard& c = Courtyard::Get();
  cv::Mat linear(c.encoded.size(), CV_32FC3);
  for (auto _ : state) {
    c.scene.response.Linearize(c.encoded.ptr<float>(), linear.ptr<float>(), c.encoded.total() * 3);
    benchmark::DoNotOptimize(linear.data);
  }
}
BENCHMARK(BM_LinearizeFrame)->Unit(benchmark::kMillisecond);

void BM_Draw(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  Sampler sampler(c.bake, c.Capture(), *c.caster);
  sampler.SetSun(c.sun);
  for (auto _ : state) {
    const std::vector<Sample> samples = sampler.Draw(c.linear, c.exposure);
    benchmark::DoNotOptimize(samples.data());
  }
}
BENCHMARK(BM_Draw)->Unit(benchmark::kMillisecond);

void BM_FitSunSky(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  Sampler sampler(c.bake, c.Capture(), *c.caster);
  sampler.SetSun(c.sun);
  const std::vector<Sample> samples = sampler.Draw(c.linear, c.exposure);
  for (auto _ : state) {
    const SunSkyFitSummary fit = FitSunSky({}, samples);
    benchmark::DoNotOptimize(fit.light.sun_rgb.x);
  }
  state.counters["samples"] = static_cast<double>(samples.size());
}
BENCHMARK(BM_FitSunSky)->Unit(benchmark::kMillisecond);

// The courtyard frame's samples and their fit: what the benchmarks of the steps after the fit start from.
struct FittedFrame {
  std::vector<Sample> samples;
  SunSkyFitSummary fit;
};
FittedFrame FitCourtyardFrame(Courtyard& c) {
  Sampler sampler(c.bake, c.Capture(), *c.caster);
  sampler.SetSun(c.sun);
  FittedFrame out{sampler.Draw(c.linear, c.exposure), {}};
  out.fit = FitSunSky({}, out.samples);
  return out;
}

// A frame's 90% interval from its samples and fit (estimation/light_interval.h).
void BM_LightInterval(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  const FittedFrame f = FitCourtyardFrame(c);
  for (auto _ : state) {
    const LightInterval interval = IntervalOfFit({}, {}, f.samples, f.fit, c.bake.camera.surface);
    benchmark::DoNotOptimize(interval.sun.x);
  }
}
BENCHMARK(BM_LightInterval)->Unit(benchmark::kMillisecond);

// Everything after decoding and linearisation for one frame: samples, fit, interval, filter.
void BM_EstimateFrame(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  Sampler sampler(c.bake, c.Capture(), *c.caster);
  sampler.SetSun(c.sun);
  TemporalFilter filter(TemporalFilterOptions{});
  double t = 0.0;
  const LightIntervalOptions interval_options;
  SkyShapeSpread shape;
  StrataSensitivity sensitivity;
  long frame = 0;
  for (auto _ : state) {
    const std::vector<Sample> samples = sampler.Draw(c.linear, c.exposure);
    const SunSkyFitSummary fit = FitSunSky({}, samples);
    // The sky shape's and the strata sensitivity's refits every two seconds, as the estimator makes
    // them: every twentieth frame at 10 fps.
    if (frame++ % 20 == 0) {
      shape = SkyShapeSpreadOfFit(interval_options, {}, samples, fit, c.bake.camera.surface);
      sensitivity = StrataSensitivityOfFit(interval_options, {}, samples, fit);
    }
    const LightInterval interval =
        IntervalOfFit(interval_options, {}, samples, fit, c.bake.camera.surface, shape, sensitivity);
    const FilteredLight light = filter.Update(t += 0.1, fit.light, fit.confidence);
    benchmark::DoNotOptimize(light.light.sun_rgb.x);
    benchmark::DoNotOptimize(interval.sky.x);
  }
}
BENCHMARK(BM_EstimateFrame)->Unit(benchmark::kMillisecond);

// The sky shape's two refits of one frame (estimation/light_interval.h), made every two seconds.
void BM_SkyShapeSpread(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  const FittedFrame f = FitCourtyardFrame(c);
  for (auto _ : state) {
    const SkyShapeSpread shape = SkyShapeSpreadOfFit({}, {}, f.samples, f.fit, c.bake.camera.surface);
    benchmark::DoNotOptimize(shape.sky.x);
  }
}
BENCHMARK(BM_SkyShapeSpread)->Unit(benchmark::kMillisecond);

// The strata sensitivity's two refits of one frame (estimation/light_interval.h), made with the sky
// shape's.
void BM_StrataSensitivity(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  const FittedFrame f = FitCourtyardFrame(c);
  for (auto _ : state) {
    const StrataSensitivity sensitivity = StrataSensitivityOfFit({}, {}, f.samples, f.fit);
    benchmark::DoNotOptimize(sensitivity.sky.x);
  }
}
BENCHMARK(BM_StrataSensitivity)->Unit(benchmark::kMillisecond);

// A sun move: shadow rays for every model pixel, new strata, transfer terms of the pools (paths
// already traced: the first move traces them, which is timed apart).
void BM_SunMove(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  Sampler sampler(c.bake, c.Capture(), *c.caster);
  sampler.SetSun(c.sun);
  int k = 0;
  for (auto _ : state) {
    const float turn = (++k % 2 ? 0.1f : -0.1f) * 0.0175f;  // ±0.1° about the vertical
    const glm::vec3 sun(c.sun.x * std::cos(turn) - c.sun.y * std::sin(turn),
                        c.sun.x * std::sin(turn) + c.sun.y * std::cos(turn), c.sun.z);
    benchmark::DoNotOptimize(sampler.SetSun(sun));
  }
}
BENCHMARK(BM_SunMove)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_FirstSun(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  for (auto _ : state) {
    Sampler sampler(c.bake, c.Capture(), *c.caster);
    benchmark::DoNotOptimize(sampler.SetSun(c.sun));
  }
}
BENCHMARK(BM_FirstSun)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

}  // namespace
}  // namespace daylit::estimation
