// The relighting stage's figures: a full irradiance-volume update for 512 probes (8×8×8, 512
// gather directions each, a 1024×512 env map) ≤ 2 ms on one core.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "bake/sampling.h"
#include "relight/irradiance_volume.h"
#include "scene/latlong.h"

namespace daylit::relight {
namespace {

void BM_VolumeUpdate512Probes(benchmark::State& state) {
  bake::GatherTables gather;
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
          gather.texel[p * dirs + d] = static_cast<uint32_t>(scene::LatLongTexel(glm::dvec3(o + t * v), 1024, 512));
        }
      }
    }
  }
  std::uniform_real_distribution<float> radiance(0.0f, 10.0f);
  std::vector<glm::vec3> env(1024 * 512);
  for (glm::vec3& l : env) l = glm::vec3(radiance(rng), radiance(rng), radiance(rng));
  IrradianceVolume volume(gather);
  for (auto _ : state) {
    volume.Update(env);
    benchmark::DoNotOptimize(volume.coefficients().data());
  }
  state.counters["probes"] = static_cast<double>(gather.ProbeCount());
}
BENCHMARK(BM_VolumeUpdate512Probes)->Arg(256)->Arg(512)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace daylit::relight
