// End-to-end engine throughput and latency (issue 4):
//  - events/s with 1, 2, 4 workers on the real recordings replayed back to
//    back (stripes + garfield) and on a synthetic 1280x720 scene;
//  - the bare estimator on the same events (the engine's overhead baseline);
//  - latency from arrival at the source to merged output, p50/p99/max, with
//    the replay paced at 1 M events/s (drop policy, as for a live camera).
// Run: build/bench/bench_engine --benchmark_min_time=1
#include <benchmark/benchmark.h>
#include <sys/mman.h>

#include <time.h>

#include <algorithm>
#include <string>
#include <vector>

#include "evlife/algo/lifetime_estimator.h"
#include "evlife/engine/engine.h"
#include "evlife/engine/pipeline.h"
#include "evlife/engine/replay_source.h"
#include "evlife/io/event_reader.h"
#include "evlife/io/synthetic_scene.h"

namespace ee = evlife::engine;
using evlife::AugmentedEvent;
using evlife::Event;
using evlife::SensorSize;

namespace {

// CPU time of the whole process (every thread), ns: the engine's cost per
// event stays measurable when other work shares the cores.
std::int64_t process_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

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

// 25 ms of the `large` preset (about 1 M events): 80 px grating tiles over a 1280x720 sensor.
const Recording& synthetic() {
  static const Recording r = [] {
    Recording rec;
    rec.sensor = {1280, 720};
    auto scene = evlife::io::generate_scene(evlife::io::large_scene(rec.sensor, 25'000, 7));
    rec.events = std::move(scene.events);
    rec.duration_s = static_cast<double>(rec.events.back().t_us - rec.events.front().t_us) * 1e-6;
    return rec;
  }();
  return r;
}

const Recording& data(int which) { return which == 0 ? recordings() : synthetic(); }

// tiles_x x 1 tiles per polarity (default margin: 4 x window size).
ee::EngineOptions options_for(const Recording& rec, int workers, int tiles_x = 1) {
  ee::EngineOptions o;
  o.lifetime.sensor = rec.sensor;
  o.workers = workers;
  o.tiles_x = tiles_x;
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
  std::int64_t cpu_ns = 0;
  for (auto _ : state) {
    state.PauseTiming();
    evlife::LifetimeEstimator est(lo);
    state.ResumeTiming();
    const std::int64_t c0 = process_cpu_ns();
    est.process(rec.events, out);
    cpu_ns += process_cpu_ns() - c0;
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(rec.events.size()));
  state.counters["cpu_ns_per_event"] =
      static_cast<double>(cpu_ns) / static_cast<double>(state.iterations() * static_cast<std::int64_t>(rec.events.size()));
  set_labels(state, rec, which);
}
BENCHMARK(BM_BareEstimator)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// Throughput, as fast as possible (policy block: nothing dropped), no sink.
void BM_Engine(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  const int workers = static_cast<int>(state.range(1));
  const int tiles_x = static_cast<int>(state.range(2));
  const Recording& rec = data(which);
  const ee::EngineOptions o = options_for(rec, workers, tiles_x);
  std::uint64_t dropped = 0;
  std::int64_t cpu_ns = 0;
  double balance_bound = 0;
  for (auto _ : state) {
    state.PauseTiming();
    ee::ReplaySource source(rec.events, rec.sensor);
    ee::Engine engine(source, nullptr, o);
    state.ResumeTiming();
    const std::int64_t c0 = process_cpu_ns();
    const ee::RunResult r = engine.run();
    cpu_ns += process_cpu_ns() - c0;
    dropped += r.stats.events_dropped;
    double sum = 0, max = 0;
    for (const auto& w : r.stats.workers) {
      sum += w.busy_s;
      max = std::max(max, w.busy_s);
    }
    // Speed-up the work split allows when every worker has a core of its
    // own (sum of busy times / the busiest worker's).
    balance_bound = max > 0 ? sum / max : 0;
  }
  state.counters["split_speedup_bound"] = balance_bound;
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(rec.events.size()));
  state.counters["cpu_ns_per_event"] =
      static_cast<double>(cpu_ns) / static_cast<double>(state.iterations() * static_cast<std::int64_t>(rec.events.size()));
  state.counters["dropped"] = static_cast<double>(dropped);
  std::uint64_t fed = 0;
  {
    ee::ReplaySource source(rec.events, rec.sensor);
    ee::Pipeline probe(source, nullptr, o);  // counts the margin's extra work, once
    probe.run_inline();
    for (const auto& w : probe.stats().workers) fed += w.events_fed;
  }
  state.counters["extra_work_pct"] =
      100.0 * (static_cast<double>(fed) / static_cast<double>(rec.events.size()) - 1.0);
  set_labels(state, rec, which);
}
// workers, tiles: 1 and 2 workers with one tile per polarity (output equal to
// the bare estimator); 2 and 4 workers with 2x1 tiles per polarity (balances
// ON/OFF imbalance; costs the margin's extra work).
BENCHMARK(BM_Engine)
    ->ArgsProduct({{0, 1}, {1}, {1}})
    ->ArgsProduct({{0, 1}, {2}, {1, 2}})
    ->ArgsProduct({{0, 1}, {4}, {2}})
    ->ArgNames({"data", "workers", "tiles_x"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Latency at 1 M (and 200 k) events/s: the replay is paced so that events
// arrive at that rate on average (the recordings' own rhythm, sped up), in
// packets of packet_us as a camera's USB transfers; policy drop as for a
// camera. Latency starts when an event's packet was due (so a lagging engine
// shows); age_p99 adds the event's wait for its packet.
void engine_latency(benchmark::State& state, const ee::RealtimeOptions& realtime);
void BM_EngineLatency(benchmark::State& state) { engine_latency(state, {}); }

// The same with the real-time settings of `evlife run --cpus 0,1
// --rt-priority 50 --lock-memory` (realtime:1) and without (realtime:0), run
// alternately so that both see the same machine load. Needs CAP_SYS_NICE and
// CAP_IPC_LOCK (root in the container here): else the benchmark reports the
// refusal as an error.
void BM_EngineLatencyRealtime(benchmark::State& state) {
  ee::RealtimeOptions rt;
  if (state.range(5) != 0) {
    rt.cpus = {0, 1};
    rt.rt_priority = 50;
    rt.lock_memory = true;
  }
  engine_latency(state, rt);
}

// Events per packet that an event of the replay shares its packet with, p99
// over events (the packet's events are estimated before it is delivered, so
// this sets the latency floor: x the per-event cost / workers).
double packet_events_p99(const Recording& rec, double speed, std::int64_t packet_us) {
  if (packet_us <= 0 || rec.events.empty()) return 0;
  std::vector<std::size_t> sizes;
  const double slot_us = static_cast<double>(packet_us) * speed;  // event time per packet
  std::int64_t current = -1;
  for (const Event& e : rec.events) {
    const auto slot = static_cast<std::int64_t>(static_cast<double>(e.t_us - rec.events.front().t_us) / slot_us);
    if (slot != current) {
      sizes.push_back(0);
      current = slot;
    }
    ++sizes.back();
  }
  std::vector<std::size_t> per_event;
  per_event.reserve(rec.events.size());
  for (const std::size_t n : sizes) per_event.insert(per_event.end(), n, n);
  std::nth_element(per_event.begin(), per_event.begin() + static_cast<std::ptrdiff_t>(per_event.size() * 99 / 100), per_event.end());
  return static_cast<double>(per_event[per_event.size() * 99 / 100]);
}

void engine_latency(benchmark::State& state, const ee::RealtimeOptions& realtime) {
  const int which = static_cast<int>(state.range(0));
  const int workers = static_cast<int>(state.range(1));
  const double target_rate = static_cast<double>(state.range(2)) * 1e3;
  const std::int64_t packet_us = state.range(3);
  const Recording& rec = data(which);
  ee::EngineOptions o = options_for(rec, workers);
  o.idle_spin_us = static_cast<int>(state.range(4));
  o.auto_policy = false;
  o.policy = ee::OverloadPolicy::drop;
  o.batch_events = 256;
  o.realtime = realtime;
  const double rate = static_cast<double>(rec.events.size()) / rec.duration_s;
  const double speed = target_rate / rate;
  ee::EngineStats st;
  for (auto _ : state) {
    ee::ReplaySource source(rec.events, rec.sensor, speed, ee::SourceKind::live);
    source.set_packet_us(packet_us);
    ee::Engine engine(source, nullptr, o);
    const ee::RunResult r = engine.run();
    if (realtime.lock_memory) munlockall();
    if (r.status == ee::RunStatus::realtime_error) {
      state.SkipWithError(r.message.c_str());
      return;
    }
    st = r.stats;
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(rec.events.size()));
  state.counters["p50_us"] = st.latency_p50_us;
  state.counters["p99_us"] = st.latency_p99_us;
  state.counters["max_us"] = st.latency_max_us;
  state.counters["age_p99_us"] = st.age_p99_us;
  // Where the p99 builds up (each from the packet's arrival; the slowest
  // worker): pulled by the source thread, batch started, event estimated;
  // p99_us adds the merge-order wait and the delivery.
  double started = 0, estimated = 0;
  for (const auto& w : st.workers) {
    started = std::max(started, w.started_p99_us);
    estimated = std::max(estimated, w.estimated_p99_us);
  }
  state.counters["over_1ms_pct"] =
      st.latency_count > 0 ? 100.0 * static_cast<double>(st.latency_over_1ms) / static_cast<double>(st.latency_count) : 0.0;
  state.counters["pulled_p99_us"] = st.pulled_p99_us;
  state.counters["started_p99_us"] = started;
  state.counters["estimated_p99_us"] = estimated;
  static const char* const kStarted[] = {"w0_started_p99_us", "w1_started_p99_us"};
  for (std::size_t w = 0; w < st.workers.size() && w < 2; ++w) state.counters[kStarted[w]] = st.workers[w].started_p99_us;
  state.counters["dropped_pct"] =
      100.0 * static_cast<double>(st.events_dropped) / static_cast<double>(st.events_in);
  state.counters["speedup"] = speed;
  state.counters["packet_events_p99"] = packet_events_p99(rec, speed, packet_us);
  set_labels(state, rec, which);
}
BENCHMARK(BM_EngineLatency)
    ->ArgsProduct({{0, 1}, {1, 2}, {1000, 200}, {ee::ReplaySource::kDefaultPacketUs}, {0}})
    ->ArgNames({"data", "workers", "kev_per_s", "packet_us", "idle_spin_us"})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
// The packet period's trade-off at 1 M events/s: shorter packets wait less
// but cost the engine more hand-offs per event.
BENCHMARK(BM_EngineLatency)
    ->Name("BM_EngineLatencyByPacket")
    ->ArgsProduct({{0, 1}, {1, 2}, {1000}, {25, 50, 200, 500}, {0}})
    ->ArgNames({"data", "workers", "kev_per_s", "packet_us", "idle_spin_us"})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
// Idle workers polling (and yielding) instead of sleeping: saves the thread
// wake-up per packet at the price of busy cores.
BENCHMARK(BM_EngineLatency)
    ->Name("BM_EngineLatencySpin")
    ->ArgsProduct({{0, 1}, {1, 2}, {1000, 200}, {ee::ReplaySource::kDefaultPacketUs}, {100}})
    ->ArgNames({"data", "workers", "kev_per_s", "packet_us", "idle_spin_us"})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_EngineLatencyRealtime)
    ->ArgsProduct({{0, 1}, {1, 2}, {1000}, {ee::ReplaySource::kDefaultPacketUs}, {0, 100}, {0, 1}})
    ->ArgNames({"data", "workers", "kev_per_s", "packet_us", "idle_spin_us", "realtime"})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
