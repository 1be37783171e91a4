// Solar position throughput on one core: one call, and the whole `daylit sunpos --csv` path
// (parse, compute, format) for 100 000 rows at distinct times and places.
#include <benchmark/benchmark.h>

#include <fmt/format.h>

#include <random>

#include "base/csv.h"
#include "sunmodel/solar_position.h"
#include "sunmodel/sunpos_batch.h"

namespace daylit::sunmodel {
namespace {

// state.range(0): the year; ERFA's series cost more far from J2000 (larger sin/cos arguments).
void BM_ComputeSunPosition(benchmark::State& state) {
  UtcTime t;
  t.year = static_cast<int>(state.range(0));
  t.month = 6;
  t.day = 21;
  const GeoSite site{57.0488, 9.9217, 10.0};
  const Atmosphere atmosphere = Atmosphere::Standard(site.elevation_m);
  int step = 0;
  for (auto _ : state) {
    t.hour = step % 24;
    t.minute = (step / 24) % 60;
    t.second = (step % 600) * 0.1;
    ++step;
    benchmark::DoNotOptimize(ComputeSunPosition(t, site, atmosphere, {}));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ComputeSunPosition)->Arg(1900)->Arg(2000)->Arg(2026)->Arg(2100);

std::string MakeCsv(int rows) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> lat(-89, 89), lon(-180, 180), elev(0, 3000);
  std::uniform_int_distribution<int> year(1900, 2100), month(1, 12), day(1, 28), hour(0, 23),
      minute(0, 59);
  fmt::memory_buffer out;
  fmt::format_to(std::back_inserter(out), "utc,lat_deg,lon_deg,elev_m,pressure_hpa,temp_c\n");
  for (int i = 0; i < rows; ++i) {
    fmt::format_to(std::back_inserter(out), "{:04d}-{:02d}-{:02d}T{:02d}:{:02d}:{:06.3f}Z,{:.6f},{:.6f},{:.1f},1013.25,10\n",
                   year(rng), month(rng), day(rng), hour(rng), minute(rng), 59.999 * (i % 1000) / 1000.0,
                   lat(rng), lon(rng), elev(rng));
  }
  return fmt::to_string(out);
}

void BM_SunposCsv100k(benchmark::State& state) {
  const std::string csv = MakeCsv(100000);
  for (auto _ : state) {
    const std::string out = ComputeSunposCsv(ParseCsv(csv, "bench.csv"));
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * 100000);
}
BENCHMARK(BM_SunposCsv100k)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace daylit::sunmodel
