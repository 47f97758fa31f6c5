// The output stage: follows the router's merge order, chunk by chunk, taking
// each event's result from its owner's output queue, so the merged stream is
// in input order and the same bit for bit whatever the scheduling. Hands
// merged spans to the sink (none: counted and discarded), records each
// event's latency from source arrival, and recycles the batches.
#pragma once

#include <atomic>
#include <cstdint>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "evlife/engine/augmented_sink.h"
#include "evlife/engine/pipeline_state.h"
#include "evlife/engine/step_result.h"

namespace evlife::engine {

class Merger {
 public:
  /// `sink` may be null (output discarded, still counted).
  Merger(PipelineState& state, AugmentedSink* sink);

  /// Merges as far as the workers' outputs allow, up to one chunk. Never
  /// waits. Allocates only if the sink throws (to keep its message).
  StepResult step() noexcept;

  /// Any thread: the sink has failed (the engine then stops the source).
  bool sink_failed() const noexcept { return sink_failed_.load(std::memory_order_acquire); }
  /// The sink's message; read it after the run (the merge role's holder writes it).
  const std::string& sink_error() const noexcept { return sink_error_; }

 private:
  bool deliver(std::int64_t now_ns) noexcept;  // false: render tap full (policy block)
  void complete_order() noexcept;
  void release(WorkBatch* batch) noexcept;

  PipelineState& state_;
  AugmentedSink* sink_;
  OrderBatch* order_ = nullptr;
  std::size_t order_pos_ = 0;
  std::vector<WorkBatch*> current_;     // per worker: batch being consumed
  std::vector<std::size_t> cursor_;     // per worker: next output in it
  std::vector<std::size_t> ready_;      // per worker: outputs of it published (last look)
  std::vector<AugmentedEvent> merged_;  // one chunk's worth
  std::size_t merged_count_ = 0;
  std::vector<std::unique_ptr<moodycamel::ProducerToken>> free_tokens_;
  std::unique_ptr<moodycamel::ProducerToken> order_free_token_;
  std::string sink_error_;
  std::atomic<bool> sink_failed_{false};
  std::uint64_t sink_accepted_events_ = 0;  // handed to the sink without an error
  // The sink's error: its text, and where its file says how many records it
  // kept, the events handed to it that are not in it (before: only those
  // handed after the error counted, not those the writer's buffer lost).
  void sink_failed_with(const std::exception& e, std::size_t handed_now) noexcept;
  bool delivery_pending_ = false;
  bool finished_ = false;
};

}  // namespace evlife::engine
