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
    const std::size_t i = static_cast<std::size_t>(e.y) * static_cast<std::size_t>(sensor_.width) + e.x;
    if (e.t_us >= last_t_us_[i]) {
      last_t_us_[i] = e.t_us;
      polarity_[i] = e.p;
    }
  }
  void feed(const AugmentedEvent& a) noexcept { feed(a.event); }
  void feed(std::span<const AugmentedEvent> events) noexcept {
    for (const auto& a : events) feed(a.event);
  }

  void reset() noexcept;

  /// True when pixel i (y * width + x) had an event in [t_us - window_us, t_us].
  bool is_active(std::size_t i, std::int64_t t_us, std::int64_t window_us) const noexcept {
    const std::int64_t last = last_t_us_[i];
    return last <= t_us && last >= t_us - window_us;
  }
  std::int8_t polarity(std::size_t i) const noexcept { return polarity_[i]; }
  std::size_t count_active(std::int64_t t_us, std::int64_t window_us) const noexcept;

  SensorSize sensor() const noexcept { return sensor_; }
  std::uint64_t out_of_sensor() const noexcept { return out_of_sensor_; }

  static constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::min() / 2;

 private:
  SensorSize sensor_;
  std::uint64_t out_of_sensor_ = 0;
  std::vector<std::int64_t> last_t_us_;  // kNever: never fired
  std::vector<std::int8_t> polarity_;
};

}  // namespace evlife::render
