// The bake's figures: the full bake of the bundled recording (bar ≤ 60 s on 2 cores), and shadow
// rays toward the sun for 100 000 camera points (bar ≤ 20 ms), which the online stages re-run
// whenever the sun has moved.
#include <benchmark/benchmark.h>

#include <random>

#include "bake/bake.h"
#include "base/log.h"
#include "scene/raycaster.h"
#include "scene/scene.h"

namespace daylit::bake {
namespace {

const scene::Scene& Courtyard() {
  static const scene::Scene scene = scene::LoadScene(DAYLIT_SOURCE_DIR "/recordings/courtyard-a");
  return scene;
}

void BM_BakeCourtyard(benchmark::State& state) {
  SetLogVerbosity(0);
  for (auto _ : state) {
    const SceneBake bake = RunBake(Courtyard(), BakeOptions{});
    benchmark::DoNotOptimize(bake.camera.albedo.data());
  }
}
BENCHMARK(BM_BakeCourtyard)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

void BM_SunVisibility100k(benchmark::State& state) {
  const scene::Scene& scene = Courtyard();
  const scene::RayCaster caster(scene.model);
  const scene::CameraModel camera = scene.Camera();
  // 100 000 random camera pixels' points on the model, as the estimation samples them.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, scene.intrinsics.width - 1), v(0, scene.intrinsics.height - 1);
  std::vector<glm::dvec2> pixels(110000);
  for (glm::dvec2& p : pixels) p = {u(rng), v(rng)};
  const std::vector<glm::dvec3> rays = camera.UnprojectToWorldRays(pixels);
  std::vector<glm::vec3> points, normals;
  for (const glm::dvec3& r : rays) {
    if (points.size() == 100000) break;
    const scene::RayHit hit = caster.Intersect(glm::vec3(camera.CenterInWorld()), glm::vec3(r));
    if (!hit.IsHit()) continue;
    points.push_back(glm::vec3(camera.CenterInWorld()) + hit.t * glm::vec3(r));
    normals.push_back(hit.normal);
  }
  const glm::vec3 sun = glm::normalize(glm::vec3(-0.65f, -0.19f, 0.74f));  // 13:48 UTC in courtyard-a
  std::vector<uint8_t> lit(points.size());
  for (auto _ : state) {
    SunVisibility(caster, points.data(), normals.data(), points.size(), sun, 2e-3f, lit.data());
    benchmark::DoNotOptimize(lit.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(points.size()));
  state.counters["points"] = static_cast<double>(points.size());
}
BENCHMARK(BM_SunVisibility100k)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace daylit::bake
