// Rendering the bundled courtyard (960×540, two objects) with software GL (llvmpipe) on this
// machine: the compositor alone (shadow map, background, phantom, objects, 4× MSAA, resolve and
// read back) and a whole frame of the replay after decoding (linearise, relight the env map,
// update the volume, the objects' shadows on real surfaces, composite). Bars: rendering alone
// ≥ 60 fps; the replay end to end ≥ 30 fps.
#include <benchmark/benchmark.h>

#include <memory>

#include "bake/bake.h"
#include "base/log.h"
#include "estimation/recording_estimator.h"
#include "render/compositor.h"
#include "render/frame_renderer.h"
#include "render/gl_context.h"
#include "scene/scene.h"

namespace daylit::render {
namespace {

struct Courtyard {
  std::unique_ptr<HeadlessGlContext> gl;
  scene::Scene scene = scene::LoadScene(DAYLIT_SOURCE_DIR "/recordings/courtyard-a");
  bake::SceneBake bake;
  std::unique_ptr<scene::RayCaster> caster;
  estimation::FrameFit fit;

  Courtyard() {
    SetLogVerbosity(0);
    std::string why;
    gl = HeadlessGlContext::Create(&why);
    if (gl == nullptr) throw std::runtime_error(why);
    bool loaded = false;
    bake = bake::BakeOrLoad(scene, bake::BakeOptions{}, DAYLIT_BINARY_DIR "/bench-cache/courtyard-a", &loaded);
    caster = std::make_unique<scene::RayCaster>(scene.model);
    fit = estimation::FitFrame(scene, bake, *caster, 300, {});
  }
  static Courtyard& Get() {
    static Courtyard c;
    return c;
  }
};

void BM_CompositeFrame(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  FrameRenderer renderer(c.scene, c.bake, *c.caster);
  std::vector<float> out;
  renderer.Render(c.fit.frame, c.fit.fit.light, c.fit.fit.overcast_share, c.fit.sun_dir, &out);  // sets up the sun
  std::vector<float> linear;
  renderer.Linearize(c.fit.frame, &linear);
  Compositor compositor(c.scene);
  CompositeInput input;
  input.light = c.fit.fit.light;
  input.sun_dir = c.fit.sun_dir;
  for (auto _ : state) {
    out = linear;
    compositor.Render(input, out.data());
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_CompositeFrame)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_RenderFrame(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  FrameRenderer renderer(c.scene, c.bake, *c.caster);
  std::vector<float> out;
  renderer.Render(c.fit.frame, c.fit.fit.light, c.fit.fit.overcast_share, c.fit.sun_dir, &out);  // the sun's one-off work
  for (auto _ : state) {
    renderer.Render(c.fit.frame, c.fit.fit.light, c.fit.fit.overcast_share, c.fit.sun_dir, &out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RenderFrame)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_RendererSetUp(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  for (auto _ : state) {
    FrameRenderer renderer(c.scene, c.bake, *c.caster);
    benchmark::DoNotOptimize(&renderer);
  }
}
BENCHMARK(BM_RendererSetUp)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);

}  // namespace
}  // namespace daylit::render
