// Per-stage counters. Each counter has ONE writer at a time (the stage that
// owns it; the merger's, whoever holds the merge role, handed over with
// acquire/release) and is read by the monitor while the run goes on: relaxed
// atomics written with load+store (no read-modify-write on the hot path).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include "evlife/engine/latency_histogram.h"
#include "evlife/engine/tile_layout.h"

namespace evlife::engine {

class Counter {
 public:
  void add(std::uint64_t n = 1) noexcept {
    v_.store(v_.load(std::memory_order_relaxed) + n, std::memory_order_relaxed);
  }
  void raise_to(std::uint64_t n) noexcept {  // high-water mark
    if (n > v_.load(std::memory_order_relaxed)) v_.store(n, std::memory_order_relaxed);
  }
  std::uint64_t get() const noexcept { return v_.load(std::memory_order_relaxed); }

 private:
  std::atomic<std::uint64_t> v_{0};
};

/// First and last event time (us) handed out: extended once per delivered
/// batch (never per event), one writer; readable while the run goes on.
class TimeRange {
 public:
  void extend(std::int64_t first_t_us, std::int64_t last_t_us) noexcept {
    if (!seen_.load(std::memory_order_relaxed)) first_.store(first_t_us, std::memory_order_relaxed);
    last_.store(last_t_us, std::memory_order_relaxed);
    seen_.store(true, std::memory_order_release);
  }
  bool seen() const noexcept { return seen_.load(std::memory_order_acquire); }
  std::int64_t first() const noexcept { return first_.load(std::memory_order_relaxed); }
  std::int64_t last() const noexcept { return last_.load(std::memory_order_relaxed); }

 private:
  std::atomic<std::int64_t> first_{0};
  std::atomic<std::int64_t> last_{0};
  std::atomic<bool> seen_{false};
};

struct RouterCounters {
  Counter events_in;        ///< events accepted from the source
  Counter chunks;           ///< source chunks routed
  Counter dropped;          ///< events dropped in total (policy drop)
  Counter dropped_no_order; ///< of which: whole chunks, merge-order pool empty
  Counter blocked_ns;       ///< time the source waited for room (policy block)
  Counter order_in_flight_hwm;  ///< merge-order batches in flight, high-water mark
  /// Sources that state arrival times (paced replays, cameras): arrival of
  /// a chunk -> pulled by the source thread, per event (latency's first stage).
  LatencyHistogram pulled_ns;
  std::array<Counter, TileLayout::kMaxWorkers> dropped_for_worker;
  std::array<Counter, TileLayout::kMaxWorkers> in_flight_hwm;  ///< batches queued or held, per worker
};

struct WorkerCounters {
  Counter batches;
  Counter events_fed;    ///< owned + margin events run through the estimator
  Counter events_owned;  ///< events whose output was kept
  Counter busy_ns;       ///< time spent processing
  Counter busy_cpu_ns;   ///< of which on a CPU (thread CPU time: without preemption)
  Counter rejected;      ///< owned events its estimator labelled noise unexamined (LifetimeStats::rejected())
  /// Latency's worker stages, from the chunk's arrival at the source, per
  /// event: the worker starts its batch; the event is estimated (end of its
  /// step). Merge-order wait and delivery follow (MergerCounters::latency_ns).
  LatencyHistogram started_ns;
  LatencyHistogram estimated_ns;
};

struct MergerCounters {
  Counter events_out;          ///< events handed to the sink (or discarded without one)
  Counter sink_failed_events;  ///< of which the sink threw on
  LatencyHistogram latency_ns; ///< source arrival -> handed to the sink
  LatencyHistogram age_ns;     ///< the chunk's oldest event happened -> handed to the sink
  TimeRange event_t_us;        ///< first .. last event time handed to the sink
};

}  // namespace evlife::engine
