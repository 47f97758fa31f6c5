// What this machine charges for the engine's hand-offs (engine/README.md,
// "What the latency is made of"): how late a short sleep ends (the paced
// replay's problem; 1 ns timer slack as the source thread sets) and how long
// a thread sleeping on the engine's Semaphore takes to run once signalled
// from another core after that core went idle (a router -> worker hand-off).
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

}  // namespace

BENCHMARK_MAIN();
