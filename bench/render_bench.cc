// Rendering the bundled courtyard (960×540, two objects) with software GL (llvmpipe) on this
// machine: the compositor alone (shadow map, phantom, objects, 4× MSAA, resolve, read back and
// blend) and a whole frame of the replay after decoding (linearise, relight the env map,
// update the volume, the objects' shadows on real surfaces, composite). Bars: rendering alone
// ≥ 60 fps; the replay end to end ≥ 30 fps.
#include <benchmark/benchmark.h>

#include <memory>

#include "bake/bake.h"
#include "base/log.h"
#include "estimation/frame_estimator.h"
#include "pipeline/frame_fits.h"
#include "render/compositor.h"
#include "render/frame_renderer.h"
#include "render/gl_context.h"
#include "render/image_relight_gl.h"
#include "lightfit/env_lights.h"
#include "relight/image_relight.h"
#include "composite/object_shadows.h"
#include "scene/object_mesh.h"
#include "capture/frame_source.h"
#include "scene/scene.h"

namespace daylit::render {
namespace {

struct Courtyard {
  std::unique_ptr<HeadlessGlContext> gl;
  scene::Scene scene = scene::LoadScene(DAYLIT_SOURCE_DIR "/recordings/courtyard-a");
  bake::SceneBake bake;
  std::unique_ptr<scene::RayCaster> caster;
  pipeline::FrameFit fit;

