// A source the host feeds: the flight software's camera driver (or its
// uORB/ROS topic callback) push()es each packet of events it received; the
// pipeline pulls them in Pipeline::run_for() on the same thread. A bounded
// FIFO allocated once: push() never allocates, blocks or throws; events that
// do not fit are refused and counted in lost_events() (a live camera cannot
// be paused). close() ends the stream once the buffered events are pulled.
//
// Threads: push(), close() and the pipeline's pull() from ONE thread (the
// host's Run()); request_stop() and lost_events() (Pipeline::stats() of a
// monitor) from any.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "evlife/engine/event_source.h"
#include "evlife/engine/stage_counters.h"

namespace evlife::engine {

class PacketSource final : public EventSource {
 public:
  /// `capacity_events`: the most events held between two run_for() calls
  /// (>= 1; e.g. the camera's peak rate times the host's period, with margin).
  PacketSource(SensorSize sensor, std::size_t capacity_events, SourceKind kind = SourceKind::live);

  /// Appends `events` (non-decreasing time, continuing the previous
  /// packets); returns how many were taken — the rest is counted as lost.
  std::size_t push(std::span<const Event> events) noexcept;
  /// No more packets: the stream ends after the buffered events.
  void close() noexcept { closed_ = true; }
  std::size_t buffered() const noexcept { return count_; }

  std::size_t pull(std::span<Event> out) noexcept override;
  SourceStatus status() const noexcept override;
  std::string error_message() const override { return {}; }
  SensorSize sensor_size() const noexcept override { return sensor_; }
  SourceKind kind() const noexcept override { return kind_; }
  std::string describe() const override { return "host packets"; }
  std::uint64_t lost_events() const noexcept override { return lost_.get(); }
  /// As close() (from any thread): the buffered events are still pulled,
  /// later pushes are refused and counted as lost.
  void request_stop() noexcept override { stop_.store(true, std::memory_order_relaxed); }

 private:
  SensorSize sensor_;
  SourceKind kind_;
  std::vector<Event> ring_;
  std::size_t head_ = 0;   // next to pull
  std::size_t count_ = 0;  // buffered
  Counter lost_;  // one writer (push), read by stats() on any thread: a plain integer raced
  bool closed_ = false;
  std::atomic<bool> stop_{false};
};

}  // namespace evlife::engine
