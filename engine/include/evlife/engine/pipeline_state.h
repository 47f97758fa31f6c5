// What the stages share: the fixed pools, the lock-free queues between them
// and their counters. Built once by Pipeline; no stage allocates after that.
//
//   source -> Router --in[w]--> TileWorker w --out[w]--> Merger -> sink
//               |                                          ^
//               +--------------- order -------------------+
// Recycling: free[w] (worker batches, returned by the merger or, for batches
// holding only margin events, by the worker) and order_free (by the merger).
#pragma once

#include <atomic>
#include <memory>
#include <vector>

#include <concurrentqueue.h>
#include <lightweightsemaphore.h>

#include "evlife/engine/batch.h"
#include "evlife/engine/engine_options.h"
#include "evlife/engine/render_tap.h"
#include "evlife/engine/stage_counters.h"
#include "evlife/engine/tile_layout.h"

namespace evlife::engine {

using WorkQueue = moodycamel::ConcurrentQueue<WorkBatch*>;
using OrderQueue = moodycamel::ConcurrentQueue<OrderBatch*>;
using Semaphore = moodycamel::LightweightSemaphore;

/// Spins of a waiting stage before it sleeps in the kernel: short, because
/// the engine's threads often outnumber the cores and a spinning thread
/// steals the core the stage it waits for needs.
inline constexpr int kWakeSpins = 200;

/// Wakes a stage that may be sleeping; keeps the count at most 1 so that a
/// busy stage does not accumulate wake-ups.
inline void wake(Semaphore& s) noexcept {
  if (s.availableApprox() == 0) s.signal();
}

struct WorkerChannel {
  WorkerChannel(std::size_t batches, std::size_t batch_events, int worker);
  std::vector<std::unique_ptr<WorkBatch>> pool;
  WorkQueue free;  // producers: merger, worker; consumer: router
  WorkQueue in;    // router -> worker
  WorkQueue out;   // worker -> merger
  Semaphore wake_worker{0, kWakeSpins};
  WorkerCounters counters;
  std::atomic<bool> done{false};
};

struct PipelineState {
  PipelineState(const EngineOptions& options, SensorSize sensor, OverloadPolicy policy);

  EngineOptions options;
  OverloadPolicy policy;
  TileLayout layout;
  std::vector<std::unique_ptr<WorkerChannel>> workers;
  std::vector<std::unique_ptr<OrderBatch>> order_pool;
  OrderQueue order_free;  // merger -> router
  OrderQueue order;       // router -> merger
  Semaphore wake_router{0, kWakeSpins};  // room came back (policy block)
  Semaphore wake_merger{0, kWakeSpins};  // render room, all-dropped order, end
  std::atomic<bool> input_done{false};  // router pushed its last batch
  std::unique_ptr<RenderTap> render_tap;  // null unless options.render_batches > 0
  RouterCounters router_counters;
  MergerCounters merger_counters;

  /// A batch or merge order went back to its pool (`pool_size` items, about
  /// `free_now` free). Policy block: the router, blocked on a full pool,
  /// is woken once half the pool is free and refills it in a burst, rather
  /// than woken per returned batch (a futex wake and two context switches
  /// per 1024 events, on the cores the workers need). The workers still
  /// hold the other half queued, so none runs dry. Policy drop: at once
  /// (the router does not wait for room there; kept as it was).
  void room_returned(std::size_t free_now, std::size_t pool_size) noexcept {
    if (policy == OverloadPolicy::drop || 2 * free_now >= pool_size) wake(wake_router);
  }
};

}  // namespace evlife::engine
