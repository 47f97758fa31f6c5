// Cost of rendering: one 1280x720 frame of the events active at an arbitrary
// instant (target < 2 ms), the fixed-window baseline, feeding events, and a
// DVS128 compare frame (3 panels, x4). Items = frames (pixels for the
// per-pixel benches are in the "px/s" counter). Run e.g.
//   build/bench/bench_render --benchmark_min_time=1
#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <vector>

#include <opencv2/core.hpp>

#include "evlife/io/synthetic_scene.h"
#include "evlife/algo/active_event_map.h"
#include "evlife/render/fixed_window_map.h"
#include "evlife/render/frame_composer.h"
#include "evlife/render/frame_painter.h"

namespace {

using evlife::AugmentedEvent;
using evlife::SensorSize;

// Edges in every direction and speed over the sensor, plus 20 % noise: about
// 4 events per pixel over 100 ms, so a good share of pixels is active.
std::vector<AugmentedEvent> busy_events(SensorSize s, std::size_t n) {
  std::mt19937_64 rng(1234);
  std::vector<AugmentedEvent> events(n);
  for (std::size_t i = 0; i < n; ++i) {
    AugmentedEvent& a = events[i];
    a.event.t_us = static_cast<std::int64_t>(i * 100000 / n);
    a.event.x = static_cast<std::uint16_t>(rng() % static_cast<unsigned>(s.width));
    a.event.y = static_cast<std::uint16_t>(rng() % static_cast<unsigned>(s.height));
    a.event.p = (rng() & 1) ? 1 : -1;
    a.lifetime_us = (rng() % 5 == 0) ? 0.0f : static_cast<float>(300 + rng() % 20000);
    a.vx_px_s = static_cast<float>(static_cast<int>(rng() % 2001) - 1000);
    a.vy_px_s = static_cast<float>(static_cast<int>(rng() % 2001) - 1000);
  }
  return events;
}

constexpr SensorSize kHd{1280, 720};

// A realistic frame: the synthetic "large" scene (gratings over the whole
// sensor, lifetimes 0.3..20 ms, noise) with its true lifetimes and velocities.
const std::vector<AugmentedEvent>& scene_events() {
  static const std::vector<AugmentedEvent> events = [] {
    const auto scene = evlife::io::generate_scene(evlife::io::large_scene(kHd, 60000, 7));
    std::vector<AugmentedEvent> out(scene.events.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
      const auto& t = scene.truth[i];
      out[i].event = scene.events[i];
      const auto lifetime_us = static_cast<float>(t.lifetime_us);
      const bool edge = !t.is_noise && lifetime_us > 0.0f;
      out[i].lifetime_us = edge ? lifetime_us : 0.0f;
      out[i].vx_px_s = edge ? static_cast<float>(t.nx) / lifetime_us * 1e6f : 0.0f;
      out[i].vy_px_s = edge ? static_cast<float>(t.ny) / lifetime_us * 1e6f : 0.0f;
    }
    return out;
  }();
  return events;
}

// Arg 0: colour mode (0 lifetime, 1 polarity, 2 plain); arg 1: 0 synthetic
// scene with true lifetimes, 1 random events (4 per pixel, worst case).
void BM_PaintActive_1280x720(benchmark::State& state) {
  const auto mode = static_cast<evlife::render::ColorMode>(state.range(0));
  evlife::ActiveEventMap set(kHd);
  const auto& events = state.range(1) == 0 ? scene_events()
                                           : busy_events(kHd, 4u * static_cast<std::size_t>(kHd.pixel_count()));
  set.feed(events);
  const evlife::render::LifetimeColormap cmap;
  cv::Mat img;
  const std::int64_t t_last = events.back().event.t_us;
  std::int64_t k = 0;
  for (auto _ : state) {
    // Arbitrary instants just after the last event, never a frame multiple.
    const std::int64_t t = t_last + 1 + (k++ * 37) % 1000;
    evlife::render::paint_active(set, t, mode, cmap, img);
    benchmark::DoNotOptimize(img.data);
  }
  const std::size_t active = set.count_active(t_last + 1);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
  state.counters["px/s"] = benchmark::Counter(static_cast<double>(state.iterations()) * static_cast<double>(kHd.pixel_count()),
                                              benchmark::Counter::kIsRate);
  state.counters["active_px"] = static_cast<double>(active);
  state.SetLabel(std::string(evlife::render::to_string(mode)));
}
BENCHMARK(BM_PaintActive_1280x720)
    ->Args({0, 0})->Args({1, 0})->Args({2, 0})->Args({0, 1})
    ->Unit(benchmark::kMillisecond);

// Same synthetic scene; every event of the last 30 ms is drawn.
void BM_PaintWindow30ms_1280x720(benchmark::State& state) {
  evlife::render::FixedWindowMap map(kHd);
  const auto& events = scene_events();
  map.feed(events);
  cv::Mat img;
  std::int64_t t = events.back().event.t_us;
  for (auto _ : state) {
    t += 37;
    evlife::render::paint_window(map, t, 30000, evlife::render::ColorMode::plain, img);
    benchmark::DoNotOptimize(img.data);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
  state.counters["active_px"] = static_cast<double>(map.count_active(events.back().event.t_us, 30000));
}
BENCHMARK(BM_PaintWindow30ms_1280x720)->Unit(benchmark::kMillisecond);

// Feeding cost per event (items = events), edge thinning on.
void BM_FeedActiveEventSet_1280x720(benchmark::State& state) {
  evlife::ActiveEventMap set(kHd, true);
  const auto events = busy_events(kHd, 1u << 20);
  for (auto _ : state) {
    set.reset();
    set.feed(events);
    benchmark::DoNotOptimize(set.stats().stored);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * events.size()));
}
BENCHMARK(BM_FeedActiveEventSet_1280x720)->Unit(benchmark::kMillisecond);

// What `evlife render --mode compare` draws per frame for a DVS128.
void BM_ComposeCompare_128x128_x4(benchmark::State& state) {
  constexpr SensorSize kDvs{128, 128};
  evlife::ActiveEventMap set(kDvs);
  evlife::render::FixedWindowMap map(kDvs);
  const auto events = busy_events(kDvs, 60000);
  set.feed(events);
  map.feed(events);
  evlife::render::FrameComposer composer(evlife::render::parse_view_mode("compare"), {}, "compare");
  std::int64_t t = events.back().event.t_us;
  for (auto _ : state) {
    t += 37;
    benchmark::DoNotOptimize(composer.compose(set, map, t).data);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK(BM_ComposeCompare_128x128_x4)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
