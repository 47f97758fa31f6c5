// Throughput of the estimator alone (one core): whole recordings held in
// memory, processed event by event, SAE reset between repetitions.
//   ./build/bench/bench_estimator --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "evlife/algo/lifetime_estimator.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/synthetic_scene.h"

namespace {

struct Recording {
  std::vector<evlife::Event> events;
  evlife::SensorSize sensor;
};

const Recording& recording(const std::string& name) {
  static std::map<std::string, Recording> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  Recording r;
  if (name == "synthetic_1280x720") {
    r.sensor = {1280, 720};
    r.events = evlife::io::generate_scene(evlife::io::large_scene(r.sensor, 200'000, 1)).events;
  } else {
    const std::string path = std::string(EVLIFE_SHARED_DATA_DIR) + "/reference/" + name + ".mat";
    auto reader = evlife::io::open_event_reader(path);
    r.sensor = reader->sensor_size().value_or(evlife::SensorSize{128, 128});
    std::vector<evlife::Event> buf(1 << 16);
    while (const std::size_t n = reader->read(buf)) r.events.insert(r.events.end(), buf.begin(), buf.begin() + n);
  }
  return cache.emplace(name, std::move(r)).first->second;
}

void run(benchmark::State& state, const std::string& name, int window, bool regularization) {
  const Recording& rec = recording(name);
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
BENCHMARK_CAPTURE(BM_Estimator_N5_noreg, stripes, "stripes")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Estimator_N3_reg, stripes, "stripes")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Estimator_N7_reg, stripes, "stripes")->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
