// The source stage: pulls a chunk of events from the EventSource, stamps its
// arrival time, and splits it into one WorkBatch per worker (owned + margin
// events) plus an OrderBatch recording, per event, whose output to merge; the
// order is queued before the batches. Overload (a worker's pool empty):
// policy block keeps the chunk, and the batches reserved so far, pending and
// retries on the next step; policy drop drops that worker's events of the
// chunk and counts them. step() never waits and never allocates.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "evlife/engine/event_source.h"
#include "evlife/engine/pipeline_state.h"
#include "evlife/engine/step_result.h"

namespace evlife::engine {

class Router {
 public:
  Router(PipelineState& state, EventSource& source);

  StepResult step() noexcept;

  /// The source ended with an error (set when step() returns finished).
  bool source_failed() const noexcept { return source_failed_; }
  /// A chunk pulled from the source and not yet handed to every worker.
  bool holds_a_chunk() const noexcept { return have_chunk_; }

 private:
  template <class Pool, class Item>
  bool take_or_wait(Pool& pool, Item*& item, std::uint64_t wait_bit) noexcept;
  void stage_chunk(std::size_t n) noexcept;  // split chunk_ into per-worker staging
  void note_drop_for_render() noexcept;
  void stage_owner_only(std::size_t n) noexcept;    // layout.owner_only()
  void stage_with_margins(std::size_t n) noexcept;  // the general case
  bool dispatch_pending() noexcept;           // true when the chunk is fully handed on
  void drop_for_worker(int w) noexcept;
  void finish() noexcept;

  PipelineState& state_;
  EventSource& source_;
  std::vector<Event> chunk_;
  std::vector<std::uint8_t> chunk_owner_;
  std::size_t chunk_count_ = 0;
  std::uint64_t chunk_seq_ = 0;
  std::int64_t arrival_ns_ = 0;
  std::int64_t oldest_ns_ = 0;
  OrderBatch* order_ = nullptr;
  std::uint32_t pending_ = 0;  // workers with events in the chunk, not dropped
  std::uint32_t reserved_mask_ = 0;  // of which: a free batch is reserved
  std::vector<WorkBatch*> reserved_;  // per worker, while the chunk waits
  bool have_chunk_ = false;
  std::int64_t waiting_since_ns_ = 0;
  bool finished_ = false;
  bool source_failed_ = false;
  // Per worker staging of the current chunk (copied into a pool batch when
  // one is free, so a blocked chunk can be retried).
  std::vector<std::vector<Event>> stage_events_;
  std::vector<Event*> stage_event_ptr_;  // stage_events_[w].data()
  std::vector<std::vector<std::uint8_t>> stage_owned_;
  std::vector<std::size_t> stage_count_;
  std::vector<std::size_t> stage_owned_count_;
  std::vector<std::unique_ptr<moodycamel::ProducerToken>> in_tokens_;
  std::unique_ptr<moodycamel::ProducerToken> order_token_;
};

}  // namespace evlife::engine
