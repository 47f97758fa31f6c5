#include "evlife/engine/packet_source.h"

#include <algorithm>
#include <stdexcept>

namespace evlife::engine {

PacketSource::PacketSource(SensorSize sensor, std::size_t capacity_events, SourceKind kind)
    : sensor_(sensor), kind_(kind) {
  if (capacity_events == 0) throw std::invalid_argument("PacketSource: capacity_events must be >= 1");
  ring_.resize(capacity_events);
}

std::size_t PacketSource::push(std::span<const Event> events) noexcept {
  if (closed_ || stop_.load(std::memory_order_relaxed)) {
    lost_.add(events.size());
    return 0;
  }
  const std::size_t n = std::min(events.size(), ring_.size() - count_);
  std::size_t tail = (head_ + count_) % ring_.size();
  for (std::size_t i = 0; i < n; ++i) {
    ring_[tail] = events[i];
    tail = tail + 1 == ring_.size() ? 0 : tail + 1;
  }
  count_ += n;
  lost_.add(events.size() - n);
  return n;
}

std::size_t PacketSource::pull(std::span<Event> out) noexcept {
  const std::size_t n = std::min(out.size(), count_);
  for (std::size_t i = 0; i < n; ++i) {
    out[i] = ring_[head_];
    head_ = head_ + 1 == ring_.size() ? 0 : head_ + 1;
  }
  count_ -= n;
  return n;
}

SourceStatus PacketSource::status() const noexcept {
  // A stop ends the stream as close() does: the events already taken are
  // still pulled (push() refuses and counts new ones), as a camera's
  // completed transfers are drained on a stop.
  const bool ending = closed_ || stop_.load(std::memory_order_relaxed);
  return ending && count_ == 0 ? SourceStatus::end_of_stream : SourceStatus::ok;
}

}  // namespace evlife::engine
