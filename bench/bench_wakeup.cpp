// What this machine charges for the engine's hand-offs (engine/README.md,
// "What the latency is made of"): how late a short sleep ends (the paced
// replay's problem; 1 ns timer slack as the source thread sets) and how long
// a thread sleeping on the engine's Semaphore takes to run once signalled
// from another core after that core went idle (a router -> worker hand-off),
// and how often the machine takes a polling thread off its core for longer
// than the latency target (BM_SpinGaps: what no engine setting can avoid).
// Run: build/bench/bench_wakeup
#include <benchmark/benchmark.h>

#include <pthread.h>
#include <sched.h>
#include <sys/prctl.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>
#include <vector>

#include "evlife/engine/monotonic_clock.h"
#include "evlife/engine/pipeline_state.h"

namespace ee = evlife::engine;

namespace {
constexpr int kSamples = 2000;

void set_percentiles(benchmark::State& state, std::vector<std::int64_t> ns) {
  std::sort(ns.begin(), ns.end());
  state.counters["p50_us"] = static_cast<double>(ns[ns.size() / 2]) * 1e-3;
  state.counters["p99_us"] = static_cast<double>(ns[ns.size() * 99 / 100]) * 1e-3;
  state.counters["max_us"] = static_cast<double>(ns.back()) * 1e-3;
}

void pin_to(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu % static_cast<int>(std::max(1u, std::thread::hardware_concurrency())), &set);
  pthread_setaffinity_np(pthread_self(), sizeof set, &set);
}

void BM_SleepOvershoot(benchmark::State& state) {
  prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
  const std::int64_t sleep_ns = state.range(0) * 1000;
  std::vector<std::int64_t> late;
  for (auto _ : state) {
    late.clear();
    for (int i = 0; i < kSamples; ++i) {
      const std::int64_t t0 = ee::monotonic_ns();
      std::this_thread::sleep_for(std::chrono::nanoseconds(sleep_ns));
      late.push_back(ee::monotonic_ns() - t0 - sleep_ns);
    }
  }
  set_percentiles(state, late);
}
BENCHMARK(BM_SleepOvershoot)->Arg(50)->Arg(100)->ArgName("sleep_us")->Iterations(1)
    ->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ThreadWakeup(benchmark::State& state) {
  std::vector<std::int64_t> wake;
  for (auto _ : state) {
    wake.clear();
    ee::Semaphore sem{0, ee::kWakeSpins};
    std::atomic<std::int64_t> signalled_ns{0};
    std::thread waiter([&] {
      pin_to(1);
      for (int i = 0; i < kSamples; ++i) {
        sem.wait();
        wake.push_back(ee::monotonic_ns() - signalled_ns.load(std::memory_order_acquire));
      }
    });
    pin_to(0);
    for (int i = 0; i < kSamples; ++i) {
      std::this_thread::sleep_for(std::chrono::microseconds(100));  // the waiter's core idles
      signalled_ns.store(ee::monotonic_ns(), std::memory_order_release);
      sem.signal();
    }
    waiter.join();
  }
  set_percentiles(state, wake);
}
BENCHMARK(BM_ThreadWakeup)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// Threads that only read the clock, as the engine's source and workers poll
// with idle polling on: each gap between two reads is time the machine gave
// the core to something else. An event arriving during the part of a gap
// beyond 100 us waits over 100 us however fast the engine is, so where
// beyond_100us_pct (summed over the threads, each on the event's path) nears
// 1 %, a p99 under 100 us cannot hold at any rate.
void BM_SpinGaps(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  constexpr std::int64_t kSpinNs = 5'000'000'000;
  constexpr std::int64_t kTargetNs = 100'000;
  std::vector<std::vector<std::int64_t>> gaps(static_cast<std::size_t>(threads));
  for (auto _ : state) {
    std::vector<std::thread> spinners;
    for (int k = 0; k < threads; ++k) {
      spinners.emplace_back([&gaps, k] {
        std::vector<std::int64_t>& mine = gaps[static_cast<std::size_t>(k)];
        mine.reserve(1 << 16);
        const std::int64_t start = ee::monotonic_ns();
        std::int64_t last = start;
        while (last - start < kSpinNs) {
          const std::int64_t now = ee::monotonic_ns();
          if (now - last > 20'000) mine.push_back(now - last);
          last = now;
        }
      });
    }
    for (std::thread& t : spinners) t.join();
  }
  std::int64_t over_target = 0, over_1ms = 0, beyond_target_ns = 0, longest = 0;
  for (const std::vector<std::int64_t>& mine : gaps) {
    for (const std::int64_t g : mine) {
      over_target += g > kTargetNs;
      over_1ms += g > 1'000'000;
      beyond_target_ns += std::max<std::int64_t>(0, g - kTargetNs);
      longest = std::max(longest, g);
    }
  }
  const double seconds = static_cast<double>(kSpinNs) * 1e-9;
  state.counters["over_100us_per_s"] = static_cast<double>(over_target) / seconds / threads;
  state.counters["over_1ms_per_s"] = static_cast<double>(over_1ms) / seconds / threads;
  state.counters["beyond_100us_pct"] = 100.0 * static_cast<double>(beyond_target_ns) * 1e-9 / seconds;
  state.counters["max_us"] = static_cast<double>(longest) * 1e-3;
}
BENCHMARK(BM_SpinGaps)->Arg(1)->Arg(2)->ArgName("threads")->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
