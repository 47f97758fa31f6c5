#include "evlife/engine/tile_worker.h"

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
  const std::int64_t t0 = monotonic_ns();
  const std::int64_t cpu0 = thread_cpu_ns();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < batch->count; ++i) {
    if (i + kPrefetchDistance < batch->count) estimator_.prefetch(batch->events[i + kPrefetchDistance]);
    const AugmentedEvent a = estimator_.process(batch->events[i]);
    if (batch->owned[i] != 0) batch->out[kept++] = a;
  }
  channel_.counters.busy_cpu_ns.add(static_cast<std::uint64_t>(thread_cpu_ns() - cpu0));
  channel_.counters.busy_ns.add(static_cast<std::uint64_t>(monotonic_ns() - t0));
  channel_.counters.batches.add();
  channel_.counters.events_fed.add(batch->count);
  channel_.counters.events_owned.add(kept);
  if (kept == 0) {  // margin only: the merger will never ask for it
    if (!channel_.free.try_enqueue(*free_token_, batch)) channel_.free.enqueue(*free_token_, batch);
    state_.room_returned(std::uint64_t{1} << batch->worker, channel_.free.size_approx(),
                         channel_.pool.size());
  } else {
    // No wake-up: the engine has this thread merge next (Engine::run).
    if (!channel_.out.try_enqueue(*out_token_, batch)) channel_.out.enqueue(*out_token_, batch);
  }
  return StepResult::progressed;
}

}  // namespace evlife::engine
