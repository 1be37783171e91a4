// The relighting stage's figures, one core: a full irradiance-volume update for 512 probes (8×8×8,
// 512 gather directions each, a 1024×512 env map) ≤ 2 ms; relighting courtyard-a's 1024×512 env
// map with a frame's light ≤ 3 ms; and the cost of a sun move for the relighter.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "bake/sampling.h"
#include "base/log.h"
#include "relight/env_relight.h"
#include "sh/exact_irradiance.h"
#include "sh/irradiance_volume.h"
#include "lightfit/light_fit.h"
#include "lightfit/lights.h"
#include "scene/scene.h"
#include "base/latlong.h"

namespace daylit::relight {
namespace {

void BM_VolumeUpdate512Probes(benchmark::State& state) {
  sh::GatherTables gather;
  gather.min = glm::vec3(-2.0f), gather.max = glm::vec3(2.0f);
  gather.resolution = glm::ivec3(8);
  gather.directions = bake::SphericalFibonacci(static_cast<int>(state.range(0)));
  // Texels as the bake's parallax gives them: each probe's directions land on the map point that
  // shows what they hit, here a sphere of 5 m radius around the probes seen from the centre.
  std::mt19937 rng(1);
  const size_t dirs = gather.directions.size();
  gather.texel.resize(gather.ProbeCount() * dirs);
  for (int k = 0; k < 8; ++k) {
    for (int j = 0; j < 8; ++j) {
      for (int i = 0; i < 8; ++i) {
        const glm::vec3 o = gather.ProbePosition(i, j, k);
        const size_t p = (static_cast<size_t>(k) * 8 + j) * 8 + i;
        for (size_t d = 0; d < dirs; ++d) {
          const glm::vec3 v = gather.directions[d];
          const float b = glm::dot(o, v), t = -b + std::sqrt(b * b - glm::dot(o, o) + 25.0f);
          gather.texel[p * dirs + d] = static_cast<uint32_t>(LatLongTexel(glm::dvec3(o + t * v), 1024, 512));
        }
      }
    }
  }
  std::uniform_real_distribution<float> radiance(0.0f, 10.0f);
  gather.map_texels = 1024 * 512;
  std::vector<glm::vec3> env(2 * gather.map_texels);  // the map and its sky layer (no direction escapes here)
  for (glm::vec3& l : env) l = glm::vec3(radiance(rng), radiance(rng), radiance(rng));
  sh::IrradianceVolume volume(gather);
  for (auto _ : state) {
    volume.Update(env);
    benchmark::DoNotOptimize(volume.coefficients().data());
  }
  state.counters["probes"] = static_cast<double>(gather.ProbeCount());
}
BENCHMARK(BM_VolumeUpdate512Probes)->Arg(256)->Arg(512)->Unit(benchmark::kMillisecond);

// Seed 002's ground truth: 20 480 icosahedron normals (bar ≤ 5 s) and a whole 1024×512
// irradiance map (bar ≤ 60 s; HDRShop took 24 hours) from a 1024×512 probe, on 2 cores.
void BM_ExactIrradiance20480(benchmark::State& state) {
  const HdrImage probe = scene::ReadHdrImage(DAYLIT_SOURCE_DIR "/probes/galileo_latlong_1024x512.hdr");
  const std::vector<glm::vec3> normals = sh::IcosahedronNormals(5);
  for (auto _ : state) benchmark::DoNotOptimize(sh::ExactIrradiance(probe, normals).data());
}
BENCHMARK(BM_ExactIrradiance20480)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ExactIrradianceMap1024x512(benchmark::State& state) {
  const HdrImage probe = scene::ReadHdrImage(DAYLIT_SOURCE_DIR "/probes/galileo_latlong_1024x512.hdr");
  for (auto _ : state) benchmark::DoNotOptimize(sh::ExactIrradianceMap(probe, 1024, 512).data());
}
BENCHMARK(BM_ExactIrradianceMap1024x512)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

// Irradiance Optimization of N lights from a 1024×512 probe, all of it: the exact irradiance at
// the fitting normals, median cut's start and the Ceres fit (bar for 8 lights ≤ 200 ms on 2
// cores). Rooitou Park (outdoor, with the sun) takes the most iterations of the bundled probes.
void BM_IrradianceOptimization(benchmark::State& state, const char* file) {
  const HdrImage probe = scene::ReadHdrImage(std::string(DAYLIT_SOURCE_DIR "/probes/") + file);
  int iterations = 0;
  for (auto _ : state) {
    const lightfit::LightFitResult fit = lightfit::IrradianceOptimization(probe, static_cast<int>(state.range(0)));
    iterations = fit.iterations;
    benchmark::DoNotOptimize(fit.lights.lights.data());
  }
  state.counters["lm_iterations"] = iterations;
}
BENCHMARK_CAPTURE(BM_IrradianceOptimization, galileo, "galileo_latlong_1024x512.hdr")
    ->Arg(4)->Arg(8)->Arg(32)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_IrradianceOptimization, rooitou, "rooitou_park_1k.hdr")
    ->Arg(4)->Arg(8)->Arg(32)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_MedianCut(benchmark::State& state) {
  const HdrImage probe = scene::ReadHdrImage(DAYLIT_SOURCE_DIR "/probes/galileo_latlong_1024x512.hdr");
  for (auto _ : state) benchmark::DoNotOptimize(lightfit::MedianCutLights(probe, static_cast<int>(state.range(0))).lights.data());
}
BENCHMARK(BM_MedianCut)->Arg(8)->Arg(128)->Unit(benchmark::kMillisecond);

struct Courtyard {
  scene::Scene scene = scene::LoadScene(DAYLIT_SOURCE_DIR "/recordings/courtyard-a");
  bake::SceneBake bake;
  std::unique_ptr<scene::RayCaster> caster;
  const glm::vec3 sun = glm::vec3(0.9571569f, -0.0397556f, 0.2868279f);  // burst 0 (info.json)

