// How much tiling changes the output (issue 4): share of events whose
// lifetime differs from the single-threaded estimator's, on the real
// recordings, per tile grid and margin. Deterministic (the pipeline is driven
// inline; threaded runs give the same bits), so one iteration each.
// Run: build/bench/bench_engine_margin
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "evlife/algo/lifetime_estimator.h"
#include "evlife/engine/pipeline.h"
#include "evlife/engine/replay_source.h"
#include "evlife/io/event_reader.h"

namespace ee = evlife::engine;
using evlife::AugmentedEvent;
using evlife::Event;

namespace {

const char* const kFiles[] = {"stripes.mat", "garfield.mat"};

struct Reference {
  std::vector<Event> events;
  std::vector<AugmentedEvent> bare;
};

const Reference& reference(int file) {
  static Reference refs[2];
  Reference& r = refs[file];
  if (r.events.empty()) {
    auto reader = evlife::io::open_event_reader(std::string(EVLIFE_SHARED_DATA_DIR) +
                                                "/reference/" + kFiles[file]);
    std::vector<Event> buf(1 << 16);
    while (const std::size_t n = reader->read(buf))
      r.events.insert(r.events.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
    evlife::LifetimeOptions lo;
    lo.sensor = {128, 128};
    evlife::LifetimeEstimator est(lo);
    r.bare.resize(r.events.size());
    est.process(r.events, r.bare);
  }
  return r;
}

void BM_TiledDiffersFromSingleThread(benchmark::State& state) {
  const int file = static_cast<int>(state.range(0));
  const int tiles = static_cast<int>(state.range(1));
  const int margin = static_cast<int>(state.range(2));
  const Reference& ref = reference(file);
  ee::EngineOptions o;
  o.lifetime.sensor = {128, 128};
  o.workers = 2;
  o.tiles_x = tiles;
  o.tiles_y = tiles;
  o.margin_px = margin;
  o.stats_period_s = 0;
  std::vector<AugmentedEvent> out;
  std::uint64_t fed = 0;
  for (auto _ : state) {
    out.clear();
    ee::ReplaySource source(ref.events, o.lifetime.sensor);
    ee::CallbackSink sink([&](std::span<const AugmentedEvent> s) { out.insert(out.end(), s.begin(), s.end()); });
    ee::Pipeline p(source, &sink, o);
    p.run_inline();
    fed = 0;
    for (const auto& w : p.stats().workers) fed += w.events_fed;
  }
  std::size_t lifetime_differs = 0, noise_label_differs = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    lifetime_differs += out[i].lifetime_us != ref.bare[i].lifetime_us ? 1 : 0;
    noise_label_differs += out[i].is_noise() != ref.bare[i].is_noise() ? 1 : 0;
  }
  const double n = static_cast<double>(out.size());
  state.counters["lifetime_differs_pct"] = 100.0 * static_cast<double>(lifetime_differs) / n;
  state.counters["noise_label_differs_pct"] = 100.0 * static_cast<double>(noise_label_differs) / n;
  state.counters["extra_work_pct"] = 100.0 * (static_cast<double>(fed) / n - 1.0);
  state.SetLabel(std::string(kFiles[file]) + " " + std::to_string(tiles) + "x" +
                 std::to_string(tiles) + " tiles, margin " + std::to_string(margin) + " px");
}
BENCHMARK(BM_TiledDiffersFromSingleThread)
    ->ArgsProduct({{0, 1}, {2, 4}, {2, 5, 10, 20, 40}})
    ->ArgNames({"file", "tiles", "margin"})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

// With one tile per polarity the output must be identical (0 %).
BENCHMARK(BM_TiledDiffersFromSingleThread)
    ->Args({0, 1, 0})
    ->Args({1, 1, 0})
    ->ArgNames({"file", "tiles", "margin"})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
