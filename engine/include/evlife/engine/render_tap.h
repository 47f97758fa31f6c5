// The merged stream's branch to the render thread: a fixed pool of batches
// and two lock-free queues. The merger offers each merged span (copied into
// one free batch); the render thread takes, uses and gives back. When no
// batch is free the merger either waits (policy block: every frame is
// exact) or drops the span and counts it (policy drop: rendering never slows
// the output).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <vector>

#include <concurrentqueue.h>
#include <lightweightsemaphore.h>

#include "evlife/algo/event.h"
#include "evlife/engine/stage_counters.h"

namespace evlife::engine {

struct RenderBatch {
  explicit RenderBatch(std::size_t capacity_events)
      : events(std::make_unique<AugmentedEvent[]>(capacity_events)), capacity(capacity_events) {}
  std::unique_ptr<AugmentedEvent[]> events;
  std::size_t capacity;
  std::size_t count = 0;
  bool after_skip = false;  ///< events before this batch's first were dropped (policy drop)
  /// With after_skip: when the last of the dropped events stops being active
  /// (t + lifetime, us): frames up to then miss some of them.
  std::int64_t skipped_active_until_us = INT64_MIN;
};

class RenderTap {
 public:
  /// `wake_merger` is signalled when a batch comes back (a blocked merger waits on it).
  RenderTap(std::size_t batches, std::size_t batch_events,
            moodycamel::LightweightSemaphore& wake_merger);

  /// Merger side: copies `events` (at most batch_events) into a free batch
  /// and queues it; false when no batch is free. Never allocates or waits.
  bool try_offer(std::span<const AugmentedEvent> events) noexcept;
  /// Merger side: the span of the failed offer is dropped (policy drop); the
  /// next batch offered says so (RenderBatch::after_skip), and until when the
  /// dropped events were active (a frame after the gap may lack long-lived ones).
  void drop(std::span<const AugmentedEvent> events) noexcept {
    dropped_events.add(events.size());
    skipped_since_offer_ = true;
    for (const AugmentedEvent& a : events) {
      if (!(a.lifetime_us > 0.0f)) continue;  // noise is never drawn (and NaN never cast)
      const auto until = a.event.t_us + static_cast<std::int64_t>(std::min(a.lifetime_us, 1e12f));
      skipped_active_until_us_ = std::max(skipped_active_until_us_, until);
    }
  }
  /// Merger side: no more offers (the stream ended).
  void close() noexcept;

  /// Render side: the next batch, or null. Give it back when done.
  RenderBatch* try_take() noexcept;
  void give_back(RenderBatch* batch) noexcept;
  bool closed() const noexcept { return closed_.load(std::memory_order_acquire); }

  moodycamel::LightweightSemaphore& wake_render() noexcept { return wake_render_; }

  Counter offered_events;  ///< events the merger offered (merger writes)
  Counter dropped_events;  ///< of which dropped, no free batch (merger writes)
  /// The last offered event's time, dropped or not (merger writes; read after
  /// closed()): the clock frames owed up to it are counted when not drawn.
  std::atomic<std::int64_t> last_offered_t_us{INT64_MIN};
  /// The last time of a chunk the router dropped (some or all of it: policy
  /// drop, the workers behind; router writes; read after closed(), the
  /// router's end having reached the merger): when the recording's last
  /// events are dropped, the frames due up to them are counted when not drawn.
  std::atomic<std::int64_t> last_dropped_t_us{INT64_MIN};

 private:
  std::vector<std::unique_ptr<RenderBatch>> pool_;
  moodycamel::ConcurrentQueue<RenderBatch*> free_;
  moodycamel::ConcurrentQueue<RenderBatch*> full_;
  moodycamel::LightweightSemaphore wake_render_{0, 200};
  moodycamel::LightweightSemaphore& wake_merger_;
  std::unique_ptr<moodycamel::ProducerToken> full_token_;  // merger's
  std::unique_ptr<moodycamel::ProducerToken> free_token_;  // render's
  std::atomic<bool> closed_{false};
  bool skipped_since_offer_ = false;  // merger's
  std::int64_t skipped_active_until_us_ = INT64_MIN;  // merger's, of the drops since the last offer
};

}  // namespace evlife::engine
