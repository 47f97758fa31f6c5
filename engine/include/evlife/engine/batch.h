// The units that travel through the engine's queues. Both are allocated once
// in fixed pools at start and recycled; a batch is never copied.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "evlife/algo/event.h"
#include "evlife/io/uninitialized_array.h"

namespace evlife::engine {

/// The events of one source chunk that one worker must process, with a flag
/// per event saying whether the worker owns it (its output is kept) or only
/// needs it as context (margin: its output is discarded). The worker writes
/// the outputs of owned events, in order, into `out`.
struct WorkBatch {
  // Not zeroed: the router and the worker write what they count; a run's
  // pages are faulted in by the threads that first use them, not all by the
  // main thread before the run.
  explicit WorkBatch(std::size_t capacity_events)
      : events(capacity_events), owned(capacity_events), out(capacity_events), capacity(capacity_events) {}

  io::UninitializedArray<Event> events;
  io::UninitializedArray<std::uint8_t> owned;
  io::UninitializedArray<AugmentedEvent> out;
  std::size_t capacity;
  std::size_t count = 0;        // events to process
  std::size_t owned_count = 0;  // outputs in `out` once processed
  std::uint64_t chunk_seq = 0;  // source chunk it came from (checks order)
  int worker = 0;
  std::int64_t arrival_ns = 0;  // steady clock: when its chunk arrived at the source
  /// Outputs in `out` the merger may take (written by the worker with
  /// release, read with acquire). A worker may hand a batch on before it is
  /// processed and publish its outputs as they come (TileWorker); it stores
  /// owned_count only once it is done with the batch, which the merger may
  /// then recycle.
  std::atomic<std::size_t> ready{0};
};

/// The merge order of one source chunk: for each accepted event, the worker
/// whose output queue holds its result (kDropped: dropped, not merged).
struct OrderBatch {
  static constexpr std::uint8_t kDropped = 0xFE;

  explicit OrderBatch(std::size_t capacity_events)
      : owner(std::make_unique<std::uint8_t[]>(capacity_events)), capacity(capacity_events) {}

  std::unique_ptr<std::uint8_t[]> owner;
  std::size_t capacity;
  std::size_t count = 0;
  std::uint64_t chunk_seq = 0;
  std::int64_t arrival_ns = 0;  // steady clock: when the chunk arrived at the source
  std::int64_t oldest_ns = 0;   // when its oldest event happened (= arrival if unknown)
};

}  // namespace evlife::engine
