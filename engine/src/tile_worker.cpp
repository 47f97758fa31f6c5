#include "evlife/engine/tile_worker.h"

#include <type_traits>

#include "evlife/engine/monotonic_clock.h"
#include "evlife/engine/thread_cpu_clock.h"

namespace evlife::engine {
namespace {
// Events ahead whose memory the estimator starts loading (as its own
// process(span) does): hides the cache misses of large sensors.
constexpr std::size_t kPrefetchDistance = 4;
}  // namespace

TileWorker::TileWorker(PipelineState& state, int worker)
    : state_(state),
      channel_(*state.workers[static_cast<std::size_t>(worker)]),
      estimator_(state.options.lifetime),
      out_token_(std::make_unique<moodycamel::ProducerToken>(channel_.out)),
      free_token_(std::make_unique<moodycamel::ProducerToken>(channel_.free)) {}

StepResult TileWorker::step() noexcept {
  if (finished_) return StepResult::finished;
  if (batch_ == nullptr) {
    WorkBatch* batch = nullptr;
    if (!channel_.in.try_dequeue(batch)) {
      // The router's last enqueue happens before input_done is set, so a
      // second look after seeing the flag cannot miss a batch.
      if (!state_.input_done.load(std::memory_order_acquire)) return StepResult::idle;
      if (!channel_.in.try_dequeue(batch)) {
        finished_ = true;
        channel_.done.store(true, std::memory_order_release);
        state_.wake_merger.signal();
        return StepResult::finished;
      }
    }
    batch_ = batch;
    pos_ = 0;
    kept_ = 0;
    // A batch of several steps goes to the merger now, its outputs
    // published as they come (a margin-only batch is never merged).
    published_early_ = batch->count > step_events_ && batch->owned_count != 0;
    batch->ready.store(0, std::memory_order_relaxed);
    if (published_early_ && !channel_.out.try_enqueue(*out_token_, batch))
      channel_.out.enqueue(*out_token_, batch);
  }
  WorkBatch* const batch = batch_;
  const std::size_t count = batch->count;
  const std::size_t end = count - pos_ > step_events_ ? pos_ + step_events_ : count;
  const std::int64_t t0 = monotonic_ns();
  const std::int64_t cpu0 = thread_cpu_ns();
  if (pos_ == 0) channel_.counters.started_ns.record(t0 - batch->arrival_ns, count);
  std::size_t kept = kept_;
  const std::uint64_t rejected_before = estimator_.stats().rejected();
  std::uint64_t rejected_margin = 0;  // rejections of the margin events fed: their owners count theirs
  // One loop, compiled twice: with margins it reads the rejection counters
  // around each event; owner-only (every event fed is owned) it does not.
  const auto estimate = [&](auto with_margins) noexcept {
    constexpr bool kMargins = decltype(with_margins)::value;
    for (std::size_t i = pos_; i < end; ++i) {
      if (i + kPrefetchDistance < count) estimator_.prefetch(batch->events[i + kPrefetchDistance]);
      [[maybe_unused]] std::uint64_t rejected = 0;
      if constexpr (kMargins) rejected = estimator_.stats().rejected();
      const AugmentedEvent a = estimator_.process(batch->events[i]);
      if (batch->owned[i] != 0) {
        batch->out[kept++] = a;
      } else if constexpr (kMargins) {
        rejected_margin += estimator_.stats().rejected() - rejected;
      }
    }
  };
  if (state_.layout.owner_only()) estimate(std::false_type{});
  else estimate(std::true_type{});
  if (const std::uint64_t rejected = estimator_.stats().rejected() - rejected_before - rejected_margin; rejected != 0)
    channel_.counters.rejected.add(rejected);
  channel_.counters.busy_cpu_ns.add(static_cast<std::uint64_t>(thread_cpu_ns() - cpu0));
  const std::int64_t t1 = monotonic_ns();
  channel_.counters.busy_ns.add(static_cast<std::uint64_t>(t1 - t0));
  channel_.counters.estimated_ns.record(t1 - batch->arrival_ns, end - pos_);
  pos_ = end;
  kept_ = kept;
  if (end < count) {
    // All outputs but the last are published here; the last one only with
    // the batch's end (below), after which the merger may recycle it.
    if (published_early_ && kept < batch->owned_count) batch->ready.store(kept, std::memory_order_release);
    return StepResult::progressed;
  }
  batch_ = nullptr;
  channel_.counters.batches.add();
  channel_.counters.events_fed.add(count);
  channel_.counters.events_owned.add(kept);
  if (kept == 0) {  // margin only: the merger will never ask for it
    state_.return_batch(batch, *free_token_);
  } else if (published_early_) {
    batch->ready.store(kept, std::memory_order_release);  // the batch is the merger's now
  } else {
    // No wake-up: the engine has this thread merge next (Engine::run).
    batch->ready.store(kept, std::memory_order_relaxed);  // the enqueue releases it
    if (!channel_.out.try_enqueue(*out_token_, batch)) channel_.out.enqueue(*out_token_, batch);
  }
  return StepResult::progressed;
}

}  // namespace evlife::engine