  Courtyard() {
    SetLogVerbosity(0);
    bool loaded = false;
    bake = bake::BakeOrLoad(scene, bake::BakeOptions{}, DAYLIT_BINARY_DIR "/bench-cache/courtyard-a", &loaded);
    caster = std::make_unique<scene::RayCaster>(scene.model);
  }
  static Courtyard& Get() {
    static Courtyard c;
    return c;
  }
};

void BM_RelightEnv(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  EnvRelighter relighter(c.bake, glm::vec3(c.scene.envmap->position), *c.caster);
  relighter.SetSun(c.sun);
  std::vector<glm::vec3> radiance;
  const estimation::SunSky light{{86.3, 63.6, 37.1}, {9.9, 9.7, 10.0}};
  for (auto _ : state) {
    relighter.Relight(light, 0.2, &radiance);
    benchmark::DoNotOptimize(radiance.data());
  }
  state.counters["texels"] = static_cast<double>(radiance.size());
}
BENCHMARK(BM_RelightEnv)->Unit(benchmark::kMillisecond);

// A sun move: shadow rays for the 288k model texels, the transfer of the representatives (their
// paths traced already), the sky's shape for the sky texels.
void BM_RelightEnvSunMove(benchmark::State& state) {
  Courtyard& c = Courtyard::Get();
  EnvRelighter relighter(c.bake, glm::vec3(c.scene.envmap->position), *c.caster);
  relighter.SetSun(c.sun);
  int k = 0;
  for (auto _ : state) {
    const float turn = (++k % 2 ? 0.1f : -0.1f) * 0.0175f;
    const glm::vec3 sun(c.sun.x * std::cos(turn) - c.sun.y * std::sin(turn), c.sun.x * std::sin(turn) + c.sun.y * std::cos(turn),
                        c.sun.z);
    benchmark::DoNotOptimize(relighter.SetSun(sun));
  }
}
BENCHMARK(BM_RelightEnvSunMove)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(4);

}  // namespace
}  // namespace daylit::relight
