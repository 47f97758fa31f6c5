// The naive baseline (paper Figs. 1, 4b, 8a-b): draw every event of the fixed
// window [t - window, t]. Keeps the latest timestamp and polarity per pixel
// (a most-recent-timestamp map), so any window ending at any t >= the last
// fed time is answered in O(sensor pixels) without re-reading the history.
// Noise is drawn too: the baseline has no way to tell it apart.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "evlife/algo/event.h"

namespace evlife::render {

class FixedWindowMap {
 public:
  /// Throws std::invalid_argument for an empty or oversized sensor.
  explicit FixedWindowMap(SensorSize sensor);

  void feed(const Event& e) noexcept {
    if (!sensor_.contains(e.x, e.y)) {
      ++out_of_sensor_;
      return;
    }
    // Older than the epoch (a corrupt time, a clock restarted: the engine's
    // render stage feeds what the estimator rejected too): counted and
    // ignored, as ActiveEventMap does; taken for a jump forward, it moved the
    // epoch and erased every pixel's history.
    if (has_epoch_ && e.t_us < epoch_us_) {
      ++late_;
      return;
    }
    // Unsigned: times fed in order are at or after the epoch, but may lie
    // more than 2^63 us from it (a file's times may span all of int64).
    if (!has_epoch_ || since_epoch_us(e.t_us) > static_cast<std::uint64_t>(kRebaseAfterUs)) rebase(e.t_us);
    const std::size_t i = static_cast<std::size_t>(e.y) * static_cast<std::size_t>(sensor_.width) + e.x;
    const auto rel = static_cast<std::int32_t>(since_epoch_us(e.t_us));
    if (rel >= last_rel_[i]) {
      last_rel_[i] = rel;
      polarity_[i] = e.p;
    }
  }
  void feed(const AugmentedEvent& a) noexcept { feed(a.event); }
  void feed(std::span<const AugmentedEvent> events) noexcept {
    for (const auto& a : events) feed(a.event);
  }

  void reset() noexcept;

  /// Window bounds relative to the epoch, for is_active_rel() in per-pixel loops.
  struct RelWindow {
    std::int64_t lo;
    std::int64_t hi;
  };
  RelWindow relative_window(std::int64_t t_us, std::int64_t window_us) const noexcept {
    std::int64_t start_us = 0;
    if (__builtin_sub_overflow(t_us, window_us, &start_us)) start_us = INT64_MIN;  // before the clock
    return {saturated_rel(start_us), saturated_rel(t_us)};
  }
  bool is_active_rel(std::size_t i, RelWindow w) const noexcept {
    const std::int64_t last = last_rel_[i];
    return last >= w.lo && last <= w.hi;
  }
  /// True when pixel i (y * width + x) had an event in [t_us - window_us, t_us]
  /// (windows up to ~9 minutes).
  bool is_active(std::size_t i, std::int64_t t_us, std::int64_t window_us) const noexcept {
    return is_active_rel(i, relative_window(t_us, window_us));
  }
  std::int8_t polarity(std::size_t i) const noexcept { return polarity_[i]; }
  /// Raw map: latest timestamp per pixel relative to the epoch (kNeverRel = none).
  std::span<const std::int32_t> last_map() const noexcept { return last_rel_; }
  std::size_t count_active(std::int64_t t_us, std::int64_t window_us) const noexcept;

  SensorSize sensor() const noexcept { return sensor_; }
  std::uint64_t out_of_sensor() const noexcept { return out_of_sensor_; }
  /// Events older than the map's time range (~9 min before its newest): ignored.
  std::uint64_t late() const noexcept { return late_; }

  static constexpr std::int32_t kNeverRel = std::numeric_limits<std::int32_t>::min();
  static constexpr std::int32_t kMaxRel = std::numeric_limits<std::int32_t>::max();
  /// The longest window drawn exactly (about 537 s): the 32-bit times keep
  /// that much history behind the newest event; longer windows are refused.
  static constexpr std::int64_t kLongestWindowUs = std::int64_t{1} << 29;

 private:
  static constexpr std::int64_t kKeepUs = kLongestWindowUs;
  static constexpr std::int64_t kRebaseAfterUs = kMaxRel - kKeepUs;
  void rebase(std::int64_t t_us) noexcept;
  std::uint64_t since_epoch_us(std::int64_t t_us) const noexcept { return span_us(epoch_us_, t_us); }
  // t_us - epoch within (kNeverRel, kMaxRel], saturated, for any two times.
  std::int64_t saturated_rel(std::int64_t t_us) const noexcept {
    std::int64_t r = 0;
    if (__builtin_sub_overflow(t_us, epoch_us_, &r)) r = t_us > epoch_us_ ? INT64_MAX : INT64_MIN;
    return r <= kNeverRel ? std::int64_t{kNeverRel} + 1 : (r > kMaxRel ? std::int64_t{kMaxRel} : r);
  }

  SensorSize sensor_;
  std::uint64_t out_of_sensor_ = 0;
  std::uint64_t late_ = 0;
  // Latest timestamp per pixel relative to epoch_us_ (32-bit: half the
  // memory read per frame); kNeverRel: never fired.
  std::int64_t epoch_us_ = 0;
  bool has_epoch_ = false;
  std::vector<std::int32_t> last_rel_;
  std::vector<std::int8_t> polarity_;
};

}  // namespace evlife::render
