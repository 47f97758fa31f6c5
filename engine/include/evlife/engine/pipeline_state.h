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
#include <cstdint>
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

  /// Pools the router found empty and waits on (policy block): bit w for
  /// worker w's batches, kOrderPoolBit for merge orders.
  static constexpr std::uint64_t kOrderPoolBit = std::uint64_t{1} << 63;
  std::atomic<std::uint64_t> router_waiting{0};

  /// A batch or merge order went back to pool `pool_bit` (`pool_size` items,
  /// about `free_now` free). Policy block: the router, if it waits on that
  /// pool, is woken once half of it is free and refills it in a burst,
  /// rather than once per returned batch (a futex wake and two context
  /// switches per 1024 events, on the cores the workers need); the workers
  /// still hold the other half queued, so none runs dry. Policy drop: at
  /// once (the router does not wait for room there; kept as it was).
  /// Puts `batch` back in its worker's free pool (`token`: the caller's
  /// producer token of that pool) and tells the router (room_returned).
  void return_batch(WorkBatch* batch, moodycamel::ProducerToken& token) noexcept {
    WorkerChannel& ch = *workers[static_cast<std::size_t>(batch->worker)];
    if (!ch.free.try_enqueue(token, batch)) ch.free.enqueue(token, batch);
    room_returned(std::uint64_t{1} << batch->worker, ch.free.size_approx(), ch.pool.size());
  }

  void room_returned(std::uint64_t pool_bit, std::size_t free_now, std::size_t pool_size) noexcept {
    if (policy == OverloadPolicy::drop) {
      wake(wake_router);
      return;
    }
    // The return (a store in the queue) before the look at router_waiting,
    // against the router's mark before its second look at the pool: one of
    // the two sees the other (Router::take_or_wait).
    std::atomic_thread_fence(std::memory_order_seq_cst);
    if ((router_waiting.load(std::memory_order_relaxed) & pool_bit) != 0 && 2 * free_now >= pool_size)
      wake(wake_router);
  }
};

}  // namespace evlife::engine
