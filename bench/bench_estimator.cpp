// Throughput of the estimator alone (one core): whole recordings held in
// memory, processed event by event, SAE reset between repetitions.
//   ./build/bench/bench_estimator --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <exception>
#include <vector>

#include "bench_recordings.h"
#include "evlife/algo/lifetime_estimator.h"

namespace {

using evlife::bench::recording;
using evlife::bench::Recording;

void run(benchmark::State& state, const std::string& name, int window, bool regularization) {
  const Recording* loaded = nullptr;
  try {
    loaded = &recording(name);
  } catch (const std::exception& e) {  // a recording missing from ../shared/data: this benchmark only
    state.SkipWithError(e.what());
    for (auto _ : state) {
    }
    return;
  }
  const Recording& rec = *loaded;
  evlife::LifetimeOptions o;
  o.sensor = rec.sensor;
  o.window_size = window;
  o.regularization = regularization;
  evlife::LifetimeEstimator est(o);
  std::vector<evlife::AugmentedEvent> out(rec.events.size());
  std::size_t noise = 0;
  for (auto _ : state) {
    state.PauseTiming();
    est.reset();
    state.ResumeTiming();
    est.process(rec.events, out);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  for (const auto& a : out) noise += a.is_noise();
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * rec.events.size()));
  state.counters["events"] = static_cast<double>(rec.events.size());
  state.counters["noise_share"] = static_cast<double>(noise) / static_cast<double>(out.size());
}

void BM_Estimator_N5_reg(benchmark::State& s, const char* name) { run(s, name, 5, true); }
void BM_Estimator_N5_noreg(benchmark::State& s, const char* name) { run(s, name, 5, false); }
void BM_Estimator_N3_reg(benchmark::State& s, const char* name) { run(s, name, 3, true); }
void BM_Estimator_N7_reg(benchmark::State& s, const char* name) { run(s, name, 7, true); }

BENCHMARK_CAPTURE(BM_Estimator_N5_reg, stripes, "stripes")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Estimator_N5_reg, garfield, "garfield")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Estimator_N5_reg, synthetic_1280x720, "synthetic_1280x720")->Unit(benchmark::kMillisecond);
// The same scene on smaller sensors: the per-event work alike, the footprint
// (surface and states) 1/4 and 1/16, so the ratio to 1280x720 shows what
// cache misses cost there.
BENCHMARK_CAPTURE(BM_Estimator_N5_reg, synthetic_640x360, "synthetic_640x360")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Estimator_N5_reg, synthetic_320x180, "synthetic_320x180")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Estimator_N5_noreg, stripes, "stripes")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Estimator_N3_reg, stripes, "stripes")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Estimator_N7_reg, stripes, "stripes")->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
