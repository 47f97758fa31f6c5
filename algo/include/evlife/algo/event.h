// Plain event types shared by every module. Trivially copyable, fixed size,
// integer microsecond time, so that they travel through queues and files as-is.
#pragma once

#include <cstdint>
#include <limits>
#include <type_traits>

namespace evlife {

/// The largest sensor side evlife handles, px (the largest event cameras are
/// 1280x720): what the estimator and --sensor accept, and the limit for a
/// per-pixel plane sized from a file's stated or scanned sensor.
inline constexpr int kMaxSensorSide = 4096;

/// A stretch without events this long (event time, us) or longer is said to
/// the user (a timestamp outlier?): before `render --fps`/`run --fps` draw
/// its empty frames, and before `run --realtime` waits it out.
inline constexpr std::int64_t kEventGapNoticeUs = 60'000'000;

/// Sensor geometry in pixels.
struct SensorSize {
  int width = 0;
  int height = 0;
  constexpr bool contains(int x, int y) const noexcept {
    return x >= 0 && y >= 0 && x < width && y < height;
  }
  constexpr long long pixel_count() const noexcept {
    return static_cast<long long>(width) * height;
  }
  /// 1..kMaxSensorSide each way: a size that per-pixel planes may follow.
  constexpr bool within_camera_limits() const noexcept {
    return width >= 1 && height >= 1 && width <= kMaxSensorSide && height <= kMaxSensorSide;
  }
  friend constexpr bool operator==(SensorSize, SensorSize) = default;
};

/// One DVS event <x, y, t, p>. Polarity is +1 (ON, brighter) or -1 (OFF).
struct Event {
  std::int64_t t_us = 0;  ///< timestamp, microseconds
  std::uint16_t x = 0;    ///< column, 0 = left
  std::uint16_t y = 0;    ///< row, 0 = top
  std::int8_t p = 1;      ///< polarity: +1 or -1
  std::uint8_t reserved[3] = {0, 0, 0};  ///< explicit, zeroed: byte-exact copies and files
};
static_assert(std::is_trivially_copyable_v<Event>);

/// The event times the estimator and the active-event map take: |t_us| <=
/// 2^62 us (about 146,000 years either side of the clock's zero), where no
/// difference of two times overflows; events beyond are rejected and counted.
inline constexpr std::int64_t kMaxEventTimeUs = std::int64_t{1} << 62;

/// True for a time within [-kMaxEventTimeUs, kMaxEventTimeUs] (one compare).
constexpr bool within_event_time_range(std::int64_t t_us) noexcept {
  return static_cast<std::uint64_t>(t_us) + static_cast<std::uint64_t>(kMaxEventTimeUs) <=
         2 * static_cast<std::uint64_t>(kMaxEventTimeUs);
}
static_assert(sizeof(Event) == 16, "Event must stay 16 bytes");

/// later_us - earlier_us for later >= earlier, exact for any two times (as
/// unsigned: they may lie more than 2^63 us apart).
constexpr std::uint64_t span_us(std::int64_t earlier_us, std::int64_t later_us) noexcept {
  return static_cast<std::uint64_t>(later_us) - static_cast<std::uint64_t>(earlier_us);
}

/// last_us - first_us in seconds, for any two times (no int64 overflow: a
/// file's times may span the whole clock); the difference is taken in 64 bits
/// where it fits (times beyond 2^53 us lost their microseconds converted first).
constexpr double seconds_between(std::int64_t first_us, std::int64_t last_us) noexcept {
  std::int64_t d = 0;
  if (!__builtin_sub_overflow(last_us, first_us, &d)) return static_cast<double>(d) * 1e-6;
  return (static_cast<double>(last_us) - static_cast<double>(first_us)) * 1e-6;
}

/// An event augmented with its lifetime and normal velocity (paper eq. 1).
/// Noise events have lifetime 0 and velocity 0.
struct AugmentedEvent {
  Event event;
  float lifetime_us = 0.0f;  ///< time the edge needs to move one pixel; 0 = noise
  /// Normal velocity of the edge, pixels per second: the component of its
  /// motion perpendicular to the edge (the gradient direction of the plane
  /// fitted to its events), the only one local events can measure (aperture
  /// problem); its speed is 1e6 / lifetime_us. Not the full optical flow.
  float vx_px_s = 0.0f;
  float vy_px_s = 0.0f;      ///< see vx_px_s
  /// t - t_hat of the prediction made for this pixel by an earlier event
  /// (paper Fig. 9), microseconds; NaN when no prediction existed.
  float prediction_error_us = std::numeric_limits<float>::quiet_NaN();

  bool is_noise() const noexcept { return lifetime_us <= 0.0f; }
  bool has_prediction() const noexcept {
    return prediction_error_us == prediction_error_us;  // false for NaN
  }
};
static_assert(std::is_trivially_copyable_v<AugmentedEvent>);
static_assert(sizeof(AugmentedEvent) == 32, "AugmentedEvent must stay 32 bytes");

}  // namespace evlife
