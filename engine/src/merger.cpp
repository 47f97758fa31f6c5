#include "evlife/engine/merger.h"

#include <exception>

#include "evlife/engine/monotonic_clock.h"
#include "evlife/io/write_error.h"

namespace evlife::engine {

Merger::Merger(PipelineState& state, AugmentedSink* sink)
    : state_(state), sink_(sink), current_(state.workers.size(), nullptr),
      cursor_(state.workers.size(), 0), ready_(state.workers.size(), 0), merged_(state.options.batch_events) {
  for (auto& ch : state.workers)
    free_tokens_.push_back(std::make_unique<moodycamel::ProducerToken>(ch->free));
  order_free_token_ = std::make_unique<moodycamel::ProducerToken>(state.order_free);
}

void Merger::release(WorkBatch* batch) noexcept {
  state_.return_batch(batch, *free_tokens_[static_cast<std::size_t>(batch->worker)]);
}

void Merger::complete_order() noexcept {
  if (!state_.order_free.try_enqueue(*order_free_token_, order_))
    state_.order_free.enqueue(*order_free_token_, order_);
  order_ = nullptr;
  delivery_pending_ = false;
  state_.room_returned(PipelineState::kOrderPoolBit, state_.order_free.size_approx(),
                       state_.order_pool.size());
}

StepResult Merger::step() noexcept {
  if (finished_) return StepResult::finished;
  if (delivery_pending_) {  // the chunk is merged; the render tap had no room
    if (!deliver(monotonic_ns())) return StepResult::blocked;
    complete_order();
    return StepResult::progressed;
  }
  if (order_ == nullptr) {
    if (!state_.order.try_dequeue(order_)) {
      order_ = nullptr;
      if (!state_.input_done.load(std::memory_order_acquire)) return StepResult::idle;
      if (!state_.order.try_dequeue(order_)) {  // every chunk merged
        order_ = nullptr;
        finished_ = true;
        if (state_.render_tap) state_.render_tap->close();
        if (sink_ != nullptr && sink_error_.empty()) {
          try {
            sink_->finish();
          } catch (const std::exception& e) {
            sink_failed_with(e, 0);
          } catch (...) {
            sink_error_ = "unknown error while finishing the output";
          }
          if (!sink_error_.empty()) sink_failed_.store(true, std::memory_order_release);
        }
        return StepResult::finished;
      }
    }
    order_pos_ = 0;
    merged_count_ = 0;
  }
  bool progressed = false;
  while (order_pos_ < order_->count) {
    const std::uint8_t owner = order_->owner[order_pos_];
    if (owner == OrderBatch::kDropped) {
      ++order_pos_;
      continue;
    }
    WorkBatch*& batch = current_[owner];
    if (batch == nullptr) {
      if (!state_.workers[owner]->out.try_dequeue(batch)) {
        batch = nullptr;
        // Deliver what is merged so far rather than sit on it.
        if (merged_count_ != 0) deliver(monotonic_ns());
        return progressed ? StepResult::progressed : StepResult::idle;
      }
      cursor_[owner] = 0;
      ready_[owner] = batch->ready.load(std::memory_order_acquire);
    }
    if (cursor_[owner] == ready_[owner]) {
      ready_[owner] = batch->ready.load(std::memory_order_acquire);
      if (cursor_[owner] == ready_[owner]) {  // its worker is still estimating the rest
        if (merged_count_ != 0) deliver(monotonic_ns());
        return progressed ? StepResult::progressed : StepResult::idle;
      }
    }
    merged_[merged_count_++] = batch->out[cursor_[owner]++];
    progressed = true;
    if (cursor_[owner] == batch->owned_count) {
      release(batch);
      batch = nullptr;
    }
    ++order_pos_;
  }
  if (!deliver(monotonic_ns())) {
    delivery_pending_ = true;
    return StepResult::blocked;
  }
  complete_order();
  return StepResult::progressed;
}

bool Merger::deliver(std::int64_t now_ns) noexcept {
  if (merged_count_ == 0) return true;
  MergerCounters& counters = state_.merger_counters;
  const std::span<const AugmentedEvent> merged(merged_.data(), merged_count_);
  if (RenderTap* tap = state_.render_tap.get()) {
    if (!tap->try_offer(merged)) {
      if (state_.policy == OverloadPolicy::block) return false;  // retried on the next step
      tap->drop(merged);
    }
    tap->offered_events.add(merged_count_);
  }
  if (sink_ != nullptr && sink_error_.empty()) {
    try {
      sink_->write(merged);
      sink_accepted_events_ += merged_count_;
    } catch (const std::exception& e) {
      sink_failed_with(e, merged_count_);
    } catch (...) {
      sink_error_ = "unknown error while writing the output";
      counters.sink_failed_events.add(merged_count_);
    }
  } else if (!sink_error_.empty()) {
    counters.sink_failed_events.add(merged_count_);  // after the error: none written
  }
  if (!sink_error_.empty()) sink_failed_.store(true, std::memory_order_release);
  counters.latency_ns.record(now_ns - order_->arrival_ns, merged_count_);
  counters.age_ns.record(now_ns - order_->oldest_ns, merged_count_);
  counters.event_t_us.extend(merged.front().event.t_us, merged.back().event.t_us);
  counters.events_out.add(merged_count_);
  merged_count_ = 0;
  return true;
}

void Merger::sink_failed_with(const std::exception& e, std::size_t handed_now) noexcept {
  sink_error_ = e.what();
  std::uint64_t not_written = handed_now;
  if (const auto* write_error = dynamic_cast<const io::WriteError*>(&e)) {
    const std::uint64_t handed = sink_accepted_events_ + handed_now;
    if (const auto kept = write_error->records_in_file(); kept && *kept <= handed) not_written = handed - *kept;
  }
  state_.merger_counters.sink_failed_events.add(not_written);
}

}  // namespace evlife::engine
