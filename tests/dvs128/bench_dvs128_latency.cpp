// Latency from a bulk transfer's completion (libusb callback on the source
// thread) to the augmented event at the engine's output, under a paced
// emulated stream of 1 M events/s: every K ms the emulated DVS128 gets one
// packet of K*1000 events (1 us apart on the device clock), one packet per
// bulk transfer. Also reported: from the packet's arrival at the emulated
// device (includes umockdev's ioctl round trips, the emulation's cost).
// Percentiles over every event. Must run under umockdev-wrapper:
//   umockdev-wrapper ./tests/bench_dvs128_latency
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>
#include <vector>

#include "dvs128_emulator.h"
#include "evlife/engine/augmented_sink.h"
#include "evlife/engine/dvs128_source.h"
#include "evlife/engine/engine.h"
#include "evlife/engine/monotonic_clock.h"

namespace {

using namespace std::chrono_literals;
using evlife::testing::dvs128_word;
using evlife::testing::kWrapWord;


struct Probe {
  std::vector<std::int64_t> completed_ns;  // per transfer, in order (source thread)
  std::atomic<std::size_t> transfers{0};
  static void on_transfer(void* self, std::int64_t ns) {
    auto* p = static_cast<Probe*>(self);
    const std::size_t i = p->transfers.load(std::memory_order_relaxed);
    if (i < p->completed_ns.size()) p->completed_ns[i] = ns;
    p->transfers.store(i + 1, std::memory_order_release);
  }
};

double percentile(std::vector<std::int64_t>& v, double q) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return static_cast<double>(v[k]) / 1000.0;  // ns -> us
}

void BM_Dvs128TransferToOutputLatency(benchmark::State& state) {
  const int packet_ms = static_cast<int>(state.range(0));
  const int events_per_packet = 1000 * packet_ms;  // 1 M events/s
  const int packets = 1000 / packet_ms;             // 1 s of stream
  for (auto _ : state) {
    (void)_;  // clang-analyzer: the loop variable is only a counter
    evlife::testing::UsbTestbed bed;
    auto& cam = bed.add_dvs128();
    Probe probe;
    probe.completed_ns.assign(static_cast<std::size_t>(packets), 0);
    const int transfer_bytes = (4 * events_per_packet / 4096 + 1) * 4096;
    std::vector<std::int64_t> pushed_ns(static_cast<std::size_t>(packets), 0);
    std::vector<std::int64_t> from_transfer, from_push;
    from_transfer.reserve(static_cast<std::size_t>(packets) * events_per_packet);
    from_push.reserve(from_transfer.capacity());
    std::atomic<std::size_t> seen{0};

    evlife::engine::Dvs128Source::Options so;
    so.transfer_bytes = transfer_bytes;
    so.on_transfer = &Probe::on_transfer;
    so.on_transfer_user = &probe;
    evlife::engine::Dvs128Source source(so);
    evlife::engine::CallbackSink sink([&](std::span<const evlife::AugmentedEvent> events) {
      const std::int64_t now = evlife::engine::monotonic_ns();
      for (const auto& a : events) {
        const auto p = static_cast<std::size_t>((a.event.t_us - 1) / events_per_packet);
        from_transfer.push_back(now - probe.completed_ns[p]);
        from_push.push_back(now - pushed_ns[p]);
      }
      seen.fetch_add(events.size(), std::memory_order_release);
    });
    evlife::engine::EngineOptions eo;
    eo.stats_period_s = 0.0;
    evlife::engine::Engine engine(source, &sink, eo);
    evlife::engine::RunResult result;
    std::thread runner([&] { result = engine.run(); });

    // Pace: packet p enters the emulated device at start + p ms.
    std::int64_t t_us = 0;
    const auto start = std::chrono::steady_clock::now() + 20ms;
    for (int p = 0; p < packets; ++p) {
      std::vector<std::uint32_t> words;
      for (int k = 0; k < events_per_packet; ++k) {
        ++t_us;
        if (t_us % 0x4000 == 0) words.push_back(kWrapWord);
        words.push_back(dvs128_word(k % 128, (k / 128) % 128, (k & 1) != 0,
                                    static_cast<int>(t_us % 0x4000)));
      }
      auto bytes = evlife::testing::words_to_bytes(words);
      std::this_thread::sleep_until(start + std::chrono::milliseconds(p * packet_ms));
      pushed_ns[static_cast<std::size_t>(p)] = evlife::engine::monotonic_ns();
      cam.push_packet(std::move(bytes));
    }
    const auto total = static_cast<std::size_t>(packets) * events_per_packet;
    const auto deadline = std::chrono::steady_clock::now() + 10s;
    while (std::chrono::steady_clock::now() < deadline &&
           seen.load(std::memory_order_acquire) + engine.stats().events_dropped < total) {
      std::this_thread::sleep_for(1ms);
    }
    engine.request_stop();
    runner.join();

    state.counters["transfer_B"] = transfer_bytes;
    state.counters["events"] = static_cast<double>(result.stats.events_out);
    state.counters["dropped"] = static_cast<double>(result.stats.events_dropped);
    state.counters["xfer_p50_us"] = percentile(from_transfer, 0.50);
    state.counters["xfer_p99_us"] = percentile(from_transfer, 0.99);
    state.counters["xfer_max_us"] = percentile(from_transfer, 1.0);
    state.counters["push_p50_us"] = percentile(from_push, 0.50);
    state.counters["push_p99_us"] = percentile(from_push, 0.99);
    state.counters["engine_p50_us"] = result.stats.latency_p50_us;
    state.counters["engine_p99_us"] = result.stats.latency_p99_us;
    state.SetItemsProcessed(static_cast<std::int64_t>(result.stats.events_out));
  }
}
// Arg: milliseconds per packet (= per bulk transfer); 1 s of stream each.
BENCHMARK(BM_Dvs128TransferToOutputLatency)->Arg(1)->Arg(4)->Iterations(1)->UseRealTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
