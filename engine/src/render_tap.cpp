#include "evlife/engine/render_tap.h"

#include <algorithm>
#include <utility>

namespace evlife::engine {

RenderTap::RenderTap(std::size_t batches, std::size_t batch_events,
                     moodycamel::LightweightSemaphore& wake_merger)
    : free_(batches, 2, 0), full_(batches, 1, 0), wake_merger_(wake_merger) {
  full_token_ = std::make_unique<moodycamel::ProducerToken>(full_);
  free_token_ = std::make_unique<moodycamel::ProducerToken>(free_);
  for (std::size_t i = 0; i < batches; ++i) {
    pool_.push_back(std::make_unique<RenderBatch>(batch_events));
    free_.enqueue(*free_token_, pool_.back().get());
  }
}

bool RenderTap::try_offer(std::span<const AugmentedEvent> events) noexcept {
  if (!events.empty()) last_offered_t_us.store(events.back().event.t_us, std::memory_order_relaxed);
  RenderBatch* b = nullptr;
  if (!free_.try_dequeue(b)) return false;
  b->count = std::min(events.size(), b->capacity);
  std::copy_n(events.begin(), b->count, b->events.get());
  b->after_skip = std::exchange(skipped_since_offer_, false);
  b->skipped_active_until_us = std::exchange(skipped_active_until_us_, INT64_MIN);
  if (!full_.try_enqueue(*full_token_, b)) full_.enqueue(*full_token_, b);
  if (wake_render_.availableApprox() == 0) wake_render_.signal();
  return true;
}

void RenderTap::close() noexcept {
  closed_.store(true, std::memory_order_release);
  wake_render_.signal();
}

RenderBatch* RenderTap::try_take() noexcept {
  RenderBatch* b = nullptr;
  return full_.try_dequeue(b) ? b : nullptr;
}

void RenderTap::give_back(RenderBatch* batch) noexcept {
  if (!free_.try_enqueue(*free_token_, batch)) free_.enqueue(*free_token_, batch);
  if (wake_merger_.availableApprox() == 0) wake_merger_.signal();
}

}  // namespace evlife::engine