  Courtyard() {
    SetLogVerbosity(0);
    std::string why;
    gl = HeadlessGlContext::Create(&why);
    if (gl == nullptr) throw std::runtime_error(why);
    bool loaded = false;
    bake = bake::BakeOrLoad(scene, bake::BakeOptions{}, DAYLIT_BINARY_DIR "/bench-cache/courtyard-a", &loaded);
    caster = std::make_unique<scene::RayCaster>(scene.model);
    fit = pipeline::FitRecordingFrame(scene, bake, *caster, 300);
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

// Arg: 0 the irradiance volume, N the sun plus N lights fitted to the relit map (--lighting lights:N).
void BM_RenderFrame(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  FrameRendererOptions options;
  options.lights = static_cast<int>(state.range(0));
  FrameRenderer renderer(c.scene, c.bake, *c.caster, options);
  std::vector<float> out;
  renderer.Render(c.fit.frame, c.fit.fit.light, c.fit.fit.overcast_share, c.fit.sun_dir, &out);  // the sun's one-off work
  for (auto _ : state) {
    renderer.Render(c.fit.frame, c.fit.fit.light, c.fit.fit.overcast_share, c.fit.sun_dir, &out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RenderFrame)->Arg(0)->Arg(2)->Arg(8)->Arg(16)->Unit(benchmark::kMillisecond)->UseRealTime();

// The objects' shadows and sky loss on the real surfaces (composite::ObjectShadows), on the CPU:
// per frame (B from the frame, the loss for its light; 310k of the 518k pixels on
// courtyard-a), and per sun move (the sun rays past the objects' bounding spheres).
struct CourtyardShadows {
  scene::SceneModel model;
  scene::RayCaster objects;
  composite::ObjectShadows shadows;
  std::vector<float> linear;

  explicit CourtyardShadows(Courtyard& c)
      : model(scene::ObjectsModel(c.scene.objects)), objects(model), shadows(c.scene, c.bake, *c.caster, objects) {
    relight::EnvRelighter relighter(c.bake, glm::vec3(c.scene.envmap->position), *c.caster);
    relighter.SetSun(c.fit.sun_dir);
    relight::EnvBasis basis;
    relighter.Basis(&basis);
    shadows.SetEnvBasis(basis);
    shadows.SetSun(c.fit.sun_dir);
    capture::LinearRadiance(c.fit.frame, capture::Linearizer(c.scene.response), &linear);
  }
};

void BM_ObjectShadows(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  CourtyardShadows s(c);
  std::vector<float> image;
  for (auto _ : state) {
    image = s.linear;
    s.shadows.Apply(c.fit.fit.light, c.fit.fit.overcast_share, image.data());
    benchmark::DoNotOptimize(image.data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ObjectShadows)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ObjectShadowsSunMove(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  CourtyardShadows s(c);
  int k = 0;
  for (auto _ : state) {
    const float turn = (++k % 2 ? 0.1f : -0.1f) * 0.0175f;
    const glm::vec3 d = c.fit.sun_dir;
    benchmark::DoNotOptimize(s.shadows.SetSun(
        glm::vec3(d.x * std::cos(turn) - d.y * std::sin(turn), d.x * std::sin(turn) + d.y * std::cos(turn), d.z)));
  }
}
BENCHMARK(BM_ObjectShadowsSunMove)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(6);

// --lighting lights:N when the sun moves or the light changes much: the relit map's three parts
// reprojected to the objects' centre and to each object, their exact irradiance at the fit's
// normals, Irradiance Optimization of the N directions and the per-part linear fits.
void BM_FitEnvLights(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  relight::EnvRelighter relighter(c.bake, glm::vec3(c.scene.envmap->position), *c.caster);
  relighter.SetSun(c.fit.sun_dir);
  relight::EnvBasis basis;
  relighter.Basis(&basis);
  std::vector<glm::vec3> centres;
  for (const scene::VirtualObject& o : c.scene.objects) centres.push_back(glm::vec3(o.position));
  lightfit::EnvLights lights(static_cast<int>(state.range(0)), *c.caster, centres, glm::vec3(c.scene.envmap->position),
                            c.bake.env.width, c.bake.env.height);
  const estimation::LightParts parts = estimation::SplitLight(c.fit.fit.light, c.fit.fit.overcast_share);
  for (auto _ : state) {
    lights.SetBasis(basis);
    benchmark::DoNotOptimize(lights.Update(parts));
  }
}
BENCHMARK(BM_FitEnvLights)->Arg(2)->Arg(8)->Arg(16)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_RendererSetUp(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  for (auto _ : state) {
    FrameRenderer renderer(c.scene, c.bake, *c.caster);
    benchmark::DoNotOptimize(&renderer);
  }
}
BENCHMARK(BM_RendererSetUp)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);

// Image relighting (seed 004) at 1280×720: the courtyard's terms for frame 300's sun and a sun
// three hours on, resampled (nearest) to 1280×720, and a frame in radiance units. Per frame: the
// ratio E_new / E_now and the modulation, on the CPU (both cores) or in GL (upload the frame,
// one full-screen pass, read back). Bar: ≥ 30 fps.
struct Relight720 {
  relight::RatioTerms terms;
  std::vector<float> frame;
  estimation::LightParts now, next;

  static const Relight720& Get() {
    static const Relight720 built = [] {
      Courtyard& c = Courtyard::Get();
      relight::ImageRelighter relighter(c.scene, c.bake, *c.caster);
      const glm::vec3 later = glm::normalize(glm::vec3(-c.fit.sun_dir.y, c.fit.sun_dir.x, c.fit.sun_dir.z));
      relighter.SetSuns(c.fit.sun_dir, later);
      const relight::RatioTerms& small = relighter.terms();
      std::vector<float> linear;
      capture::LinearRadiance(c.fit.frame, capture::Linearizer(c.scene.response), &linear);
      Relight720 r;
      r.terms.width = 1280, r.terms.height = 720;
      r.terms.now_sun = small.now_sun;
      const size_t n = 1280 * 720;
      for (auto* t : {&r.terms.now, &r.terms.next}) t->sun.resize(n), t->clear.resize(n), t->overcast.resize(n);
      r.terms.kind.resize(n);
      r.frame.resize(3 * n);
      for (size_t y = 0; y < 720; ++y) {
        for (size_t x = 0; x < 1280; ++x) {
          const size_t p = y * 1280 + x, q = (y * 540 / 720) * 960 + x * 960 / 1280;
          r.terms.now.sun[p] = small.now.sun[q], r.terms.now.clear[p] = small.now.clear[q];
          r.terms.now.overcast[p] = small.now.overcast[q], r.terms.next.sun[p] = small.next.sun[q];
          r.terms.next.clear[p] = small.next.clear[q], r.terms.next.overcast[p] = small.next.overcast[q];
          r.terms.kind[p] = small.kind[q];
          for (size_t k = 0; k < 3; ++k) r.frame[3 * p + k] = linear[3 * q + k];
        }
      }
      r.now = estimation::SplitLight(c.fit.fit.light, c.fit.fit.overcast_share);
      r.next = r.now;
      return r;
    }();
    return built;
  }
};

void BM_RelightImage720(benchmark::State& state) {
  const Relight720& r = Relight720::Get();
  std::vector<float> image;
  std::unique_ptr<ImageRelightGl> gl;
  if (state.range(0) == 1) gl = std::make_unique<ImageRelightGl>(1280, 720), gl->SetTerms(r.terms);
  for (auto _ : state) {
    image = r.frame;
    if (gl) {
      gl->Apply(r.terms, r.now, r.next, image.data());
    } else {
      relight::ApplyRatio(r.terms, r.now, r.next, image.data());
    }
    benchmark::DoNotOptimize(image.data());
  }
  state.SetLabel(state.range(0) == 1 ? "GL (llvmpipe)" : "CPU");
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RelightImage720)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// A sun move for the image relighter at the courtyard's 960×540: shadow rays for the 400k model
// pixels and the transfer of their representatives (paths traced already).
void BM_RelightImageSunMove(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  relight::ImageRelighter relighter(c.scene, c.bake, *c.caster);
  relighter.SetSuns(c.fit.sun_dir, c.fit.sun_dir);
  int k = 0;
  for (auto _ : state) {
    const float turn = (++k % 2 ? 0.1f : -0.1f) * 0.0175f;
    const glm::vec3 s = c.fit.sun_dir;
    const glm::vec3 sun(s.x * std::cos(turn) - s.y * std::sin(turn), s.x * std::sin(turn) + s.y * std::cos(turn), s.z);
    benchmark::DoNotOptimize(relighter.SetSuns(c.fit.sun_dir, sun));
  }
}
BENCHMARK(BM_RelightImageSunMove)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(4);

}  // namespace
}  // namespace daylit::render
