// Cost of the synthetic event source (io/synthetic_scene.h): how fast the
// scenes of the accuracy test and the 1280x720 throughput scene are made, so
// that benches and the engine can tell generation time from processing time.
#include <benchmark/benchmark.h>

#include <vector>

#include "evlife/io/synthetic_scene.h"

namespace {

void BM_SyntheticStream(benchmark::State& state, const evlife::io::SceneSpec& spec) {
  std::vector<evlife::Event> buffer(1 << 16);
  std::int64_t events = 0;
  for (auto _ : state) {
    evlife::io::SyntheticSceneReader reader(spec);
    while (const std::size_t n = reader.read(buffer)) events += static_cast<std::int64_t>(n);
    benchmark::DoNotOptimize(buffer.data());
  }
  state.SetItemsProcessed(events);
}

BENCHMARK_CAPTURE(BM_SyntheticStream, edges_240x180_0_8s, evlife::io::edges_scene({240, 180}, 800'000, 1))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SyntheticStream, bar_346x260_0_6s, evlife::io::rotating_bar_scene({346, 260}, 600'000, 4))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SyntheticStream, mixed_128x128_3s, evlife::io::mixed_scene({128, 128}, 3'000'000, 1))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SyntheticStream, large_1280x720_0_1s, evlife::io::large_scene({1280, 720}, 100'000, 7))
    ->Unit(benchmark::kMillisecond);

// The same scene with ideal and with DVS pixels: the pixel model's cost.
evlife::io::SceneSpec edges_bar(const char* pixel) {
  evlife::io::SceneSpec s = evlife::io::edges_and_bar_scene({346, 260}, 500'000, 1);
  evlife::io::apply_pixel_setting(s, pixel);
  return s;
}
BENCHMARK_CAPTURE(BM_SyntheticStream, edges_bar_346x260_0_5s_ideal, edges_bar("ideal"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SyntheticStream, edges_bar_346x260_0_5s_dvs, edges_bar("dvs"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SyntheticStream, edges_bar_346x260_0_5s_dvs_dim, edges_bar("dvs-dim"))->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
