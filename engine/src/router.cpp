#include "evlife/engine/router.h"

#include <algorithm>
#include <bit>
#include <cstring>

#include "evlife/engine/monotonic_clock.h"

namespace evlife::engine {

Router::Router(PipelineState& state, EventSource& source)
    : state_(state), source_(source), chunk_(state.options.batch_events),
      chunk_owner_(state.options.batch_events) {
  const auto workers = state.workers.size();
  stage_events_.resize(workers);
  stage_owned_.resize(workers);
  stage_count_.assign(workers, 0);
  stage_owned_count_.assign(workers, 0);
  reserved_.assign(workers, nullptr);
  for (std::size_t w = 0; w < workers; ++w) {
    stage_events_[w].resize(state.options.batch_events);
    stage_owned_[w].resize(state.options.batch_events);
    stage_event_ptr_.push_back(stage_events_[w].data());
    in_tokens_.push_back(std::make_unique<moodycamel::ProducerToken>(state.workers[w]->in));
  }
  order_token_ = std::make_unique<moodycamel::ProducerToken>(state.order);
}

StepResult Router::step() noexcept {
  if (finished_) return StepResult::finished;
  if (have_chunk_) return dispatch_pending() ? StepResult::progressed : StepResult::blocked;

  const std::size_t n = source_.pull(std::span<Event>(chunk_.data(), chunk_.size()));
  if (n == 0) {
    const SourceStatus status = source_.status();
    if (status == SourceStatus::ok) return StepResult::idle;
    source_failed_ = status == SourceStatus::error;
    finish();
    return StepResult::finished;
  }
  const std::int64_t stated_ns = source_.last_arrival_ns();
  const std::int64_t pulled_ns = monotonic_ns();
  arrival_ns_ = stated_ns != 0 ? stated_ns : pulled_ns;
  if (stated_ns != 0) state_.router_counters.pulled_ns.record(pulled_ns - stated_ns, n);
  const std::int64_t oldest_ns = source_.last_oldest_ns();
  oldest_ns_ = oldest_ns != 0 ? std::min(oldest_ns, arrival_ns_) : arrival_ns_;
  state_.router_counters.events_in.add(n);
  state_.router_counters.chunks.add();
  stage_chunk(n);
  return dispatch_pending() ? StepResult::progressed : StepResult::blocked;
}

void Router::stage_chunk(std::size_t n) noexcept {
  std::fill(stage_count_.begin(), stage_count_.end(), 0);
  std::fill(stage_owned_count_.begin(), stage_owned_count_.end(), 0);
  pending_ = 0;
  if (state_.layout.owner_only()) stage_owner_only(n);
  else stage_with_margins(n);
  chunk_count_ = n;
  ++chunk_seq_;
  order_ = nullptr;
  have_chunk_ = true;
  waiting_since_ns_ = 0;
}

// One tile per polarity or no margin: each event goes to its owner only and
// is owned; no feed mask to build (source thread CPU: the routing loop took
// ~2 % of a 2-worker run's CPU through the general path).
void Router::stage_owner_only(std::size_t n) noexcept {
  const TileLayout& layout = state_.layout;
  Event* const* dst = stage_event_ptr_.data();
  std::size_t* count = stage_count_.data();
  for (std::size_t i = 0; i < n; ++i) {
    const Event& e = chunk_[i];
    std::uint8_t owner = layout.owner(e);
    if (owner == TileLayout::kNoOwner) owner = 0;  // off-sensor / bad polarity: worker 0 counts it
    chunk_owner_[i] = owner;
    dst[owner][count[owner]++] = e;
  }
  for (std::size_t w = 0; w < stage_count_.size(); ++w) {
    if (stage_count_[w] == 0) continue;
    std::memset(stage_owned_[w].data(), 1, stage_count_[w]);
    stage_owned_count_[w] = stage_count_[w];
    pending_ |= 1u << w;
  }
}

void Router::stage_with_margins(std::size_t n) noexcept {
  const TileLayout& layout = state_.layout;
  for (std::size_t i = 0; i < n; ++i) {
    const Event& e = chunk_[i];
    std::uint8_t owner = layout.owner(e);
    std::uint32_t mask = layout.feed_mask(e);
    if (owner == TileLayout::kNoOwner) {  // off-sensor / bad polarity: worker 0 counts it
      owner = 0;
      mask = 1;
    }
    chunk_owner_[i] = owner;
    while (mask != 0) {
      const int w = std::countr_zero(mask);
      mask &= mask - 1;
      const std::size_t k = stage_count_[static_cast<std::size_t>(w)]++;
      stage_events_[static_cast<std::size_t>(w)][k] = e;
      const bool owned = w == owner;
      stage_owned_[static_cast<std::size_t>(w)][k] = owned ? 1 : 0;
      stage_owned_count_[static_cast<std::size_t>(w)] += owned ? 1 : 0;
      pending_ |= 1u << w;
    }
  }
}

// The render thread counts the frames due up to a dropped event (RenderTap::last_dropped_t_us).
void Router::note_drop_for_render() noexcept {
  if (RenderTap* tap = state_.render_tap.get(); tap != nullptr && chunk_count_ > 0)
    tap->last_dropped_t_us.store(chunk_[chunk_count_ - 1].t_us, std::memory_order_relaxed);
}

void Router::drop_for_worker(int w) noexcept {
  const std::size_t owned = stage_owned_count_[static_cast<std::size_t>(w)];
  if (owned != 0) {
    note_drop_for_render();
    for (std::size_t i = 0; i < chunk_count_; ++i)
      if (chunk_owner_[i] == w) chunk_owner_[i] = OrderBatch::kDropped;
    state_.router_counters.dropped.add(owned);
    state_.router_counters.dropped_for_worker[static_cast<std::size_t>(w)].add(owned);
  }
}

// Takes an item of `pool`; if it is empty and `wait_bit` != 0 (policy
// block), marks the router as waiting on it (PipelineState::room_returned
// then wakes it when half the pool is back) and looks once more, so that a
// return racing with the mark is not missed.
template <class Pool, class Item>
bool Router::take_or_wait(Pool& pool, Item*& item, std::uint64_t wait_bit) noexcept {
  if (pool.try_dequeue(item)) return true;
  if (wait_bit == 0) return false;
  state_.router_waiting.fetch_or(wait_bit, std::memory_order_seq_cst);
  std::atomic_thread_fence(std::memory_order_seq_cst);
  return pool.try_dequeue(item);
}

bool Router::dispatch_pending() noexcept {
  RouterCounters& counters = state_.router_counters;
  const bool drop = state_.policy == OverloadPolicy::drop;
  bool waited = false;

  if (!drop) state_.router_waiting.store(0, std::memory_order_relaxed);  // marked again below if so
  if (order_ == nullptr &&
      !take_or_wait(state_.order_free, order_, drop ? 0 : PipelineState::kOrderPoolBit)) {
    order_ = nullptr;
    if (drop) {  // nothing dispatched yet: the whole chunk goes
      note_drop_for_render();
      counters.dropped.add(chunk_count_);
      counters.dropped_no_order.add(chunk_count_);
      have_chunk_ = false;
      return true;
    }
    waited = true;
  }
  if (order_ != nullptr) {
    // Reserve a batch for every worker of the chunk before handing anything
    // on: the merge order must be queued before any output it describes, so
    // that a worker finishing first can merge its own output at once.
    std::uint32_t todo = pending_ & ~reserved_mask_;
    while (todo != 0) {
      const int w = std::countr_zero(todo);
      todo &= todo - 1;
      WorkBatch* batch = nullptr;
      if (take_or_wait(state_.workers[static_cast<std::size_t>(w)]->free, batch,
                       drop ? 0 : std::uint64_t{1} << w)) {
        reserved_[static_cast<std::size_t>(w)] = batch;
        reserved_mask_ |= 1u << w;
      } else if (drop) {
        drop_for_worker(w);
        pending_ &= ~(1u << w);
      } else {
        waited = true;
      }
    }
  }
  if (waited) {
    const std::int64_t now = monotonic_ns();
    if (waiting_since_ns_ != 0) counters.blocked_ns.add(static_cast<std::uint64_t>(now - waiting_since_ns_));
    waiting_since_ns_ = now;
    return false;
  }
  if (waiting_since_ns_ != 0) {
    counters.blocked_ns.add(static_cast<std::uint64_t>(monotonic_ns() - waiting_since_ns_));
    waiting_since_ns_ = 0;
  }
  const std::size_t in_flight = state_.order_pool.size() - state_.order_free.size_approx();
  counters.order_in_flight_hwm.raise_to(in_flight);
  std::memcpy(order_->owner.get(), chunk_owner_.data(), chunk_count_);
  order_->count = chunk_count_;
  order_->chunk_seq = chunk_seq_;
  order_->arrival_ns = arrival_ns_;
  order_->oldest_ns = oldest_ns_;
  if (!state_.order.try_enqueue(*order_token_, order_)) state_.order.enqueue(*order_token_, order_);
  order_ = nullptr;

  std::uint32_t todo = pending_;
  while (todo != 0) {
    const int w = std::countr_zero(todo);
    todo &= todo - 1;
    const auto wi = static_cast<std::size_t>(w);
    WorkerChannel& ch = *state_.workers[wi];
    WorkBatch* batch = reserved_[wi];
    const std::size_t n = stage_count_[wi];
    std::memcpy(batch->events.data(), stage_events_[wi].data(), n * sizeof(Event));
    std::memcpy(batch->owned.data(), stage_owned_[wi].data(), n);
    batch->count = n;
    batch->owned_count = stage_owned_count_[wi];
    batch->chunk_seq = chunk_seq_;
    batch->arrival_ns = arrival_ns_;
    if (!ch.in.try_enqueue(*in_tokens_[wi], batch)) ch.in.enqueue(*in_tokens_[wi], batch);
    counters.in_flight_hwm[wi].raise_to(ch.pool.size() - ch.free.size_approx());
    wake(ch.wake_worker);
  }
  // Workers merge what they finish; an order no worker output belongs to
  // (every event dropped) is left to the merger backstop thread.
  if (pending_ == 0) wake(state_.wake_merger);
  pending_ = 0;
  reserved_mask_ = 0;
  have_chunk_ = false;
  return true;
}

void Router::finish() noexcept {
  finished_ = true;
  state_.input_done.store(true, std::memory_order_release);
  for (auto& ch : state_.workers) ch->wake_worker.signal();
  state_.wake_merger.signal();
}

}  // namespace evlife::engine
