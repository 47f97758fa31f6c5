// End-to-end engine throughput and latency (issue 4):
//  - events/s with 1, 2, 4 workers on the real recordings replayed back to
//    back (stripes + garfield) and on a synthetic 1280x720 scene;
//  - the bare estimator on the same events (the engine's overhead baseline);
//  - latency from arrival at the source to merged output, p50/p99/max, with
//    the replay paced at 1 M events/s (drop policy, as for a live camera).
// Run: build/bench/bench_engine --benchmark_min_time=1
#include <benchmark/benchmark.h>

#include <algorithm>
#include <string>
#include <vector>

#include "evlife/algo/lifetime_estimator.h"
#include "evlife/engine/engine.h"
#include "evlife/engine/replay_source.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/synthetic_scene.h"

namespace ee = evlife::engine;
using evlife::AugmentedEvent;
using evlife::Event;
using evlife::SensorSize;

namespace {

std::vector<Event> read_all(const std::string& path) {
  auto reader = evlife::io::open_event_reader(path);
  std::vector<Event> events;
  std::vector<Event> buf(1 << 16);
  while (const std::size_t n = reader->read(buf)) events.insert(events.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
  return events;
}

struct Recording {
  std::vector<Event> events;
  SensorSize sensor;
  double duration_s = 0;
};

// stripes.mat then garfield.mat, garfield's clock shifted to follow on.
const Recording& recordings() {
  static const Recording r = [] {
    Recording rec;
    rec.sensor = {128, 128};
    const std::string dir = std::string(EVLIFE_SHARED_DATA_DIR) + "/reference/";
    rec.events = read_all(dir + "stripes.mat");
    const std::int64_t offset = rec.events.back().t_us + 1;
    for (Event e : read_all(dir + "garfield.mat")) {
      e.t_us += offset;
      rec.events.push_back(e);
    }
    rec.duration_s = static_cast<double>(rec.events.back().t_us - rec.events.front().t_us) * 1e-6;
    return rec;
  }();
  return r;
}

// 0.1 s of the `large` preset: 80 px grating tiles over a 1280x720 sensor.
const Recording& synthetic() {
  static const Recording r = [] {
    Recording rec;
    rec.sensor = {1280, 720};
    auto scene = evlife::io::generate_scene(evlife::io::large_scene(rec.sensor, 100'000, 7));
    rec.events = std::move(scene.events);
    rec.duration_s = static_cast<double>(rec.events.back().t_us - rec.events.front().t_us) * 1e-6;
    return rec;
  }();
  return r;
}

const Recording& data(int which) { return which == 0 ? recordings() : synthetic(); }

ee::EngineOptions options_for(const Recording& rec, int workers) {
  ee::EngineOptions o;
  o.lifetime.sensor = rec.sensor;
  o.workers = workers;
  // Enough tiles for every worker: 1x1 per polarity up to 2 workers, then 2x1.
  o.tiles_x = workers <= 2 ? 1 : (workers + 1) / 2;
  o.tiles_y = 1;
  o.stats_period_s = 0.0;
  return o;
}

void set_labels(benchmark::State& state, const Recording& rec, int which) {
  state.SetLabel(std::string(which == 0 ? "recordings" : "synthetic 1280x720") + ", " +
                 std::to_string(rec.events.size()) + " events");
}

void BM_BareEstimator(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  const Recording& rec = data(which);
  evlife::LifetimeOptions lo;
  lo.sensor = rec.sensor;
  std::vector<AugmentedEvent> out(rec.events.size());
  for (auto _ : state) {
    state.PauseTiming();
    evlife::LifetimeEstimator est(lo);
    state.ResumeTiming();
    est.process(rec.events, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(rec.events.size()));
  set_labels(state, rec, which);
}
BENCHMARK(BM_BareEstimator)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// Throughput, as fast as possible (policy block: nothing dropped), no sink.
void BM_Engine(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  const int workers = static_cast<int>(state.range(1));
  const Recording& rec = data(which);
  const ee::EngineOptions o = options_for(rec, workers);
  std::uint64_t dropped = 0;
  for (auto _ : state) {
    state.PauseTiming();
    ee::ReplaySource source(rec.events, rec.sensor);
    ee::Engine engine(source, nullptr, o);
    state.ResumeTiming();
    const ee::RunResult r = engine.run();
    dropped += r.stats.events_dropped;
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(rec.events.size()));
  state.counters["dropped"] = static_cast<double>(dropped);
  state.counters["tiles"] = o.tiles_x * o.tiles_y * 2;
  set_labels(state, rec, which);
}
BENCHMARK(BM_Engine)
    ->ArgsProduct({{0, 1}, {1, 2, 4}})
    ->ArgNames({"data", "workers"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Latency at 1 M events/s: the replay is paced so that events arrive at 1 M/s
// on average (the recordings' own rhythm, sped up); policy drop as for a
// camera. Arrival = when an event was due (so a lagging engine shows).
void BM_EngineLatency1M(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  const int workers = static_cast<int>(state.range(1));
  const Recording& rec = data(which);
  ee::EngineOptions o = options_for(rec, workers);
  o.auto_policy = false;
  o.policy = ee::OverloadPolicy::drop;
  o.batch_events = 256;
  const double rate = static_cast<double>(rec.events.size()) / rec.duration_s;
  const double speed = 1e6 / rate;
  ee::EngineStats st;
  for (auto _ : state) {
    ee::ReplaySource source(rec.events, rec.sensor, speed, ee::SourceKind::live);
    ee::Engine engine(source, nullptr, o);
    st = engine.run().stats;
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(rec.events.size()));
  state.counters["p50_us"] = st.latency_p50_us;
  state.counters["p99_us"] = st.latency_p99_us;
  state.counters["max_us"] = st.latency_max_us;
  state.counters["dropped_pct"] =
      100.0 * static_cast<double>(st.events_dropped) / static_cast<double>(st.events_in);
  state.counters["speedup"] = speed;
  set_labels(state, rec, which);
}
BENCHMARK(BM_EngineLatency1M)
    ->ArgsProduct({{0, 1}, {1, 2}})
    ->ArgNames({"data", "workers"})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
